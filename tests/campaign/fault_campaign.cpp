// The seeded fault campaign (docs/reliability.md): a real job — the example knob, planned by
// laminad and cut on lamina-sim — with one fault at a random moment of its first sheet, again
// and again. After each fault it checks what the shop relies on:
//   - the machine stopped and nothing moved on by itself while nobody resumed;
//   - what clients were told (job.get) is what the database on disk holds;
//   - the operator's resume finished the sheet;
//   - in the simulator's execution log: every finished contour cut exactly once, none skipped
//     or left dry, and the jet never on at a standstill longer than the limit (wall clock).
// One JSON line per run (--out), a summary per fault on stdout; exit 1 on any violation.
//
// The cut runs at --time-scale; some blocks before the fault lamina-sim slows to
// --fault-time-scale (real time), so the PLC's watchdog, the planner queue and the host's
// reactions meet as at a real machine, and speeds up again once the operator has resumed.
//
//   fault-campaign [--runs N] [--seed S] [--faults a,b,…] [--time-scale K] [--fault-time-scale K]
//                  [--jet-limit-ms MS] [--restart-limit-ms MS] [--out FILE] [--only-run N]
#include <sqlite3.h>

#include <random>
#include <sstream>

#include "campaign_checks.hpp"
#include "daemon_fixture.hpp"

namespace lamina::campaign {
namespace {

using daemon::RpcClient;
using namespace daemon::testing;
using Rng = std::mt19937_64;

struct Options {
  std::size_t runs = 200;
  std::uint64_t seed = 1;
  std::vector<std::string> faults;  // empty: all
  double time_scale = 20;       // the cut runs this fast …
  double fault_time_scale = 1;  // … and at this speed from just before the fault to the resume
  double jet_limit_ms = 100;
  double restart_limit_ms = 1100;  // [cell] jet_restart_s (1 s) and the jet limit
  std::string out;
  std::size_t only_run = 0;  // 1-based: repeat that one run of the seed (to look into a violation)
};

// One run's cell: the simulator, a small disk for the state folder when the fault needs one,
// the daemon, a client.
struct Rig {
  explicit Rig(double time_scale, bool small_disk) : cell({}, time_scale, kKillWatchdogMs) {
    if (small_disk) disk = std::make_unique<SmallDisk>(cell.dir.file("state"), "48m");
    daemon = std::make_unique<Laminad>(cell.config(), cell.dir.file(""));
    reconnect();
  }
  void reconnect() {
    client.reset();
    client.emplace(connect(cell.socket()));
  }
  void restart(int signal) {
    daemon->stop(signal);
    daemon->start();
    reconnect();
  }
  RpcClient& c() { return *client; }
  std::string control(const std::string& command) const {
    return sim::testing::control(cell.sim.control_port(), command);
  }
  Json status() const { return sim::testing::control_status(cell.sim.control_port()); }

