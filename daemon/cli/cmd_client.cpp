// The daemon's client commands: lamina submit | jobs | job | status | hold | resume | abort |
// confirm | cancel. They speak JSON-RPC to laminad (docs/api.md) over its Unix socket, or TCP
// with a token; --json prints the daemon's answer as it came.
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "lamina/daemon/rpc_client.hpp"

namespace lamina::cli {
namespace {

using Json = nlohmann::json;
using daemon::RpcClient;

struct ClientOptions {
  std::string socket;
  std::string tcp, token;
  bool json = false;
};

std::string default_socket() {
  if (const char* s = std::getenv("LAMINA_SOCKET")) return s;
  return "/run/lamina/lamina.sock";
}

std::expected<RpcClient, std::string> connect(const ClientOptions& o) {
  if (!o.tcp.empty()) {
    const auto colon = o.tcp.rfind(':');
    if (colon == std::string::npos) return std::unexpected(fmt::format("--tcp '{}': expected HOST:PORT", o.tcp));
    int port = 0;
    try {
      port = std::stoi(o.tcp.substr(colon + 1));
    } catch (const std::exception&) {
      return std::unexpected(fmt::format("--tcp '{}': the port is not a number", o.tcp));
    }
    std::string token = o.token;
    if (token.empty())
      if (const char* t = std::getenv("LAMINA_TOKEN")) token = t;
    return RpcClient::connect_tcp(o.tcp.substr(0, colon), port, token);
  }
  return RpcClient::connect_unix(o.socket.empty() ? default_socket() : o.socket);
}

// One call; prints the error (code and message) and returns nullopt when it failed.
std::optional<Json> call(const ClientOptions& o, const std::string& method, Json params = Json::object()) {
  auto client = connect(o);
  if (!client) {
    fmt::print(stderr, "lamina: cannot reach laminad: {}\n", client.error());
    return std::nullopt;
  }
  auto r = client->call(method, std::move(params));
  if (!r) {
    fmt::print(stderr, "lamina: {} failed: {} (code {})\n", method, r.error().message, r.error().code);
    return std::nullopt;
  }
  return *r;
}

std::string position_text(const Json& p) {
  if (!p.is_object()) return "-";
  return fmt::format("X{:.3f} Y{:.3f} Z{:.3f} A{:.2f} C{:.2f}", p.value("x_mm", 0.0), p.value("y_mm", 0.0),
                     p.value("z_mm", 0.0), p.value("a_deg", 0.0), p.value("c_deg", 0.0));
}

// `lamina status`: state, position, feed, job with its sheet and line, a latched PLC alarm — in
// words where the controller has not reported yet (no position) or there is no job, not dashes.
std::string status_line(const Json& s) {
  const std::string state = s.value("state", "unknown");
  const bool reported = s.contains("position") && s["position"].is_object();
  std::string line;
  if (!reported) {
    // The PLC may have read the CNC's state already; the position comes with the controller's report.
    line = state == "unknown" ? "machine not connected yet" : fmt::format("{} (the PLC's reading of the CNC)", state);
    line += ": waiting for the controller's first report";
    if (s.contains("link") && s["link"].is_string()) line += fmt::format(" ({})", s["link"].get<std::string>());
  } else {
    line = fmt::format("{}  {}", state, position_text(s["position"]));
    const Json feed = s.value("feed_mm_per_s", Json());
    if (feed.is_number()) line += fmt::format("  F{:.0f} mm/min", feed.get<double>() * 60);
  }
  if (s.contains("job") && s["job"].is_string()) {
    line += fmt::format("  job {}", s["job"].get<std::string>());
    if (s.contains("sheet")) line += fmt::format(" sheet {}", s["sheet"].dump());
    if (s.contains("program_line")) line += fmt::format(" line {}", s["program_line"].dump());
  } else {
    line += "  no job";
  }
  if (s.contains("cell") && s["cell"].value("alarm_latched", Json()) == true)
    line += fmt::format("  PLC alarm {} latched", s["cell"].value("alarm_code", Json()).dump());
  if (s.contains("cell") && s["cell"].contains("fault")) line += "  cell: " + s["cell"]["fault"].get<std::string>();
  return line;
}

void print_job(const Json& j) {
  fmt::print("{}  {}  {}  sheet {}/{}{}\n", j.value("id", "?"), j.value("state", "?"), j.value("name", ""),
             j.value("current_sheet", 0), j.contains("sheets") && j["sheets"].is_array() ? j["sheets"].size() : 0,
             j.value("error", "").empty() ? "" : "  (" + j.value("error", "") + ")");
}

std::string bar(double fraction) {
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * kWidth);
  return fmt::format("[{}{}]", std::string(static_cast<std::size_t>(filled), '#'),
                     std::string(static_cast<std::size_t>(kWidth - filled), '-'));
}

// Follows a job through planning and cutting until it needs the operator or ends.
int follow(const ClientOptions& o, const std::string& id) {
  auto client = connect(o);
  if (!client) return 1;
  if (!client->call("server.subscribe")) return 1;
  auto job = client->call("job.get", {{"job", id}});
  if (!job) return 1;
  Json j = *job;
  const bool tty = ::isatty(STDERR_FILENO);
  int planning_step_shown = 0;
  while (true) {
    const std::string state = j.value("state", "");
    if (j.value("id", "") == id) {
      std::string line = fmt::format("{} {}", id, state);
      if (j.contains("planning") && j["planning"].is_object()) {
        const Json& p = j["planning"];
        const int step = p.value("step", 0), steps = p.value("steps", 0);
        line += fmt::format(" {} {}/{} {}", bar(steps ? double(step - 1) / steps : 0), step, steps, p.value("phase", ""));
        if (!tty && step != planning_step_shown) fmt::print(stderr, "{}\n", line);  // a log keeps each phase
        planning_step_shown = step;
      }
      if (j.contains("progress")) {
        const Json& p = j["progress"];
        const double f = p.value("lines", 0) ? p.value("lines_accepted", 0) / double(p.value("lines", 1)) : 0;
        line += fmt::format(" sheet {} {} {:5.1f} %", p.value("sheet", 0), bar(f), 100 * f);
      }
      if (tty) fmt::print(stderr, "\r{:<100}", line);
      if (state == "completed" || state == "failed" || state == "cancelled" || state == "interrupted" ||
          state == "waiting_sheet" || state == "paused") {
        if (tty) fmt::print(stderr, "\n");
        print_job(j);
        if (state == "waiting_sheet")
          fmt::print("load sheet {} on the table, then: lamina confirm {} {}\n", j.value("current_sheet", 0), id,
                     j.value("current_sheet", 0));
        if (state == "completed" && j.contains("summary")) fmt::print("{}\n", j["summary"].dump(2));
        return state == "failed" || state == "cancelled" ? 1 : 0;
      }
    }
    auto n = client->next_notification(3600);
    if (!n) return 1;
    if (n->value("method", "") == "notify_job_progress") j = (*n)["params"];
  }
}

std::string encode_base64(std::string_view bytes) {
  static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    unsigned v = 0;
    for (std::size_t k = 0; k < 3; ++k) v = v << 8 | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k) out += k <= n ? alphabet[v >> (18 - 6 * k) & 63] : '=';
  }
  return out;
}

