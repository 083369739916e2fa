#pragma once
// Shared by the RPC server tests: a server on its own io thread in a temporary directory, with a
// handler of test methods, and a raw socket client for what RpcClient would never send.
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "lamina/daemon/rpc_client.hpp"
#include "lamina/daemon/rpc_server.hpp"

namespace lamina::daemon::test {

using nlohmann::json;
using namespace std::chrono_literals;

class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "lamina-rpc-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// A client socket driven by hand: arbitrary bytes out, lines in, with timeouts.
class RawConn {
 public:
  static RawConn unix_socket(const std::string& path) {
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::strncpy(address.sun_path, path.c_str(), sizeof address.sun_path - 1);
    RawConn conn(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
    if (::connect(conn.fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) conn.reset();
    return conn;
  }
  static RawConn tcp_loopback(int port) {
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<std::uint16_t>(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    RawConn conn(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
    if (::connect(conn.fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) conn.reset();
    return conn;
  }
  RawConn(RawConn&& other) noexcept : fd_(std::exchange(other.fd_, -1)), buffer_(std::move(other.buffer_)) {}
  RawConn(const RawConn&) = delete;
  RawConn& operator=(const RawConn&) = delete;
  ~RawConn() { reset(); }

  bool connected() const { return fd_ >= 0; }
  void shutdown_write() { ::shutdown(fd_, SHUT_WR); }
  void reset() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

  // Blocking send of everything; false when the server has closed the connection.
  bool send(const std::string& data) {
    std::size_t sent = 0;
    while (sent < data.size()) {
      const ssize_t n = ::send(fd_, data.data() + sent, data.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) return false;
      sent += static_cast<std::size_t>(n);
    }
    return true;
  }

  // One line without its '\n'; nullopt on timeout or when the connection ends first.
  std::optional<std::string> read_line(std::chrono::milliseconds timeout = 5s) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      if (const auto newline = buffer_.find('\n'); newline != std::string::npos) {
        std::string line = buffer_.substr(0, newline);
        buffer_.erase(0, newline + 1);
        return line;
      }
      if (!fill(deadline)) return std::nullopt;
    }
  }
  std::optional<json> read_json(std::chrono::milliseconds timeout = 5s) {
    auto line = read_line(timeout);
    if (!line) return std::nullopt;
    return json::parse(*line);
  }
  // Reads and discards until the server closes the connection; false if it is still open at the
  // timeout. `received` counts what was discarded (what the server had sent before closing).
  bool wait_closed(std::chrono::milliseconds timeout, std::size_t* received = nullptr) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    std::size_t total = buffer_.size();
    buffer_.clear();
    for (;;) {
      pollfd readable{fd_, POLLIN, 0};
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (::poll(&readable, 1, static_cast<int>(std::max<std::int64_t>(left.count(), 0))) <= 0) return false;
      char chunk[64 * 1024];
      const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
      if (n <= 0) {
        if (received != nullptr) *received = total;
        return true;
      }
      total += static_cast<std::size_t>(n);
    }
  }

 private:
  explicit RawConn(int fd) : fd_(fd) {}
  bool fill(std::chrono::steady_clock::time_point deadline) {
    pollfd readable{fd_, POLLIN, 0};
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (::poll(&readable, 1, static_cast<int>(std::max<std::int64_t>(left.count(), 0))) <= 0) return false;
    char chunk[64 * 1024];
    const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
    if (n <= 0) return false;
    buffer_.append(chunk, static_cast<std::size_t>(n));
    return true;
  }
  int fd_ = -1;
  std::string buffer_;
};

inline std::string request_line(const json& id, const std::string& method, const json& params = json::object()) {
  return json{{"jsonrpc", "2.0"}, {"id", id}, {"method", method}, {"params", params}}.dump() + "\n";
}

// The server under test, on its own io thread. Methods of its handler:
//   echo → params; add → params.a + params.b; whoami → {client, tcp}; big → a string of
//   params.bytes 'x'; note → counts calls (for notifications); throw → throws;
//   server.subscribe → subscribes the client; stop → stops the server from inside a handler;
//   block → waits (on the worker) until the test sets release_ (at most 20 s); hold → "held"
//   (a test makes it an inline method).
class ServerFixture : public ::testing::Test {
 protected:
  void SetUp() override { spdlog::set_level(spdlog::level::warn); }
  void TearDown() override { shutdown(); }

  RpcServerSettings default_settings() const {
    RpcServerSettings settings;
    settings.unix_path = socket_path();
    return settings;
  }
  std::string socket_path() const { return (dir_.path() / "laminad.sock").string(); }

  // Listens and starts the io thread; fails the test when listen() does.
  void start(RpcServerSettings settings) {
    server_ = std::make_unique<RpcServer>(io_, std::move(settings), [this](const RpcRequest& r, ClientContext& c) {
      return handle(r, c);
    });
    const auto listening = server_->listen();
    ASSERT_TRUE(listening.has_value()) << listening.error();
    thread_ = std::thread([this] { io_.run(); });
  }
  void start() { start(default_settings()); }

  void shutdown() {
    if (server_) server_->stop();
    guard_.reset();
    if (thread_.joinable()) thread_.join();
    server_.reset();
  }

  RpcClient unix_client() {
    auto client = RpcClient::connect_unix(socket_path());
    if (!client) throw std::runtime_error(client.error());
    return std::move(*client);
  }

  // Polls `condition` until it holds or the timeout passes.
  template <typename Condition>
  static bool eventually(Condition condition, std::chrono::milliseconds timeout = 5s) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!condition()) {
      if (std::chrono::steady_clock::now() > deadline) return false;
      std::this_thread::sleep_for(5ms);
    }
    return true;
  }

  RpcResult handle(const RpcRequest& request, ClientContext& client) {
    const json& p = request.params;
    if (request.method == "echo") return p;
    if (request.method == "add") return p.at("a").get<int>() + p.at("b").get<int>();
    if (request.method == "whoami") return json{{"client", client.id}, {"tcp", client.via == lamina::daemon::Via::tcp}};
    if (request.method == "big") return std::string(p.at("bytes").get<std::size_t>(), 'x');
    if (request.method == "note") {
      ++notes_;
      return nullptr;
    }
    if (request.method == "throw") throw std::runtime_error("handler failure on purpose");
    if (request.method == "server.subscribe") {
      client.subscribed = true;
      return true;
    }
    if (request.method == "block") {
      ++blocked_;
      for (int i = 0; i < 2000 && !release_; ++i) std::this_thread::sleep_for(10ms);
      return release_.load();
    }
    if (request.method == "hold") return "held";
    if (request.method == "stop") {
      server_->stop();
      return true;
    }
    return std::unexpected(RpcError{rpc_code::method_not_found, "method not found: " + request.method, {}});
  }

  TempDir dir_;
  boost::asio::io_context io_;
  boost::asio::executor_work_guard<boost::asio::io_context::executor_type> guard_{io_.get_executor()};
  std::thread thread_;
  std::unique_ptr<RpcServer> server_;
  std::atomic<int> notes_{0};
  std::atomic<int> blocked_{0};
  std::atomic<bool> release_{false};
};

}  // namespace lamina::daemon::test
