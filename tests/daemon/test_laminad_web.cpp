// laminad's web server wired to its jobs (issue 19): a planned job's artefacts over HTTP, the same
// bytes as in its folder, and nothing outside it.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fstream>

#include "daemon_fixture.hpp"
#include "http_test_client.hpp"

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