// upload.begin, then 384 kB chunks; the upload id for job.submit.
std::expected<std::string, std::string> upload_file(const ClientOptions& o, const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::unexpected(fmt::format("cannot read {}", path));
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  auto client = connect(o);
  if (!client) return std::unexpected(client.error());
  auto begun = client->call("upload.begin", {{"name", std::filesystem::path(path).filename().string()}, {"size", bytes.size()}});
  if (!begun) return std::unexpected(begun.error().message);
  const std::string id = (*begun)["upload"];
  constexpr std::size_t kChunk = 384 << 10;
  for (std::size_t offset = 0; offset < bytes.size(); offset += kChunk) {
    const std::string_view piece = std::string_view(bytes).substr(offset, kChunk);
    auto r = client->call("upload.chunk", {{"upload", id}, {"offset", offset}, {"data", encode_base64(piece)}}, 60);
    if (!r) return std::unexpected(r.error().message);
  }
  return id;
}

void add_common(CLI::App* cmd, ClientOptions& o) {
  cmd->add_option("--socket", o.socket, "laminad's Unix socket (default $LAMINA_SOCKET or /run/lamina/lamina.sock)");
  cmd->add_option("--tcp", o.tcp, "laminad over TCP, HOST:PORT (token from --token or $LAMINA_TOKEN)");
  cmd->add_option("--token", o.token, "the daemon's TCP token");
  cmd->add_flag("--json", o.json, "print the daemon's answer as JSON");
}

