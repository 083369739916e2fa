// laminad's web server (issue 19) over a real socket: the console's files and a job's artefacts,
// and what it refuses. Requests are written byte for byte (a browser or curl would normalise a
// "../" away before sending it; an attacker does not).
#include <gtest/gtest.h>

#include <fstream>
#include <thread>

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>

#include "http/http_server.hpp"
#include "http_test_client.hpp"
#include "sim_process.hpp"

namespace lamina::daemon::http {
namespace {

using lamina::sim::testing::TempDir;

const std::string kServerJob = "j-1764892800123-a3f9";

void write_file(const std::filesystem::path& p, const std::string& text) {
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

// The server on its own io thread, with a console folder and one job's folder.
struct Web {
  TempDir dir;
  std::filesystem::path console = std::filesystem::path(dir.file("web"));
  std::filesystem::path job_dir = std::filesystem::path(dir.file("jobs")) / kServerJob;
  boost::asio::io_context io;
  boost::asio::executor_work_guard<boost::asio::io_context::executor_type> work{io.get_executor()};
  std::unique_ptr<HttpServer> server;
  std::thread thread;

  explicit Web(HttpSettings s = {}) {
    write_file(console / "index.html", "<!doctype html><title>Lamina</title>");
    write_file(console / "assets" / "app.js", "console.log('lamina');");
    write_file(job_dir / "sheet-1.svg", "<svg/>");
    write_file(job_dir / "report.json", "{}");
    write_file(std::filesystem::path(dir.file("jobs")) / "jobs.db", "secret");
    s.host = "127.0.0.1";
    s.port = 0;
    s.static_dir = console;
    server = std::make_unique<HttpServer>(io, s, [this](const ArtefactRequest& r) -> std::expected<std::filesystem::path, RouteError> {
      if (r.job_id != kServerJob) return std::unexpected(RouteError{404, "no job " + r.job_id});
      const auto p = job_dir / artefact_file_name(r);
      if (!std::filesystem::exists(p)) return std::unexpected(RouteError{404, "not yet written"});
      return p;
    }, nullptr);
    auto ok = server->listen();
    if (!ok) throw std::runtime_error(ok.error());
    thread = std::thread([this] { io.run(); });
  }
  ~Web() {
    server->stop();
    work.reset();
    io.stop();
    thread.join();
  }
  int port() const { return server->port(); }
};

std::string get(int port, const std::string& target) { return testing::http_get(port, target); }
std::string exchange(int port, const std::string& request) { return testing::http_exchange(port, request); }
using testing::body_of;
using testing::status_of;

TEST(HttpServer, ServesTheConsolesFilesWithTheirTypes) {
  Web web;
  const std::string index = get(web.port(), "/");
  EXPECT_EQ(status_of(index), 200) << index;
  EXPECT_EQ(body_of(index), "<!doctype html><title>Lamina</title>");
  EXPECT_NE(index.find("Content-Type: text/html; charset=utf-8"), std::string::npos) << index;
  EXPECT_NE(index.find("X-Content-Type-Options: nosniff"), std::string::npos) << index;
  const std::string js = get(web.port(), "/assets/app.js");
  EXPECT_EQ(status_of(js), 200);
  EXPECT_NE(js.find("text/javascript"), std::string::npos) << js;
  EXPECT_EQ(status_of(get(web.port(), "/assets/missing.js")), 404);
}

TEST(HttpServer, AJobsArtefactsAndNothingBesideThem) {
  Web web;
  const std::string svg = get(web.port(), "/api/jobs/" + kServerJob + "/sheet-1.svg");
  EXPECT_EQ(status_of(svg), 200) << svg;
  EXPECT_EQ(body_of(svg), "<svg/>");
  EXPECT_NE(svg.find("image/svg+xml"), std::string::npos);
  EXPECT_EQ(status_of(get(web.port(), "/api/jobs/" + kServerJob + "/sheet-2.svg")), 404);  // not written
  EXPECT_EQ(status_of(get(web.port(), "/api/jobs/j-1764892800123-0000/report.json")), 404);
  for (const std::string& attack : std::vector<std::string>{"/api/jobs/" + kServerJob + "/../jobs.db", "/api/jobs/../jobs.db",
                                   "/../jobs/jobs.db", "/%2e%2e/jobs/jobs.db", "/api/jobs/" + kServerJob + "/..%2fjobs.db"}) {
    const std::string r = get(web.port(), attack);
    EXPECT_EQ(status_of(r), 400) << attack << ": " << r;
    EXPECT_EQ(r.find("secret"), std::string::npos) << attack;
  }
}

TEST(HttpServer, ASymlinkOutOfTheConsolesFolderIsNotFollowed) {
  Web web;
  std::filesystem::create_symlink(web.job_dir.parent_path() / "jobs.db", web.console / "db");
  const std::string r = get(web.port(), "/db");
  EXPECT_EQ(status_of(r), 404) << r;
  EXPECT_EQ(r.find("secret"), std::string::npos);
}

TEST(HttpServer, OnlyGetAndHeadAreServedAndPostOnlyForTheLogin) {
  Web web;
  const std::string del = exchange(web.port(), "DELETE / HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(status_of(del), 405) << del;
  EXPECT_NE(del.find("Allow: GET, HEAD, POST"), std::string::npos) << del;
  const std::string post = exchange(web.port(), "POST / HTTP/1.1\r\nHost: localhost\r\nContent-Length: 5\r\nConnection: close\r\n\r\nhello");
  EXPECT_EQ(status_of(post), 404) << post;
  const std::string big = exchange(web.port(), "POST /api/login HTTP/1.1\r\nHost: localhost\r\nContent-Length: 5000\r\n\r\n" + std::string(5000, 'a'));
  EXPECT_EQ(status_of(big), 413) << big;
  const std::string body = exchange(web.port(), "GET / HTTP/1.1\r\nHost: localhost\r\nContent-Length: 5\r\n\r\nhello");
  EXPECT_EQ(status_of(body), 413) << body;
  const std::string head = exchange(web.port(), "HEAD / HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(status_of(head), 200) << head;
  EXPECT_NE(head.find("Content-Length: 36"), std::string::npos) << head;
  EXPECT_EQ(body_of(head), "");
}

TEST(HttpServer, AnOversizedRequestHeadIsRefused) {
  Web web;
  const std::string r = get(web.port(), "/?" + std::string(20000, 'a'));
  EXPECT_EQ(status_of(r), 431) << r.substr(0, 200);
}

TEST(HttpServer, KeepAliveServesSeveralRequestsOnOneConnection) {
  Web web;
  const std::string two = exchange(web.port(),
                                   "GET /assets/app.js HTTP/1.1\r\nHost: localhost\r\n\r\n"
                                   "GET / HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n");
  EXPECT_NE(two.find("console.log('lamina');"), std::string::npos) << two;
  EXPECT_NE(two.find("<title>Lamina</title>"), std::string::npos) << two;
}

TEST(HttpServer, AConnectionThatSaysNothingIsClosedAfterTheIdleTimeout) {
  HttpSettings s;
  s.idle_timeout_s = 0.3;
  Web web(s);
  const int fd = testing::connect_loopback(web.port());
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(testing::read_until_close(fd), "");  // EOF, not the 10 s receive timeout
  ::close(fd);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 9.0);
}

TEST(HttpServer, ConnectionsBeyondTheLimitGetABusyAnswer) {
  HttpSettings s;
  s.max_connections = 2;
  Web web(s);
  const int a = testing::connect_loopback(web.port());
  const int b = testing::connect_loopback(web.port());
  // Both are admitted once the server has counted them; the third is one too many.
  for (int i = 0; i < 1000 && web.server->connection_count() < 2; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_EQ(web.server->connection_count(), 2u);
  const std::string third = get(web.port(), "/");
  EXPECT_EQ(status_of(third), 503) << third;
  ::close(a);
  ::close(b);
}

}  // namespace
}  // namespace lamina::daemon::http
