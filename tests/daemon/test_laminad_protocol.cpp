// A malformed or hostile client gets its error and the daemon keeps serving everyone else:
// bad JSON, oversized lines, unknown methods, bad params, TCP without the token; 50 clients at
// once while a job streams; sd_notify READY/STOPPING.
#include <gtest/gtest.h>

#include <sys/socket.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/un.h>

#include <atomic>
#include <algorithm>
#include <chrono>
#include <fstream>
#include <thread>

#include "daemon_fixture.hpp"
#include "http_test_client.hpp"

namespace lamina::daemon::testing {
namespace {

// A raw line on a fresh connection; the first reply line (empty when the daemon closed it).
std::string raw_exchange(const std::string& socket, const std::string& bytes) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", socket.c_str());
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) return "connect failed";
  std::size_t sent = 0;
  while (sent < bytes.size()) {
    const auto n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<std::size_t>(n);
  }
  std::string reply;
  char c;
  pollfd p{fd, POLLIN, 0};
  while (::poll(&p, 1, 5000) > 0 && ::read(fd, &c, 1) == 1 && c != '\n') reply += c;
  ::close(fd);
  return reply;
}

int error_code(const std::string& reply) {
  const Json j = Json::parse(reply);
  return j.at("error").at("code").get<int>();
}

// What laminad warns about reaches the people at the cell (the console's Warnings): every
// logger's warnings, its own at start-up and the RPC server's, in order, and only the new ones
// for a client that says what it has seen.
TEST(LaminadProtocol, TheDaemonsWarningsAreThereForTheConsole) {
  Cell cell;
  std::string config = cell.config();
  const std::string roots = "roots = [\"";
  ASSERT_NE(config.find(roots), std::string::npos) << config;
  config.replace(config.find(roots), roots.size(), roots + cell.dir.file("no-such-folder") + "\", \"");
  Laminad daemon(config, cell.dir.file(""));
  RpcClient c = connect(cell.socket());
  EXPECT_EQ(error_code(raw_exchange(cell.socket(), std::string(2 << 20, 'x') + "\n")), -32600);

  Json all;
  for (int i = 0; i < 100 && (all.empty() || all["warnings"].size() < 2); ++i) {  // the RPC's is logged as it closes
    all = call_ok(c, "server.warnings");
    if (all["warnings"].size() < 2) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_GE(all["warnings"].size(), 2u) << all.dump(1) << daemon.log();
  const Json& first = all["warnings"][0];
  EXPECT_EQ(first["source"], "laminad");
  EXPECT_EQ(first["level"], "warning");
  EXPECT_NE(first["message"].get<std::string>().find("no-such-folder is not a folder"), std::string::npos) << first;
  const auto rpc = std::find_if(all["warnings"].begin(), all["warnings"].end(), [](const Json& w) { return w["source"] == "rpc"; });
  ASSERT_NE(rpc, all["warnings"].end()) << all.dump(1);
  EXPECT_NE((*rpc)["message"].get<std::string>().find("over the limit"), std::string::npos) << *rpc;
  EXPECT_GT((*rpc)["seq"].get<std::uint64_t>(), first["seq"].get<std::uint64_t>());
  EXPECT_EQ(all["last"], all["warnings"].back()["seq"]);

  const Json none = call_ok(c, "server.warnings", {{"since", all["last"]}});
  EXPECT_TRUE(none["warnings"].empty()) << none;
  EXPECT_EQ(none["last"], all["last"]);
  auto negative = c.call("server.warnings", {{"since", -1}});
  ASSERT_FALSE(negative);
  EXPECT_EQ(negative.error().code, -32602);
}

TEST(LaminadProtocol, EveryBadRequestGetsItsErrorAndTheDaemonKeepsServing) {
  Cell cell;
  Laminad daemon(cell.config(), cell.dir.file(""));
  RpcClient c = connect(cell.socket());
  EXPECT_EQ(error_code(raw_exchange(cell.socket(), "{not json\n")), -32700);
  EXPECT_EQ(error_code(raw_exchange(cell.socket(), "[1,2]\n")), -32600);
  EXPECT_EQ(error_code(raw_exchange(cell.socket(), R"({"jsonrpc":"1.0","id":1,"method":"job.list"})" "\n")), -32600);
  EXPECT_EQ(error_code(raw_exchange(cell.socket(), std::string(2 << 20, 'x') + "\n")), -32600);
  auto unknown = c.call("job.explode");
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().code, -32601);
  for (const Json& params : {Json::object(), Json{{"job", 5}}}) {
    auto r = c.call("job.get", params);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, -32602) << params;
  }
  auto relative = c.call("job.submit", {{"model", "knob.stl"}});
  ASSERT_FALSE(relative);
  EXPECT_EQ(relative.error().code, -32602);
  auto bad_setting = c.call("job.submit", {{"model", std::string(LAMINA_EXAMPLES_DIR) + "/knob.stl"}, {"settings", {{"strategy", "wavy"}}}});
  ASSERT_FALSE(bad_setting);
  EXPECT_EQ(bad_setting.error().code, -32602);
  EXPECT_NE(bad_setting.error().message.find("strategy"), std::string::npos) << bad_setting.error().message;
  auto missing = c.call("job.get", {{"job", "j-0-0000"}});
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code, -32010);
  auto nothing = c.call("machine.hold");
  ASSERT_FALSE(nothing);
  EXPECT_EQ(nothing.error().code, -32011);
  // Still serving, on the first connection and new ones.
  EXPECT_TRUE(call_ok(c, "job.list").is_array());
  RpcClient other = connect(cell.socket());
  EXPECT_EQ(call_ok(other, "server.info")["name"], "laminad");
  EXPECT_TRUE(daemon.running());
}

