#pragma once
// A blocking JSON-RPC 2.0 client of laminad (newline-delimited JSON), for the lamina CLI and the
// tests: plain POSIX sockets and poll(), one request at a time. Notifications the server sends
// (broadcasts to a subscribed client) are queued while call() waits for its reply, and read with
// next_notification().
#include <cstdint>
#include <deque>
#include <expected>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "lamina/daemon/rpc_server.hpp"  // RpcError, rpc_code

namespace lamina::daemon {

namespace rpc_code {
// Client side only, never sent by the server: timeout, connection lost, unreadable reply.
inline constexpr int transport_error = -32099;
}  // namespace rpc_code

class RpcClient {
 public:
  // Errors name the path or host:port.
  static std::expected<RpcClient, std::string> connect_unix(const std::string& path);
  // TCP needs the server's token; call() adds it to every request's params.
  static std::expected<RpcClient, std::string> connect_tcp(const std::string& host, int port, std::string token);

  RpcClient(RpcClient&& other) noexcept;
  RpcClient& operator=(RpcClient&& other) noexcept;
  RpcClient(const RpcClient&) = delete;
  RpcClient& operator=(const RpcClient&) = delete;
  ~RpcClient();

  // Sends a request and waits for its reply: the result, the server's error, or a
  // rpc_code::transport_error (after which the connection is closed unless it was a timeout).
  std::expected<nlohmann::json, RpcError> call(const std::string& method,
                                               nlohmann::json params = nlohmann::json::object(),
                                               double timeout_s = 10);
  // The next notification ({"jsonrpc","method","params"}), queued or read within timeout_s.
  std::optional<nlohmann::json> next_notification(double timeout_s);

  bool is_open() const { return fd_ >= 0; }
  void close();

 private:
  RpcClient(int fd, std::string token, bool via_tcp);
  enum class ReadStatus { line, timeout, closed };
  // Reads one complete line into `line` (without '\n') before the deadline (steady clock, ms).
  ReadStatus read_line(std::string& line, std::int64_t deadline_ms);
  // Empty on success, else why not (the deadline passed, the connection broke).
  std::string send_all(const std::string& data, std::int64_t deadline_ms);

  int fd_ = -1;
  std::string token_;
  bool via_tcp_ = false;
  std::int64_t next_id_ = 1;
  std::string buffer_;  // received bytes not yet returned as lines
  std::deque<nlohmann::json> notifications_;
};

}  // namespace lamina::daemon
