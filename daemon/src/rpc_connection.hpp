#pragma once
// One client of rpc_server: reads newline-delimited requests, runs the handler, queues replies,
// over whichever RpcTransport it came through (a Unix or TCP socket, a WebSocket).
// Used by rpc_server.cpp only; the server owns connections through shared_ptr and every
// completion handler holds one too, so a connection outlives any operation still in flight.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <spdlog/logger.h>

#include "lamina/daemon/rpc_server.hpp"
#include "rpc_transport.hpp"

namespace lamina::daemon::rpc_detail {

// What the server and all its connections share. Connections keep it alive by shared_ptr, so it
// outlives the RpcServer object when completion handlers are still queued in the io_context.
struct ServerShared {
  RpcServerSettings settings;
  RpcServer::Handler handler;  // emptied when the RpcServer is destroyed: never called after that
  std::shared_ptr<spdlog::logger> log;
  // Every completion handler of the server and of its connections runs holding this lock, and so
  // do stop() and the destructor. That is what lets those two close sockets synchronously from any
  // thread, including when the io_context is not running. Uncontended in normal operation (one io
  // thread); recursive because a handler may call stop().
  std::recursive_mutex mutex;
  // The handlers of methods not in settings.inline_methods run here, one at a time, without the
  // mutex (RpcServer owns the thread; it is joined before the handler is emptied).
  boost::asio::io_context worker;
  bool is_inline(std::string_view method) const;
};

class Connection : public std::enable_shared_from_this<Connection> {
 public:
  using ClosedCallback = std::function<void(std::uint64_t client_id)>;

  Connection(std::unique_ptr<RpcTransport> transport, ClientContext context, std::string peer, std::shared_ptr<ServerShared> shared,
             ClosedCallback on_closed);
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  // All of these must be called holding shared->mutex.
  void start();
  // Queues a complete line; a client whose queue passes max_queued_bytes is dropped instead.
  void send(std::shared_ptr<const std::string> line);
  // Idempotent. Queued replies are discarded; on_closed runs once.
  void close(std::string_view reason);
  const ClientContext& context() const { return context_; }
  // For the server choosing whom to drop when a kind of client is full.
  bool evictable(std::chrono::steady_clock::time_point now) const;
  std::chrono::steady_clock::time_point last_active() const { return last_active_; }

 private:
  // A request waiting for the worker: parsed, or a long line the worker parses (a MiB of JSON
  // takes milliseconds the io thread has not).
  struct Pending {
    std::optional<RpcRequest> request;
    std::string raw;
    std::size_t bytes = 0;  // the line's length, for waiting_bytes_
  };

  void read_next();
  void on_read(const boost::system::error_code& error, std::string_view data);
  void handle_line(std::string_view line);
  std::optional<RpcRequest> accept_request(std::string_view line);  // parsed and authorised, or replied to
  void dispatch_next();
  void on_worker_done(const nlohmann::json& id, bool notification, RpcResult result);
  RpcResult invoke(const RpcRequest& request, ClientContext& context);  // the handler, exceptions caught
  void send_line(std::string line);
  void refuse_oversize(std::size_t bytes);
  void refuse_and_hang_up(std::string line, std::string_view why);
  void arm_idle_timer();
  bool may_close_after_eof() const;
  void write_next();
  void on_write(const boost::system::error_code& error);

  std::unique_ptr<RpcTransport> transport_;
  ClientContext context_;
  std::string peer_;  // for the log: "unix pid 123 uid 1000" or "tcp 127.0.0.1:51234"
  std::shared_ptr<ServerShared> shared_;
  ClosedCallback on_closed_;

  std::string partial_;      // the start of a line whose '\n' has not arrived yet

  std::deque<std::shared_ptr<const std::string>> queue_;  // broadcasts share one string
  std::vector<std::shared_ptr<const std::string>> in_flight_;  // alive until the write's handler
  std::size_t queued_bytes_ = 0;                    // queue_ and in_flight_ together
  bool writing_ = false;

  // After an oversize line: the error is written, input is read and discarded (closing with
  // unread input would make TCP send a reset that can destroy the reply before the client reads
  // it), and the connection closes on the client's EOF or when linger_ expires.
  bool draining_ = false;
  bool peer_done_ = false;  // the client half-closed: close once its replies are written
  std::optional<boost::asio::steady_timer> linger_;
  bool closed_ = false;

  bool authenticated_ = false;              // TCP: a request with the right token was seen
  std::deque<Pending> waiting_;             // for the worker, in order
  std::size_t waiting_bytes_ = 0;
  bool busy_ = false;                       // one of ours is on the worker
  bool read_paused_ = false;                // waiting_ is full: the socket is not read
  std::chrono::steady_clock::time_point last_active_ = std::chrono::steady_clock::now();
  std::optional<boost::asio::steady_timer> idle_timer_;  // idle timeout, or the pre-auth deadline
};

}  // namespace lamina::daemon::rpc_detail