// Issue 16, item 9: a client named /etc/shadow and read its first bytes in job.error. Files
// outside [jobs] roots are refused at submit, in the answer and in no job; stock files too.
TEST(LaminadProtocol, ASubmitReadsNoFileOutsideTheRoots) {
  Cell cell;
  Laminad daemon(cell.config(), cell.dir.file(""));
  RpcClient c = connect(cell.socket());
  std::ofstream(cell.dir.file("secret.stl")) << "solid TOP-SECRET-BYTES\n";
  for (const std::string& model : {std::string("/etc/shadow"), cell.dir.file("secret.stl"),
                                   std::string(LAMINA_EXAMPLES_DIR) + "/../../etc/shadow"}) {
    auto r = c.call("job.submit", {{"model", model}});
    ASSERT_FALSE(r) << model;
    EXPECT_EQ(r.error().code, -32602);
    EXPECT_NE(r.error().message.find("outside the folders jobs may read"), std::string::npos) << r.error().message;
    EXPECT_EQ(r.error().message.find("TOP-SECRET"), std::string::npos);
  }
  auto stock = c.call("job.submit", {{"model", std::string(LAMINA_EXAMPLES_DIR) + "/knob.stl"},
                                     {"settings", {{"stock_file", "/etc/passwd"}}}});
  ASSERT_FALSE(stock);
  EXPECT_NE(stock.error().message.find("settings.stock_file: /etc/passwd is outside"), std::string::npos)
      << stock.error().message;
  EXPECT_TRUE(call_ok(c, "job.list").empty()) << "no job was made of a refused file";
  EXPECT_EQ(daemon.log().find("TOP-SECRET"), std::string::npos);

  // Inside a root, a file that is no model fails its job, and the reader's message describes
  // the bytes instead of quoting them (lamina plan --no-quote-input).
  std::filesystem::create_directories(cell.dir.file("parts"));
  std::ofstream(cell.dir.file("parts/notes.stl")) << "solid TOP-SECRET-BYTES\nfacet TOP-SECRET-2 nonsense\n";
  const Json job = call_ok(c, "job.submit", {{"model", cell.dir.file("parts/notes.stl")}});
  const Json failed = wait_state(c, job["id"], "failed", 60);
  ASSERT_EQ(failed["state"], "failed") << failed.dump(2);
  EXPECT_EQ(failed["error"].get<std::string>().find("TOP-SECRET"), std::string::npos) << failed["error"];
  EXPECT_EQ(daemon.log().find("TOP-SECRET"), std::string::npos);
}

// Issue 16, item 10: a submit with a mistyped setting used the upload up and left its file;
// now the upload stays for the corrected submit, and a cancelled one is gone with its file.
TEST(LaminadProtocol, ABadSettingLeavesTheUploadForTheNextTry) {
  Cell cell;
  Laminad daemon(cell.config(), cell.dir.file(""));
  RpcClient c = connect(cell.socket());
  const Json begun = call_ok(c, "upload.begin", {{"name", "tiny.stl"}, {"size", 3}});
  const std::string id = begun["upload"];
  call_ok(c, "upload.chunk", {{"upload", id}, {"offset", 0}, {"data", "Zm9v"}});
  auto bad = c.call("job.submit", {{"upload", id}, {"settings", {{"strategy", "wavy"}}}});
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("strategy"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(cell.dir.file("state/uploads/" + id + "-tiny.stl")));
  call_ok(c, "upload.cancel", {{"upload", id}});
  EXPECT_FALSE(std::filesystem::exists(cell.dir.file("state/uploads/" + id + "-tiny.stl")));
  auto taken = c.call("job.submit", {{"upload", id}});
  ASSERT_FALSE(taken);
  EXPECT_NE(taken.error().message.find("no upload"), std::string::npos) << taken.error().message;
}

