#pragma once
// laminad's web server and RPC server on one io thread, as in laminad, with a handler that says
// who is calling: the web console's tests (test_web_login.cpp, test_web_tls.cpp).
#include <future>
#include <memory>
#include <thread>

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <nlohmann/json.hpp>

#include "http/http_server.hpp"
#include "http/passwords.hpp"
#include "http/upload_sink.hpp"
#include "rpc_test_support.hpp"
#include "uploads.hpp"
#include "http_test_client.hpp"
#include "lamina/daemon/rpc_server.hpp"

namespace lamina::daemon::http::testing_console {

// ana is an operator, vic a viewer. Hashes are made once: each takes ~0.1 s by design.
inline const std::vector<WebUser>& users() {
  static const std::vector<WebUser> u{{"ana", Role::machine_operator, *hash_password("ana's password")},
                                      {"eve", Role::engineer, *hash_password("eve's password")},
                                      {"vic", Role::viewer, *hash_password("vic's password")}};
  return u;
}

struct Console {
  boost::asio::io_context io;
  boost::asio::executor_work_guard<boost::asio::io_context::executor_type> work{io.get_executor()};
  std::unique_ptr<RpcServer> rpc;
  std::unique_ptr<HttpServer> web;
  test::TempDir upload_dir;
  Uploads uploads{upload_dir.path() / "uploads", UploadLimits{kMaxUploadBytes, 512 << 10, 4, 600}};
  static constexpr std::uint64_t kMaxUploadBytes = 4 << 20;
  std::thread thread;

  // With tls_cert and tls_key set the console is HTTPS only.
  explicit Console(std::size_t max_request_bytes = 1 << 20, std::filesystem::path tls_cert = {},
                   std::filesystem::path tls_key = {}) {
    RpcServerSettings rs;
    rs.max_request_bytes = max_request_bytes;
    rs.inline_methods = {"server.subscribe"};  // as laminad: on the io thread, ahead of the queue
    rpc = std::make_unique<RpcServer>(io, rs, [](const RpcRequest& r, ClientContext& client) -> RpcResult {
      if (r.method == "server.subscribe") client.subscribed = true;
      if (r.method == "slow") std::this_thread::sleep_for(std::chrono::milliseconds(100));
      return nlohmann::json{{"user", client.user}, {"role", role_name(client.role)}, {"via", via_name(client.via)}};
    });
    HttpSettings s;
    s.host = "127.0.0.1";
    s.port = 0;
    s.max_request_bytes = max_request_bytes;
    s.access.users = users();
    s.access.session_lifetime_s = 3600;
    s.tls_cert = std::move(tls_cert);
    s.tls_key = std::move(tls_key);
    s.access.tls = !s.tls_cert.empty();
    web = std::make_unique<HttpServer>(
        io, s,
        [](const ArtefactRequest&) -> std::expected<std::filesystem::path, RouteError> {
          return std::unexpected(RouteError{404, "no jobs in this test"});
        },
        [this](std::unique_ptr<RpcTransport> t, const Visitor& who, std::string peer) {
          return rpc->adopt(std::move(t), Via::websocket, who.user, who.role, std::move(peer));
        },
        upload_sink(uploads, kMaxUploadBytes));
    if (auto ok = web->listen(); !ok) throw std::runtime_error(ok.error());
    thread = std::thread([this] { io.run(); });
  }
  ~Console() {
    web->stop();
    rpc->stop();
    work.reset();
    io.stop();
    thread.join();
  }
  int port() const { return web->port(); }
  std::string origin() const { return "http://localhost:" + std::to_string(port()); }

  std::string post(const std::string& target, const std::string& body, const std::string& extra = "") const {
    return testing::http_post(port(), target, body, extra);
  }
  std::string login(const std::string& user, const std::string& password) const {
    return post("/api/login", nlohmann::json{{"user", user}, {"password", password}}.dump());
  }
  std::string get(const std::string& target, const std::string& cookie) const {
    return testing::http_exchange(port(), "GET " + target + " HTTP/1.1\r\nHost: localhost\r\n" +
                                              (cookie.empty() ? "" : "Cookie: " + cookie + "\r\n") +
                                              "Connection: close\r\n\r\n");
  }
};

}  // namespace lamina::daemon::http::testing_console
