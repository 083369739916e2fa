#pragma once
// JSON-RPC 2.0, one JSON object per line, on a Unix socket and (when configured) TCP. Runs on
// the caller's io_context (one thread). Each connection reads lines up to max_request_bytes
// (longer: -32600 and the connection is closed after the reply); a client that does not read
// its replies is dropped when its queue passes max_queued_bytes, so it never delays the others.
// TCP requests must carry params.token equal to the configured token (-32001 otherwise).
#include <cstdint>
#include <expected>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <nlohmann/json.hpp>

#include "lamina/daemon/roles.hpp"

namespace lamina::daemon {

// Standard JSON-RPC codes and ours (docs/api.md).
namespace rpc_code {
inline constexpr int parse_error = -32700;
inline constexpr int invalid_request = -32600;
inline constexpr int method_not_found = -32601;
inline constexpr int invalid_params = -32602;
inline constexpr int internal_error = -32603;
inline constexpr int unauthorized = -32001;     // TCP without the right token
inline constexpr int forbidden = -32002;        // the client's role may not call this method
inline constexpr int job_not_found = -32010;
inline constexpr int invalid_state = -32011;    // e.g. confirm_sheet while planning
inline constexpr int machine_busy = -32012;
inline constexpr int machine_fault = -32013;
inline constexpr int storage_error = -32014;
inline constexpr int shutting_down = -32015;
}  // namespace rpc_code

struct RpcError {
  int code = rpc_code::internal_error;
  std::string message;
  nlohmann::json data;  // null when absent
};
using RpcResult = std::expected<nlohmann::json, RpcError>;

struct RpcRequest {
  nlohmann::json id;       // null for a notification (no reply is sent)
  bool is_notification = false;
  std::string method;
  nlohmann::json params;   // object or array; an absent params is an empty object
};

// The listener a client came through: its limits (max_clients each) and, for TCP, the token.
// A WebSocket comes through laminad's web server, which checked its session before adopt().
enum class Via : std::uint8_t { unix_socket, tcp, websocket };
const char* via_name(Via via);  // "Unix", "TCP", "WebSocket" (log lines)

struct ClientContext {
  std::uint64_t id = 0;
  Via via = Via::unix_socket;
  bool subscribed = false;  // set by a handler (server.subscribe): receives broadcast()s
  std::string user;         // who acts, for the job's events: a console login, "unix uid 1000", "tcp"
  Role role = Role::engineer;
};

class RpcTransport;  // rpc_transport.hpp (daemon/src)

struct RpcServerSettings {
  std::string unix_path;                 // empty: no Unix socket (or adopted from systemd)
  unsigned unix_mode = 0660;
  std::string unix_group;                // chgrp when set (e.g. "lamina")
  std::optional<std::string> tcp_host;   // unset: no TCP
  int tcp_port = 0;                      // 0: any free port (see tcp_port())
  std::string token;                     // required for TCP
  std::size_t max_request_bytes = 1 << 20;
  std::size_t max_queued_bytes = 8 << 20;
  // Per kind: Unix and TCP clients have their own slots, so TCP peers cannot lock out the
  // operator's terminal. When a kind is full, its longest-idle client (not subscribed, nothing
  // in flight, idle ≥ 1 s) makes room; only when none can is the new one refused.
  std::size_t max_clients = 64;
  // A TCP peer before its first request with the right token: its lines are at most this long,
  // and it is closed after this long (a wrong token closes it at once).
  std::size_t pre_auth_max_bytes = 4096;
  double pre_auth_timeout_s = 10;
  double idle_timeout_s = 600;            // no request this long, not subscribed: closed (0: never)
  // Run on the io thread as they arrive, ahead of anything the client queued before (the
  // operator's hold and abort, as grblHAL's real-time commands bypass its line queue). Every
  // other method runs on one worker thread, in order per client, so that a slow one (a file
  // copied, a thread joined, the database synced) never holds up the io thread.
  std::vector<std::string> inline_methods;
};

class RpcServer {
 public:
  // Handlers of inline_methods run on the io thread and must return at once; the others run on
  // the server's worker thread (one at a time) and may block for a while, never for long.
  using Handler = std::function<RpcResult(const RpcRequest&, ClientContext&)>;

  RpcServer(boost::asio::io_context& io, RpcServerSettings settings, Handler handler);
  ~RpcServer();
  RpcServer(const RpcServer&) = delete;
  RpcServer& operator=(const RpcServer&) = delete;

  // Binds and listens (removing a stale socket file first). Errors name the path/port.
  std::expected<void, std::string> listen();
  // A listening Unix socket handed over by systemd (sd_listen_fds), instead of unix_path.
  std::expected<void, std::string> adopt_unix_listener(int fd);
  int tcp_port() const;  // the bound port (after listen)
  // A client whose transport another server opened and vouched for (a WebSocket with a valid
  // session): it gets the pipeline and limits of any client, and max_clients of its own kind.
  // Refused (the reason returned) when stopped or full. Call on the io thread.
  std::expected<void, std::string> adopt(std::unique_ptr<RpcTransport> transport, Via via, std::string user,
                                         Role role, std::string peer);

  // Thread-safe: a notification {"jsonrpc":"2.0","method":…,"params":…} to subscribed clients.
  void broadcast(const std::string& method, const nlohmann::json& params);
  // Stop accepting; close every connection. Thread-safe.
  void stop();
  std::size_t client_count() const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace lamina::daemon