  Cell cell;
  std::unique_ptr<SmallDisk> disk;
  std::unique_ptr<Laminad> daemon;
  std::optional<RpcClient> client;
};

double uniform(Rng& rng, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }

// A fault: how it strikes, and what clears it before the operator resumes (a restart of the
// daemon for those that take it down or latch it).
struct Fault {
  std::string name;
  bool needs_disk = false;
  std::function<void(Rig&, Rng&)> strike;
  std::function<void(Rig&, Rng&)> clear;
};

const std::vector<Fault>& faults() {
  static const std::vector<Fault> table{
      {"kill9", false, [](Rig& r, Rng&) { r.daemon->stop(SIGKILL); }, [](Rig& r, Rng&) {
         r.daemon->start();
         r.reconnect();
       }},
      // Not a fault but the operator's hold: the jet must go off once the machine stands, and
      // the resume re-opens it in the kerf before the motion.
      {"hold", false, [](Rig& r, Rng&) { call_ok(r.c(), "machine.hold"); }, [](Rig&, Rng& rng) {
         std::this_thread::sleep_for(std::chrono::duration<double>(uniform(rng, 0.2, 2.0)));
       }},
      {"unplug", false, [](Rig& r, Rng&) { r.control("unplug"); },
       [](Rig& r, Rng& rng) {
         std::this_thread::sleep_for(std::chrono::duration<double>(uniform(rng, 0.1, 2.0)));
         r.control("replug");
       }},
      {"estop", false, [](Rig& r, Rng&) { r.control("estop on"); }, [](Rig& r, Rng& rng) {
         std::this_thread::sleep_for(std::chrono::duration<double>(uniform(rng, 0.1, 1.0)));
         r.control("estop off");
       }},
      {"pressure_drop", false, [](Rig& r, Rng&) { r.control("pressure drop"); },
       [](Rig& r, Rng&) { r.control("pressure restore"); }},
      {"plc_gone", false, [](Rig& r, Rng&) { r.control("plc down"); }, [](Rig& r, Rng& rng) {
         std::this_thread::sleep_for(std::chrono::duration<double>(uniform(rng, 0.2, 2.0)));
         r.control("plc up");
       }},
      {"disk_full", true, [](Rig& r, Rng&) { r.disk->fill("fill"); }, [](Rig& r, Rng&) {
         std::filesystem::remove(r.cell.dir.file("state/fill"));
         r.restart(SIGTERM);  // a failed store latches until laminad restarts (docs/daemon.md)
       }},
  };
  return table;
}

// The job's state as the database on disk holds it (read-only, beside the running daemon).
Json state_on_disk(const std::string& db_path, const std::string& id) {
  sqlite3* db = nullptr;
  Json out;
  if (sqlite3_open_v2(db_path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    sqlite3_close(db);
    throw std::runtime_error("cannot open " + db_path);
  }
  sqlite3_busy_timeout(db, 2000);
  const auto query = [&](const char* sql, const std::function<void(sqlite3_stmt*)>& row) {
    sqlite3_stmt* st = nullptr;
    if (sqlite3_prepare_v2(db, sql, -1, &st, nullptr) != SQLITE_OK) throw std::runtime_error(sqlite3_errmsg(db));
    sqlite3_bind_text(st, 1, id.c_str(), -1, SQLITE_TRANSIENT);
    while (sqlite3_step(st) == SQLITE_ROW) row(st);
    sqlite3_finalize(st);
  };
  const auto text = [](sqlite3_stmt* st, int col) { return std::string(reinterpret_cast<const char*>(sqlite3_column_text(st, col))); };
  query("SELECT state, current_sheet FROM jobs WHERE id = ?1", [&](sqlite3_stmt* st) {
    out["state"] = text(st, 0);
    out["current_sheet"] = sqlite3_column_int64(st, 1);
  });
  out["sheets"] = Json::array();
  query("SELECT state, last_acked_line FROM sheets WHERE job_id = ?1 ORDER BY idx", [&](sqlite3_stmt* st) {
    out["sheets"].push_back({{"state", text(st, 0)}, {"last_acked_line", sqlite3_column_int64(st, 1)}});
  });
  sqlite3_close(db);
  return out;
}

Json told_view(const Json& job) {
  Json out{{"state", job["state"]}, {"current_sheet", job["current_sheet"]}, {"sheets", Json::array()}};
  for (const auto& s : job["sheets"]) out["sheets"].push_back({{"state", s["state"]}, {"last_acked_line", s["last_acked_line"]}});
  return out;
}

struct RunRecord {
  Json json;
  std::vector<std::string> violations;
  int starvation_holds = 0;  // pauses by the hold watch after the resume, resumed again
};

// Waits until the machine stands and the daemon (if it runs) no longer cuts; then checks that
// nothing moves on by itself for a second.
void expect_stopped(Rig& r, const std::string& id, bool daemon_alive, RunRecord& rec) {
  const auto standing = [](const Json& s) { return s["state"] != "run" && s["state"] != "hold_pending"; };
  if (!sim::testing::wait_status(r.cell.sim.control_port(), standing, 60)) {
    rec.violations.push_back("the machine did not stop within 60 s of the fault");
    return;
  }
  if (daemon_alive) {
    // A job whose store failed may still read "cutting": that is what its database holds, and
    // what clients see is never ahead of it (machine.status says the store failed).
    const auto store_failed = [&] { return call_ok(r.c(), "machine.status")["store"]["ok"] == false; };
    const Json job = wait_job(r.c(), id, [&](const Json& j) { return j["state"] != "cutting" || store_failed(); }, 60);
    if (job["state"] == "cutting" && !store_failed())
      rec.violations.push_back("the job still says cutting 60 s after the fault");
  }
  const auto before = r.status()["executed_blocks"].get<std::size_t>();
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const Json after = r.status();
  if (after["executed_blocks"].get<std::size_t>() != before || !standing(after))
    rec.violations.push_back(fmt::format("the machine moved on by itself after the fault ({} → {} blocks, {})", before,
                                         after["executed_blocks"].get<std::size_t>(), after["state"].get<std::string>()));
}

// The operator's resume, retried while the cell gets ready (the pump's ramp, a replug).
bool operator_resumes(Rig& r, const std::string& id, RunRecord& rec) {
  std::string refused;
  for (int attempt = 0; attempt < 40; ++attempt) {
    auto result = r.c().call("job.resume", {{"job", id}}, 30);
    if (result.has_value()) return true;
    refused = result.error().message;
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  rec.violations.push_back("job.resume was refused for 20 s: " + refused);
  return false;
}

// A pause by the hold watch because the host fell behind the controller (a loaded host at 40×):
// the safe answer to a starved stream, resumed by the operator. The jet check still judges it.
bool held_because_the_host_fell_behind(const Json& job) {
  return job["state"] == "paused" && job["error"].get<std::string>().find("the host had not sent") != std::string::npos;
}

// Resumes, then waits for the sheet to end; a starvation pause is resumed again (3 at most)
// and counted. The job as it stands then.
Json resume_to_the_sheet_end(Rig& r, const std::string& id, RunRecord& rec, double time_scale) {
  Json job;
  for (;;) {
    if (!operator_resumes(r, id, rec)) return call_ok(r.c(), "job.get", {{"job", id}});
    r.control(fmt::format("time-scale {}", time_scale));
    job = wait_job(r.c(), id, [](const Json& j) { return j["state"] != "cutting" && j["state"] != "planning"; }, 600);
    if (!held_because_the_host_fell_behind(job) || rec.starvation_holds == 3) break;
    ++rec.starvation_holds;
  }
  if (job["sheets"][0]["state"] != "done")
    rec.violations.push_back(fmt::format("the resumed sheet did not finish: job {}, sheet {}: {}", job["state"].get<std::string>(),
                                         job["sheets"][0]["state"].get<std::string>(), job["error"].get<std::string>()));
  return job;
}

// The job stopped before its fault struck (the starvation net held it): the fault was not
// tried. The jet rule still holds for what the machine did; the job is cancelled.
RunRecord disturbed_run(Rig& r, const Fault& fault, const std::string& id, const Json& job, const Options& opt,
                        double wall_s) {
  RunRecord rec;
  const MachineLog log = parse_machine_log(sim::testing::read_log(r.cell.log()));
  const JetCheck jet = check_jet_off_at_standstill(log, opt.jet_limit_ms / 1000, opt.restart_limit_ms / 1000);
  rec.violations = jet.violations;
  call_ok(r.c(), "job.cancel", {{"job", id}});
  rec.json = {{"fault", fault.name},
              {"outcome", rec.violations.empty() ? "disturbed" : "violation"},
              {"why", fmt::format("the job was {} before the fault: {}", job["state"].get<std::string>(),
                                  job.value("error", std::string()))},
              {"jet_standstills", jet.standstills_with_jet},
              {"jet_worst_ms", jet.worst_wall_s * 1000},
              {"wall_s", wall_s},
              {"violations", rec.violations}};
  return rec;
}

RunRecord run_once(const Options& opt, const Fault& fault, std::size_t index) {
  Rng rng(opt.seed * 1'000'003 + index);
  RunRecord rec;
  const auto t0 = std::chrono::steady_clock::now();
  Rig r(opt.time_scale, fault.needs_disk);
  if (fault.needs_disk && !r.disk->mounted()) {
    rec.json = {{"fault", fault.name}, {"outcome", "skipped"}, {"why", "cannot mount a tmpfs: " + r.disk->why()}};
    return rec;
  }
  const std::string id = start_cutting(r.c(), r.cell, 0);
  const Json planned = call_ok(r.c(), "job.get", {{"job", id}});
  const std::string program_path = planned["sheets"][0]["program"];
  const std::size_t lines = planned["sheets"][0]["lines"];
  const auto at_block = static_cast<std::size_t>(uniform(rng, 0.02, 0.95) * static_cast<double>(lines));
  // A machine held before the fault (the hold watch's answer to a host that fell behind, at 40×
  // on a loaded machine) ends the wait too: that run is "disturbed", not a run of its fault.
  const auto reached = [&](std::size_t n) {
    return [n](const Json& s) {
      return s["executed_blocks"].get<std::size_t>() >= n || s["state"] == "idle" || s["state"] == "hold";
    };
  };
  sim::testing::wait_status(r.cell.sim.control_port(), reached(at_block > 40 ? at_block - 40 : 0), 300);
  r.control(fmt::format("time-scale {}", opt.fault_time_scale));
  sim::testing::wait_status(r.cell.sim.control_port(), reached(at_block), 300);
  r.reconnect();  // the daemon closes a client silent for its idle timeout (600 s), as configured
  if (const Json before = call_ok(r.c(), "job.get", {{"job", id}}); before["state"] != "cutting")
    return disturbed_run(r, fault, id, before, opt, seconds_since(t0));
  const std::size_t struck_at = r.status()["executed_blocks"];
  fault.strike(r, rng);
  expect_stopped(r, id, fault.name != "kill9", rec);
  fault.clear(r, rng);

  const Json told = told_view(call_ok(r.c(), "job.get", {{"job", id}}));
  const Json disk = state_on_disk(r.cell.dir.file("state/lamina.db"), id);
  if (told != disk) rec.violations.push_back("clients were told " + told.dump() + ", the disk holds " + disk.dump());

  const Json job = resume_to_the_sheet_end(r, id, rec, opt.time_scale);
  const MachineLog log = parse_machine_log(sim::testing::read_log(r.cell.log()));
  const ContourCheck contours =
      check_contours_cut_once(program_lines(program_path), log, job["sheets"][0]["state"] == "done");
  const JetCheck jet = check_jet_off_at_standstill(log, opt.jet_limit_ms / 1000, opt.restart_limit_ms / 1000);
  for (const auto* list : {&contours.violations, &jet.violations})
    rec.violations.insert(rec.violations.end(), list->begin(), list->end());
  if (auto j = call_ok(r.c(), "job.get", {{"job", id}}); j["state"] == "waiting_sheet")
    call_ok(r.c(), "job.cancel", {{"job", id}});
  rec.json = {{"fault", fault.name},     {"lines", lines},
              {"struck_at_block", struck_at}, {"contours", contours.contours},
              {"finished", contours.finished}, {"cut_again", contours.cut_again},
              {"passes", contours.passes},    {"jet_standstills", jet.standstills_with_jet},
              {"jet_worst_ms", jet.worst_wall_s * 1000}, {"restarts_in_kerf", jet.restarts_in_kerf},
              {"restart_worst_ms", jet.worst_restart_wall_s * 1000}, {"wall_s", seconds_since(t0)},
              {"starvation_holds", rec.starvation_holds},
              {"outcome", rec.violations.empty() ? "ok" : "violation"}, {"violations", rec.violations}};
  return rec;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

Options parse_options(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++i];
    };
    if (a == "--runs") o.runs = std::stoul(value());
    else if (a == "--seed") o.seed = std::stoull(value());
    else if (a == "--faults") o.faults = split(value());
    else if (a == "--time-scale") o.time_scale = std::stod(value());
    else if (a == "--fault-time-scale") o.fault_time_scale = std::stod(value());
    else if (a == "--jet-limit-ms") o.jet_limit_ms = std::stod(value());
    else if (a == "--restart-limit-ms") o.restart_limit_ms = std::stod(value());
    else if (a == "--out") o.out = value();
    else if (a == "--only-run") o.only_run = std::stoul(value());
    else throw std::runtime_error("unknown option " + a + " (--runs --seed --faults --time-scale --fault-time-scale --jet-limit-ms --restart-limit-ms --out --only-run)");
  }
  for (const auto& name : o.faults)
    if (std::none_of(faults().begin(), faults().end(), [&](const Fault& f) { return f.name == name; }))
      throw std::runtime_error("unknown fault '" + name + "'");
  return o;
}

int run_campaign(const Options& opt) {
  std::vector<const Fault*> chosen;
  for (const Fault& f : faults())
    if (opt.faults.empty() || std::find(opt.faults.begin(), opt.faults.end(), f.name) != opt.faults.end()) chosen.push_back(&f);
  std::ofstream out;
  if (!opt.out.empty()) out.open(opt.out);
  std::map<std::string, std::array<std::size_t, 4>> tally;  // runs, violating runs, skipped, disturbed
  std::map<std::string, double> worst_jet_ms;
  for (std::size_t i = 0; i < opt.runs; ++i) {
    if (opt.only_run && i + 1 != opt.only_run) continue;
    const Fault& fault = *chosen[i % chosen.size()];  // round robin: each fault as often
    RunRecord rec;
    try {
      rec = run_once(opt, fault, i);
    } catch (const std::exception& e) {
      rec.violations.push_back(std::string("the run could not go on: ") + e.what());
      rec.json = {{"fault", fault.name}, {"outcome", "error"}, {"violations", rec.violations}};
    }
    rec.json["run"] = i + 1;
    rec.json["seed"] = opt.seed;
    auto& t = tally[fault.name];
    ++t[0];
    if (!rec.violations.empty()) ++t[1];
    if (rec.json.value("outcome", "") == "skipped") ++t[2];
    if (rec.json.value("outcome", "") == "disturbed") ++t[3];
    worst_jet_ms[fault.name] = std::max(worst_jet_ms[fault.name], rec.json.value("jet_worst_ms", 0.0));
    if (out) out << rec.json.dump() << '\n' << std::flush;
    fmt::print("run {:>3} {:<14} {}\n", i + 1, fault.name, rec.violations.empty() ? rec.json.value("outcome", "ok") : rec.violations.front());
    std::fflush(stdout);
  }
  std::size_t bad = 0;
  fmt::print("\n{:<14} {:>5} {:>10} {:>8} {:>10} {:>16}\n", "fault", "runs", "violating", "skipped", "disturbed",
             "worst jet (ms)");
  for (const auto& [name, t] : tally) {
    fmt::print("{:<14} {:>5} {:>10} {:>8} {:>10} {:>16.0f}\n", name, t[0], t[1], t[2], t[3], worst_jet_ms[name]);
    bad += t[1];
  }
  fmt::print("{} runs, {} with violations (seed {}, --time-scale {} and {} at the fault, jet limit {} ms, restart {} ms)\n",
             opt.runs, bad, opt.seed, opt.time_scale, opt.fault_time_scale, opt.jet_limit_ms, opt.restart_limit_ms);
  return bad == 0 ? 0 : 1;
}

}  // namespace
}  // namespace lamina::campaign

int main(int argc, char** argv) {
  try {
    return lamina::campaign::run_campaign(lamina::campaign::parse_options(argc, argv));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fault-campaign: %s\n", e.what());
    return 2;
  }
}
