// laminad's web server wired to its jobs (issue 19): a planned job's artefacts over HTTP, the same
// bytes as in its folder, and nothing outside it.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fstream>

#include "daemon_fixture.hpp"
#include "http/passwords.hpp"
#include "http_test_client.hpp"
#include "ws_test_client.hpp"

namespace lamina::daemon::testing {
namespace {

std::string file_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(LaminadWeb, APlannedJobsArtefactsAreServedAsTheyAreInItsFolder) {
  Cell cell;
  const int port = free_loopback_port();
  const std::string web = cell.dir.file("web");
  std::filesystem::create_directories(web);
  std::ofstream(web + "/index.html") << "<!doctype html><title>Lamina</title>";
  Laminad daemon(cell.config("", fmt::format("listen = \"127.0.0.1:{}\"\nstatic_dir = \"{}\"", port, web)),
                 cell.dir.file(""));
  RpcClient c = connect(cell.socket());
  EXPECT_NE(daemon.log().find(fmt::format("web console: http://127.0.0.1:{}/", port)), std::string::npos) << daemon.log();
  EXPECT_EQ(body_of(http_get(port, "/")), "<!doctype html><title>Lamina</title>");

  Json job = call_ok(c, "job.submit", {{"model", std::string(LAMINA_EXAMPLES_DIR) + "/knob.stl"}, {"settings", {{"stock", "5"}}}});
  const std::string id = job["id"];
  EXPECT_TRUE(http_get(port, "/api/jobs/" + id + "/report.json").starts_with("HTTP/1.1 404")) << "not planned yet";
  job = wait_state(c, id, "waiting_sheet", 120);
  ASSERT_EQ(job["state"], "waiting_sheet") << job.dump(2) << daemon.log();
  const std::filesystem::path folder = job["artefacts"].get<std::string>();

  const std::string report = http_get(port, "/api/jobs/" + id + "/report.json");
  ASSERT_TRUE(report.starts_with("HTTP/1.1 200")) << report.substr(0, 300);
  EXPECT_EQ(body_of(report), file_text(folder / "report.json"));
  const std::string svg = http_get(port, "/api/jobs/" + id + "/sheet-1.svg");
  ASSERT_TRUE(svg.starts_with("HTTP/1.1 200")) << svg.substr(0, 300);
  EXPECT_EQ(body_of(svg), file_text(folder / "sheet-1.svg"));
  const std::string stack = http_get(port, "/api/jobs/" + id + "/stack.stl");
  EXPECT_EQ(body_of(stack).size(), std::filesystem::file_size(folder / "stack.stl"));
  EXPECT_EQ(body_of(http_get(port, "/api/jobs/" + id + "/model")), file_text(std::string(LAMINA_EXAMPLES_DIR) + "/knob.stl"));

  // The job database sits two folders up: no path reaches it.
  for (const std::string& attack : std::vector<std::string>{"/api/jobs/" + id + "/../../jobs.db", "/api/jobs/" + id + "/..%2f..%2fjobs.db",
                                   "/api/jobs/" + id + "/plan.log"}) {
    const std::string r = http_get(port, attack);
    EXPECT_TRUE(r.starts_with("HTTP/1.1 400") || r.starts_with("HTTP/1.1 404")) << attack << ": " << r.substr(0, 200);
    EXPECT_EQ(r.find("SQLite format"), std::string::npos) << attack;
  }
}

std::string web_user(const std::string& name, const std::string& role, const std::string& password) {
  return fmt::format("[[http.users]]\nname = \"{}\"\nrole = \"{}\"\npassword_hash = \"{}\"\n", name, role,
                     *http::hash_password(password));
}

// The roles on the real methods, through the browser's path (login, WebSocket), and who did what
// in the job's events.
TEST(LaminadWeb, AViewerIsRefusedOutLoudAndAnOperatorsConfirmIsInTheJobsEvents) {
  Cell cell;
  const int port = free_loopback_port();
  Laminad daemon(cell.config("", fmt::format("listen = \"127.0.0.1:{}\"\n{}{}", port, web_user("vic", "viewer", "v-pass"),
                                             web_user("ana", "operator", "a-pass"))),
                 cell.dir.file(""));
  RpcClient c = connect(cell.socket());
  Json job = call_ok(c, "job.submit", {{"model", std::string(LAMINA_EXAMPLES_DIR) + "/knob.stl"}, {"settings", {{"stock", "5"}}}});
  const std::string id = job["id"];
  job = wait_state(c, id, "waiting_sheet", 120);
  ASSERT_EQ(job["state"], "waiting_sheet") << job.dump(2) << daemon.log();
  const std::string origin = fmt::format("http://localhost:{}", port);

  WsClient viewer(port, http_login(port, "vic", "v-pass"), origin);
  ASSERT_TRUE(viewer.open()) << viewer.status() << " " << viewer.refusal() << daemon.log();
  EXPECT_EQ(viewer.call("job.list")["result"].size(), 1U) << "a viewer sees the queue";
  const Json refused = viewer.call("job.confirm_sheet", {{"job", id}, {"sheet", 1}});
  ASSERT_TRUE(refused.contains("error")) << refused.dump();
  EXPECT_EQ(refused["error"]["code"], rpc_code::forbidden);
  EXPECT_EQ(refused["error"]["message"], "job.confirm_sheet is for an operator or above; vic is a viewer");
  for (const char* method : {"machine.hold", "machine.abort", "job.cancel", "job.submit", "upload.begin"})
    EXPECT_EQ(viewer.call(method, {{"job", id}})["error"]["code"], rpc_code::forbidden) << method;

  WsClient op(port, http_login(port, "ana", "a-pass"), origin);
  ASSERT_TRUE(op.open());
  const Json cancel = op.call("job.cancel", {{"job", id}});
  EXPECT_EQ(cancel["error"]["code"], rpc_code::forbidden) << "cancel is an engineer's";
  EXPECT_EQ(cancel["error"]["message"], "job.cancel is for an engineer or above; ana is an operator");  // not "a operator"
  const Json confirmed = op.call("job.confirm_sheet", {{"job", id}, {"sheet", 1}});
  ASSERT_TRUE(confirmed.contains("result")) << confirmed.dump() << daemon.log();

  const Json events = op.call("job.events", {{"job", id}})["result"];
  ASSERT_TRUE(events.is_array()) << events.dump();
  bool submitted_by_socket = false, confirmed_by_ana = false;
  for (const Json& e : events) {
    if (e["kind"] == "state" && e["data"]["to"] == "queued")
      submitted_by_socket = e["data"]["by"].get<std::string>().starts_with("unix pid") && e["data"]["role"] == "engineer";
    if (e["kind"] == "action" && e["data"]["action"] == "confirm_sheet")
      confirmed_by_ana = e["data"]["by"] == "ana" && e["data"]["role"] == "operator" && e["data"]["sheet"] == 1;
  }
  EXPECT_TRUE(submitted_by_socket) << events.dump(1);
  EXPECT_TRUE(confirmed_by_ana) << events.dump(1);
  call_ok(c, "job.cancel", {{"job", id}});
}

TEST(LaminadWeb, APortThatIsTakenStopsTheStartNamingIt) {
  Cell cell;
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  ASSERT_EQ(::listen(fd, 1), 0);
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  const int port = ntohs(a.sin_port);
  Laminad daemon(cell.config("", fmt::format("listen = \"127.0.0.1:{}\"", port)), cell.dir.file(""));
  EXPECT_EQ(daemon.stop(0), 1) << daemon.log();  // signal 0: only wait for the exit
  EXPECT_NE(daemon.log().find(fmt::format("[http] listen 127.0.0.1:{}: Address already in use", port)), std::string::npos)
      << daemon.log();
  ::close(fd);
}

}  // namespace
}  // namespace lamina::daemon::testing
