#include "rpc_connection.hpp"

#include <chrono>
#include <exception>
#include <utility>

#include <boost/asio/error.hpp>
#include <boost/asio/write.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "rpc_protocol.hpp"

namespace lamina::daemon::rpc_detail {
namespace {

constexpr std::size_t read_chunk_bytes = 64 * 1024;
// How long a connection refused for an oversize line may take to read the error and hang up.
constexpr auto linger_after_refusal = std::chrono::seconds(2);

}  // namespace

Connection::Connection(Socket socket, ClientContext context, std::string peer, std::shared_ptr<ServerShared> shared,
                       ClosedCallback on_closed)
    : socket_(std::move(socket)),
      context_(context),
      peer_(std::move(peer)),
      shared_(std::move(shared)),
      on_closed_(std::move(on_closed)),
      chunk_(read_chunk_bytes) {}

void Connection::start() {
  shared_->log->debug("client {} connected ({})", context_.id, peer_);
  read_next();
}

void Connection::read_next() {
  socket_.async_read_some(boost::asio::buffer(chunk_),
                          [self = shared_from_this()](const boost::system::error_code& error, std::size_t size) {
                            std::lock_guard lock(self->shared_->mutex);
                            self->on_read(error, size);
                          });
}

void Connection::on_read(const boost::system::error_code& error, std::size_t size) {
  // A read that completed just before close() still arrives with its data: ignore it.
  if (closed_) return;
  if (error == boost::asio::error::eof && !draining_) {
    // `echo '{…}' | socat - UNIX-CONNECT:…` sends, half-closes and then reads: a last line
    // without '\n' is still a request, and the replies still go out before the close.
    if (!partial_.empty()) handle_line(std::exchange(partial_, {}));
    peer_done_ = true;
    if (!closed_ && !writing_) close("client hung up");
    return;
  }
  if (error) {
    close(error == boost::asio::error::eof ? "client hung up" : error.message());
    return;
  }
  if (draining_) {  // refused: the rest of the input is not read as requests
    read_next();
    return;
  }
  const std::size_t limit = shared_->settings.max_request_bytes;
  std::string_view data(chunk_.data(), size);
  while (!closed_ && !draining_) {
    const std::size_t newline = data.find('\n');
    if (newline == std::string_view::npos) {
      // No end of line yet: refuse as soon as the line cannot fit, so memory stays bounded by the
      // limit whatever the client sends. The size reported is then what had arrived so far.
      if (partial_.size() + data.size() > limit) {
        refuse_oversize(partial_.size() + data.size());
      } else {
        partial_.append(data);
      }
      break;
    }
    const std::size_t length = partial_.size() + newline;
    if (length > limit) {
      refuse_oversize(length);
      break;
    }
    if (partial_.empty()) {
      handle_line(data.substr(0, newline));
    } else {
      partial_.append(data.substr(0, newline));
      const std::string line = std::exchange(partial_, {});
      handle_line(line);
    }
    data.remove_prefix(newline + 1);
  }
  if (!closed_) read_next();
}

void Connection::handle_line(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  // Blank lines (someone typing into socat) are not requests and get no error.
  if (line.find_first_not_of(" \t") == std::string_view::npos) return;

  auto parsed = parse_request(line);
  if (!parsed) {
    shared_->log->info("client {}: {} ({})", context_.id, parsed.error().error.message, parsed.error().error.code);
    send_line(error_line(parsed.error().id, parsed.error().error));
    return;
  }
  RpcRequest& request = *parsed;
  if (context_.via_tcp) {
    if (auto authorized = check_and_strip_token(request.params, shared_->settings.token); !authorized) {
      shared_->log->warn("client {} ({}): {} without a valid token", context_.id, peer_, request.method);
      if (!request.is_notification) send_line(error_line(request.id, authorized.error()));
      return;
    }
  }
  RpcResult result = invoke(request);
  if (request.is_notification || closed_) return;  // the handler may have stopped the server
  send_line(result ? result_line(request.id, *result) : error_line(request.id, result.error()));
}

RpcResult Connection::invoke(const RpcRequest& request) {
  if (!shared_->handler) return std::unexpected(RpcError{rpc_code::shutting_down, "shutting down", {}});
  // A handler's bug must cost one reply, not the daemon (and the machine it drives).
  try {
    return shared_->handler(request, context_);
  } catch (const std::exception& e) {
    shared_->log->error("client {}: {} threw: {}", context_.id, request.method, e.what());
    return std::unexpected(RpcError{rpc_code::internal_error, "internal error", e.what()});
  } catch (...) {
    shared_->log->error("client {}: {} threw a non-standard exception", context_.id, request.method);
    return std::unexpected(RpcError{rpc_code::internal_error, "internal error", {}});
  }
}

void Connection::send_line(std::string line) { send(std::make_shared<const std::string>(std::move(line))); }

void Connection::refuse_oversize(std::size_t bytes) {
  const std::size_t limit = shared_->settings.max_request_bytes;
  shared_->log->warn("client {} ({}): request of {} bytes over the limit of {}; closing", context_.id, peer_, bytes,
                     limit);
  draining_ = true;
  partial_.clear();
  partial_.shrink_to_fit();
  send_line(error_line(nullptr, RpcError{rpc_code::invalid_request,
                                         fmt::format("request too large ({} bytes, limit {})", bytes, limit),
                                         {}}));
  if (closed_) return;  // the reply alone passed max_queued_bytes
  linger_.emplace(socket_.get_executor(), linger_after_refusal);
  linger_->async_wait([self = shared_from_this()](const boost::system::error_code& error) {
    std::lock_guard lock(self->shared_->mutex);
    if (!error) self->close("did not hang up after a refused request");
  });
}

void Connection::send(std::shared_ptr<const std::string> line) {
  if (closed_) return;
  queued_bytes_ += line->size();
  // A client that does not read would otherwise make the daemon hold everything sent to it.
  if (queued_bytes_ > shared_->settings.max_queued_bytes) {
    shared_->log->warn("client {} ({}): {} bytes not read (limit {}); dropping it", context_.id, peer_, queued_bytes_,
                       shared_->settings.max_queued_bytes);
    close("write queue over the limit");
    return;
  }
  queue_.push_back(std::move(line));
  if (!writing_) write_next();
}

void Connection::write_next() {
  // Everything queued goes out in one gathered write: a pipelining client gets its replies in
  // few system calls.
  in_flight_.assign(std::make_move_iterator(queue_.begin()), std::make_move_iterator(queue_.end()));
  queue_.clear();
  buffers_.clear();
  for (const auto& line : in_flight_) buffers_.push_back(boost::asio::buffer(*line));
  writing_ = true;
  boost::asio::async_write(socket_, buffers_,
                           [self = shared_from_this()](const boost::system::error_code& error, std::size_t) {
                             std::lock_guard lock(self->shared_->mutex);
                             self->on_write(error);
                           });
}

void Connection::on_write(const boost::system::error_code& error) {
  writing_ = false;
  if (closed_) return;
  if (error) {
    close(error.message());
    return;
  }
  for (const auto& line : in_flight_) queued_bytes_ -= line->size();
  in_flight_.clear();
  if (!queue_.empty()) {
    write_next();
  } else if (peer_done_) {
    close("client hung up");
  } else if (draining_) {
    // The refusal is out: half-close so the client sees EOF, and keep discarding its input until
    // it hangs up too (or linger_ expires).
    boost::system::error_code ignored;
    socket_.shutdown(Socket::shutdown_send, ignored);
  }
}

void Connection::close(std::string_view reason) {
  if (closed_) return;
  closed_ = true;
  const auto self = shared_from_this();  // on_closed_ may drop the server's reference to us
  shared_->log->debug("client {} ({}) closed: {}", context_.id, peer_, reason);
  // Before the socket closes: whoever sees the EOF must find the client gone from the count.
  if (auto on_closed = std::exchange(on_closed_, nullptr)) on_closed(context_.id);
  boost::system::error_code ignored;
  socket_.close(ignored);  // pending operations complete with operation_aborted
  if (linger_) linger_->cancel();
  queue_.clear();
  // in_flight_ stays: the aborted write's buffers point into it until its handler has run.
}

}  // namespace lamina::daemon::rpc_detail