TEST(LaminadProtocol, TcpNeedsTheToken) {
  Cell cell;
  const int port = free_loopback_port();
  Laminad daemon(cell.config(fmt::format("tcp = \"127.0.0.1:{}\"\ntoken = \"s3cret-token\"", port)), cell.dir.file(""));
  (void)connect(cell.socket());  // up
  // Without a token (our client refuses to send none: a raw socket does).
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  const std::string request = R"({"jsonrpc":"2.0","id":1,"method":"job.list","params":{}})" "\n";
  ASSERT_EQ(::send(fd, request.data(), request.size(), MSG_NOSIGNAL), static_cast<ssize_t>(request.size()));
  std::string reply;
  char ch;
  pollfd p{fd, POLLIN, 0};
  while (::poll(&p, 1, 5000) > 0 && ::read(fd, &ch, 1) == 1 && ch != '\n') reply += ch;
  ::close(fd);
  EXPECT_EQ(error_code(reply), -32001) << reply;
  auto wrong = RpcClient::connect_tcp("127.0.0.1", port, "guess");
  ASSERT_TRUE(wrong);
  auto r = wrong->call("job.list");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, -32001);
  auto right = RpcClient::connect_tcp("127.0.0.1", port, "s3cret-token");
  ASSERT_TRUE(right);
  EXPECT_TRUE(right->call("job.list"));
}

// Issue 16, item 8: 100 strangers sending a MiB of '[' held the only io thread for 40 s, and 128
// idle connections locked every new client out. Under both at once, the operator connects and
// the hold reaches the machine (bounded waits for the events, no time measured here: that is
// bench/hold_under_attack.sh).
TEST(LaminadProtocol, TheOperatorsHoldGetsThroughUnderAttack) {
  Cell cell({}, 10);
  const int port = free_loopback_port();
  Laminad daemon(cell.config(fmt::format("tcp = \"127.0.0.1:{}\"\ntoken = \"s3cret-token\"", port)), cell.dir.file(""));
  RpcClient c = connect(cell.socket());
  const std::string id = start_cutting(c, cell, 50);

  std::vector<int> idle;
  for (int i = 0; i < 130; ++i) {
    const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", cell.socket().c_str());
    if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0) idle.push_back(fd);
    else ::close(fd);
  }
  std::atomic<bool> stop{false};
  std::vector<std::thread> strangers;
  for (int i = 0; i < 40; ++i)
    strangers.emplace_back([&] {
      const std::string brackets(1 << 20, '[');
      while (!stop) {
        const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
        sockaddr_in addr{};
        addr.sin_family = AF_INET;
        addr.sin_port = htons(static_cast<std::uint16_t>(port));
        addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0) {
          (void)::send(fd, brackets.data(), brackets.size(), MSG_NOSIGNAL);
          ::shutdown(fd, SHUT_WR);
          char sink[4096];
          while (::recv(fd, sink, sizeof sink, 0) > 0) {
          }
        }
        ::close(fd);
      }
    });
  std::this_thread::sleep_for(std::chrono::milliseconds(1200));  // the idle ones have been idle a while

  RpcClient op = connect(cell.socket(), 10);
  auto held = op.call("machine.hold", Json::object(), 30);
  stop = true;
  for (auto& t : strangers) t.join();
  for (int fd : idle) ::close(fd);
  ASSERT_TRUE(held) << held.error().message << "\n" << daemon.log();
  EXPECT_TRUE(sim::testing::wait_status(cell.sim.control_port(), [](const Json& s) { return s["state"] == "hold"; }, 30));
  EXPECT_TRUE(daemon.running());
  call_ok(op, "job.cancel", {{"job", id}});
}

TEST(LaminadProtocol, FiftyClientsWhileAJobStreamsAreAllAnswered) {
  Cell cell({}, 10);
  Laminad daemon(cell.config(), cell.dir.file(""));
  RpcClient c = connect(cell.socket());
  const std::string id = start_cutting(c, cell, 50);
  std::atomic<int> ok{0}, bad{0};
  std::vector<std::thread> clients;
  for (int i = 0; i < 50; ++i)
    clients.emplace_back([&, i] {
      auto cl = RpcClient::connect_unix(cell.socket());
      if (!cl) {
        ++bad;
        return;
      }
      for (int k = 0; k < 20; ++k) {
        auto r = cl->call(k % 2 ? "job.list" : "machine.status", Json::object(), 10);
        (r && (k % 2 ? r->is_array() : r->contains("state"))) ? ++ok : ++bad;
      }
      (void)i;
    });
  for (auto& t : clients) t.join();
  EXPECT_EQ(ok.load(), 1000);
  EXPECT_EQ(bad.load(), 0);
  const Json st = sim::testing::control_status(cell.sim.control_port());
  EXPECT_EQ(st["starvation"], 0) << "the daemon kept the CNC fed while serving: " << st.dump();
  call_ok(c, "job.cancel", {{"job", id}});
}