// Prints the reply as JSON (--json) or as a person reads it.
void print_or(const ClientOptions& o, const Json& result, const std::function<void(const Json&)>& human) {
  if (o.json)
    fmt::print("{}\n", result.dump(2));
  else
    human(result);
}

// One request, its answer printed (print_or); a failed call was reported by call() and exits 1.
void call_and_print(const ClientOptions& o, const std::string& method, const Json& params,
                    const std::function<void(const Json&)>& human, int& exit_code) {
  auto r = call(o, method, params);
  if (!r) {
    exit_code = 1;
    return;
  }
  print_or(o, *r, human);
}

void print_dump(const Json& j) { fmt::print("{}\n", j.dump()); }

// --set KEY=VALUE… as the settings object: numbers and booleans as JSON, anything else as text.
std::expected<Json, std::string> settings_from(const std::vector<std::string>& sets) {
  Json settings = Json::object();
  for (const std::string& kv : sets) {
    const auto eq = kv.find('=');
    if (eq == std::string::npos) return std::unexpected(fmt::format("--set {}: expected KEY=VALUE", kv));
    const std::string key = kv.substr(0, eq), value = kv.substr(eq + 1);
    try {
      settings[key] = Json::parse(value);
      if (settings[key].is_string() || settings[key].is_object() || settings[key].is_array()) settings[key] = value;
    } catch (const std::exception&) {
      settings[key] = value;
    }
  }
  return settings;
}

void add_submit_command(CLI::App& app, const std::shared_ptr<ClientOptions>& o, int& exit_code) {
  struct Submit {
    std::string model, name;
    std::vector<std::string> set;
    bool follow = false;
    bool upload = false;
  };
  auto s = std::make_shared<Submit>();
  auto* cmd = app.add_subcommand("submit", "submit a model to laminad: it plans it, then cuts it sheet by sheet");
  cmd->add_option("model", s->model, "mesh file on the cell PC")->required();
  cmd->add_option("--name", s->name, "the job's name (default: the file name)");
  cmd->add_option("--set", s->set, "plan setting KEY=VALUE (docs/api.md), e.g. strategy=curved microjoints=2");
  cmd->add_flag("--follow", s->follow, "show planning and cutting progress until the job needs you");
  cmd->add_flag("--upload", s->upload, "send the file over the connection (the daemon is on another machine)");
  add_common(cmd, *o);
  cmd->callback([o, s, &exit_code] {
    auto settings = settings_from(s->set);
    if (!settings) {
      fmt::print(stderr, "lamina submit: {}\n", settings.error());
      exit_code = 2;
      return;
    }
    std::error_code ec;
    const std::string model = std::filesystem::absolute(s->model, ec).string();
    Json params{{"model", model}, {"settings", *settings}};
    if (s->upload) {
      auto id = upload_file(*o, model);
      if (!id) {
        fmt::print(stderr, "lamina submit: {}\n", id.error());
        exit_code = 1;
        return;
      }
      params.erase("model");
      params["upload"] = *id;
    }
    if (!s->name.empty()) params["name"] = s->name;
    auto r = call(*o, "job.submit", params);
    if (!r) {
      exit_code = 1;
      return;
    }
    print_or(*o, *r, [](const Json& j) { fmt::print("submitted {}\n", j.value("id", "?")); });
    if (s->follow) exit_code = follow(*o, r->value("id", ""));
  });
}