// A model from another machine: `lamina submit --upload` sends it in chunks; the job plans it
// from its own copy in the job's folder.
TEST(LaminadProtocol, UploadedModelIsPlanned) {
  Cell cell;
  Laminad daemon(cell.config(), cell.dir.file(""));
  (void)connect(cell.socket());
  const ClientRun run = run_client(cell.socket(), fmt::format("submit '{}/knob.stl' --upload --set stock=10 --json",
                                                             LAMINA_EXAMPLES_DIR));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const Json job = Json::parse(run.output);
  const std::string model = job["model"];
  EXPECT_NE(model.find("/jobs/"), std::string::npos) << "the upload lives with its job: " << model;
  std::ifstream original(std::string(LAMINA_EXAMPLES_DIR) + "/knob.stl", std::ios::binary), copy(model, std::ios::binary);
  EXPECT_TRUE(std::equal(std::istreambuf_iterator<char>(original), {}, std::istreambuf_iterator<char>(copy)));
  RpcClient c = connect(cell.socket());
  EXPECT_EQ(wait_state(c, job["id"], "waiting_sheet", 120)["state"], "waiting_sheet");
}

// A customer's STEP file, uploaded: planned by a planner built with OpenCASCADE; a planner built
// without it (the sanitizer build) fails the job with the reason, and the daemon goes on.
TEST(LaminadProtocol, AnUploadedStepFileIsPlannedOrSaysWhyNot) {
  const std::string step = std::string(LAMINA_SHARED_MODELS) + "/step_cube_cylinder.step";
  if (!std::filesystem::exists(step)) GTEST_SKIP() << step << " is not here";
  Cell cell;
  Laminad daemon(cell.config(), cell.dir.file(""));
  const ClientRun run = run_client(cell.socket(), fmt::format("submit '{}' --upload --set stock=10 --json", step));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const Json job = Json::parse(run.output);
  RpcClient c = connect(cell.socket());
  const Json done = wait_job(c, job["id"], [](const Json& j) {
    return j["state"] == "waiting_sheet" || j["state"] == "failed";
  }, 120);
  if (LAMINA_CLI_READS_STEP) {
    ASSERT_EQ(done["state"], "waiting_sheet") << done.dump(2);
    EXPECT_EQ(done["sheets"].size(), 1u);
  } else {
    ASSERT_EQ(done["state"], "failed") << done.dump(2);
    EXPECT_NE(done["error"].get<std::string>().find("without STEP support"), std::string::npos) << done["error"];
  }
  EXPECT_TRUE(daemon.running());
}

// systemd may stop a unit the moment it started. Once the socket exists the daemon handles
// SIGTERM itself (a clean exit 0), never the default action that kills it mid-start.
TEST(LaminadProtocol, ASigtermRightAfterTheSocketAppearsIsACleanStop) {
  Cell cell;
  for (int round = 0; round < 5; ++round) {
    Laminad daemon(cell.config(), cell.dir.file(""));
    const auto t0 = std::chrono::steady_clock::now();
    while (!std::filesystem::exists(cell.socket()) && seconds_since(t0) < 20)
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    ASSERT_TRUE(std::filesystem::exists(cell.socket()));
    EXPECT_EQ(daemon.stop(SIGTERM), 0) << "round " << round << "\n" << daemon.log();
  }
}

// sd_notify: READY=1 once the socket listens, STOPPING=1 on SIGTERM (NOTIFY_SOCKET pointed at a
// datagram socket of the test, as systemd would).
TEST(LaminadProtocol, TellsSystemdWhenReadyAndWhenStopping) {
  Cell cell;
  const std::string notify_path = cell.dir.file("notify.sock");
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", notify_path.c_str());
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  auto next_message = [&](double wait_s) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(wait_s * 1000)) <= 0) return std::string();
    char buf[4096];
    const auto n = ::recv(fd, buf, sizeof buf, 0);
    return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
  };
  Laminad daemon(cell.config(), cell.dir.file(""), {"NOTIFY_SOCKET=" + notify_path});
  std::string ready = next_message(20);
  EXPECT_NE(ready.find("READY=1"), std::string::npos) << ready;
  EXPECT_TRUE(RpcClient::connect_unix(cell.socket())) << "READY comes after the socket listens";
  EXPECT_EQ(daemon.stop(SIGTERM), 0);
  bool stopping = false;
  for (std::string m = next_message(5); !m.empty(); m = next_message(1)) stopping = stopping || m.find("STOPPING=1") != std::string::npos;
  EXPECT_TRUE(stopping);
  ::close(fd);
}

}  // namespace
}  // namespace lamina::daemon::testing