void add_jobs_command(CLI::App& app, const std::shared_ptr<ClientOptions>& o, int& exit_code) {
  auto* cmd = app.add_subcommand("jobs", "list laminad's jobs");
  add_common(cmd, *o);
  cmd->callback([o, &exit_code] {
    call_and_print(*o, "job.list", Json::object(), [](const Json& list) {
      for (const Json& j : list)
        fmt::print("{}  {:<13} {}  sheet {}/{}{}\n", j.value("id", "?"), j.value("state", "?"), j.value("name", ""),
                   j.value("current_sheet", 0), j.value("sheets", 0),
                   j.value("error", "").empty() ? "" : "  (" + j.value("error", "") + ")");
    }, exit_code);
  });
}

// job / cancel / confirm: one job each; resume: a job, or without one the held machine.
void add_job_commands(CLI::App& app, const std::shared_ptr<ClientOptions>& o, int& exit_code) {
  {
    auto id = std::make_shared<std::string>();
    auto* cmd = app.add_subcommand(
        "resume", "resume a paused or interrupted JOB (from the start of the contour it was cutting); "
                  "without JOB: continue after a hold (as lamina continue)");
    cmd->add_option("job", *id, "job id");
    add_common(cmd, *o);
    cmd->callback([o, id, &exit_code] {
      if (id->empty()) call_and_print(*o, "machine.resume", Json::object(), print_dump, exit_code);
      else call_and_print(*o, "job.resume", {{"job", *id}}, print_job, exit_code);
    });
  }
  for (const auto& [name, method, help] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"job", "job.get", "show one job"},
           {"cancel", "job.cancel", "cancel a job (a cut in progress stops safely first)"}}) {
    auto id = std::make_shared<std::string>();
    auto* cmd = app.add_subcommand(name, help);
    cmd->add_option("job", *id, "job id")->required();
    add_common(cmd, *o);
    cmd->callback([o, id, method, &exit_code] {
      call_and_print(*o, method, {{"job", *id}}, print_job, exit_code);
    });
  }
  {
    auto id = std::make_shared<std::string>();
    auto sheet = std::make_shared<int>(0);
    auto* cmd = app.add_subcommand("confirm", "the sheet is on the table: cut it");
    cmd->add_option("job", *id, "job id")->required();
    cmd->add_option("sheet", *sheet, "sheet number")->required();
    add_common(cmd, *o);
    cmd->callback([o, id, sheet, &exit_code] {
      call_and_print(*o, "job.confirm_sheet", {{"job", *id}, {"sheet", *sheet}}, print_job, exit_code);
    });
  }
}

// status / hold / continue / abort: the machine.
void add_machine_commands(CLI::App& app, const std::shared_ptr<ClientOptions>& o, int& exit_code) {
  {
    auto* cmd = app.add_subcommand("status", "the machine in one line: state, position, feed, line");
    add_common(cmd, *o);
    cmd->callback([o, &exit_code] {
      call_and_print(*o, "machine.status", Json::object(), [](const Json& s) { fmt::print("{}\n", status_line(s)); },
                     exit_code);
    });
  }
  for (const auto& [name, method, help] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"hold", "machine.hold", "feed hold now (the job pauses; lamina resume goes on)"},
           {"continue", "machine.resume", "continue after a hold (or resume the stopped job)"},
           {"abort", "machine.abort", "stop the cut now: jet off, motion held; resume or cancel the job afterwards"}}) {
    auto* cmd = app.add_subcommand(name, help);
    add_common(cmd, *o);
    cmd->callback([o, method, &exit_code] {
      call_and_print(*o, method, Json::object(), print_dump, exit_code);
    });
  }
}

}  // namespace

void add_client_commands(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<ClientOptions>();
  add_submit_command(app, o, exit_code);
  add_jobs_command(app, o, exit_code);
  add_job_commands(app, o, exit_code);
  add_machine_commands(app, o, exit_code);
}

}  // namespace lamina::cli
