#include "rpc_connection.hpp"

#include <chrono>
#include <exception>
#include <utility>

#include <boost/asio/error.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/write.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "rpc_protocol.hpp"

namespace lamina::daemon::rpc_detail {
namespace {

// Lines longer than this are parsed on the worker: even valid JSON takes milliseconds per MiB.
constexpr std::size_t parse_on_worker_bytes = 64 * 1024;
// Queued for the worker beyond this, the socket is not read until the worker catches up.
constexpr std::size_t max_waiting_requests = 32;
// A client has been quiet this long before it may be dropped to make room for a new one.
constexpr auto evict_after_idle = std::chrono::seconds(1);
// How long a connection refused for an oversize line may take to read the error and hang up.
constexpr auto linger_after_refusal = std::chrono::seconds(2);

}  // namespace

Connection::Connection(std::unique_ptr<RpcTransport> transport, ClientContext context, std::string peer,
                       std::shared_ptr<ServerShared> shared, ClosedCallback on_closed)
    : transport_(std::move(transport)),
      context_(std::move(context)),
      peer_(std::move(peer)),
      shared_(std::move(shared)),
      on_closed_(std::move(on_closed)) {}

bool ServerShared::is_inline(std::string_view method) const {
  for (const auto& m : settings.inline_methods)
    if (m == method) return true;
  return false;
}

void Connection::start() {
  shared_->log->debug("client {} connected ({})", context_.id, peer_);
  arm_idle_timer();
  read_next();
}

bool Connection::evictable(std::chrono::steady_clock::time_point now) const {
  return !closed_ && !context_.subscribed && !busy_ && waiting_.empty() && now - last_active_ >= evict_after_idle;
}

// The pre-auth deadline of a TCP peer without a valid token yet, else the idle timeout; moved
// on by every request (expires_after cancels the wait before).
void Connection::arm_idle_timer() {
  const bool pre_auth = context_.via == Via::tcp && !authenticated_;
  const double seconds = pre_auth ? shared_->settings.pre_auth_timeout_s : shared_->settings.idle_timeout_s;
  if (seconds <= 0) return;
  if (!idle_timer_) idle_timer_.emplace(transport_->executor());
  idle_timer_->expires_after(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(seconds)));
  idle_timer_->async_wait([self = shared_from_this(), pre_auth, seconds](const boost::system::error_code& error) {
    std::lock_guard lock(self->shared_->mutex);
    if (error || self->closed_) return;
    if (pre_auth && !self->authenticated_) return self->close(fmt::format("no valid token within {} s", seconds));
    if (self->context_.subscribed || self->busy_ || !self->waiting_.empty()) return self->arm_idle_timer();
    self->close(fmt::format("idle for {} s", seconds));
  });
}

bool Connection::may_close_after_eof() const { return !writing_ && !busy_ && waiting_.empty(); }

void Connection::read_next() {
  transport_->async_read([self = shared_from_this()](const boost::system::error_code& error, std::string_view data) {
    std::lock_guard lock(self->shared_->mutex);
    self->on_read(error, data);
  });
}

void Connection::on_read(const boost::system::error_code& error, std::string_view data) {
  // A read that completed just before close() still arrives with its data: ignore it.
  if (closed_) return;
  if (error == boost::asio::error::eof && !draining_) {
    // `echo '{…}' | socat - UNIX-CONNECT:…` sends, half-closes and then reads: a last line
    // without '\n' is still a request, and the replies still go out before the close.
    if (!partial_.empty()) handle_line(std::exchange(partial_, {}));
    peer_done_ = true;
    if (!closed_ && may_close_after_eof()) close("client hung up");
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
  // Before its token, a TCP peer gets a few KiB per line, not the MiB a client may send.
  const std::size_t limit = context_.via == Via::tcp && !authenticated_ ? shared_->settings.pre_auth_max_bytes
                                                                : shared_->settings.max_request_bytes;
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
  if (closed_) return;
  // Backpressure: a client far ahead of the worker waits (in its socket) until it catches up.
  if (waiting_.size() >= max_waiting_requests || waiting_bytes_ > shared_->settings.max_request_bytes)
    read_paused_ = true;
  else
    read_next();
}

void Connection::handle_line(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  // Blank lines (someone typing into socat) are not requests and get no error.
  if (line.find_first_not_of(" \t") == std::string_view::npos) return;
  last_active_ = std::chrono::steady_clock::now();
  arm_idle_timer();
  // (Only an authenticated client can send a line this long: see on_read.)
  if (line.size() > parse_on_worker_bytes) {
    waiting_.push_back(Pending{std::nullopt, std::string(line), line.size()});
    waiting_bytes_ += line.size();
    return dispatch_next();
  }
  auto request = accept_request(line);
  if (!request) return;
  if (shared_->is_inline(request->method)) {  // ahead of whatever waits for the worker
    RpcResult result = invoke(*request, context_);
    if (request->is_notification || closed_) return;  // the handler may have stopped the server
    return send_line(result ? result_line(request->id, *result) : error_line(request->id, result.error()));
  }
  waiting_bytes_ += line.size();
  waiting_.push_back(Pending{std::move(*request), {}, line.size()});
  dispatch_next();
}

std::optional<RpcRequest> Connection::accept_request(std::string_view line) {
  auto parsed = parse_request(line);
  if (!parsed) {
    shared_->log->info("client {}: {} ({})", context_.id, parsed.error().error.message, parsed.error().error.code);
    if (context_.via == Via::tcp && !authenticated_)  // a stranger gets one answer, not a parser to play with
      refuse_and_hang_up(error_line(parsed.error().id, parsed.error().error), "bad request before a valid token");
    else
      send_line(error_line(parsed.error().id, parsed.error().error));
    return std::nullopt;
  }
  if (context_.via == Via::tcp) {
    if (auto authorized = check_and_strip_token(parsed->params, shared_->settings.token); !authorized) {
      shared_->log->warn("client {} ({}): {} without a valid token", context_.id, peer_, parsed->method);
      const std::string reply = error_line(parsed->id, authorized.error());
      if (!authenticated_) refuse_and_hang_up(reply, "no valid token");
      else if (!parsed->is_notification) send_line(reply);
      return std::nullopt;
    }
    if (!authenticated_) {
      authenticated_ = true;
      arm_idle_timer();  // the idle timeout from now on, not the pre-auth deadline
    }
  }
  return std::move(*parsed);
}

// The next waiting request to the worker, once the one before has come back (replies in order).
void Connection::dispatch_next() {
  if (busy_ || closed_ || waiting_.empty()) return;
  Pending next = std::move(waiting_.front());
  waiting_.pop_front();
  waiting_bytes_ -= next.bytes;
  busy_ = true;
  if (read_paused_ && !draining_) {
    read_paused_ = false;
    read_next();
  }
  boost::asio::post(shared_->worker, [self = shared_from_this(), next = std::move(next), context = context_,
                                      was_subscribed = context_.subscribed]() mutable {
    {
      // Closed while it waited (the client left, the server stopped): not run. Released under
      // the lock, as the io thread's handlers do, in case this was the last reference.
      std::lock_guard lock(self->shared_->mutex);
      if (self->closed_) {
        self.reset();
        return;
      }
    }
    nlohmann::json id;
    bool notification = false;
    RpcResult result = std::unexpected(RpcError{rpc_code::internal_error, "internal error", {}});
    std::optional<RpcRequest> request = std::move(next.request);
    if (!request) {  // a long line: parsed here, its token checked here
      auto parsed = parse_request(next.raw);
      if (!parsed) result = std::unexpected(parsed.error().error), id = parsed.error().id;
      else if (auto ok = context.via == Via::tcp ? check_and_strip_token(parsed->params, self->shared_->settings.token)
                                         : std::expected<void, RpcError>{};
               !ok)
        result = std::unexpected(ok.error()), id = parsed->id;
      else request = std::move(*parsed);
    }
    if (request) {
      id = request->id;
      notification = request->is_notification;
      result = self->invoke(*request, context);
    }
    // The handler worked on a copy of the client's context: what it changed (a subscription)
    // is applied on the io thread, where broadcasts read it. Only a change: an inline
    // server.subscribe that overtook this request must not be undone by its reply.
    const std::optional<bool> subscribed =
        context.subscribed != was_subscribed ? std::optional<bool>(context.subscribed) : std::nullopt;
    boost::asio::post(self->transport_->executor(), [self, id = std::move(id), notification, result = std::move(result),
                                                     subscribed] {
      std::lock_guard lock(self->shared_->mutex);
      if (subscribed) self->context_.subscribed = *subscribed;
      self->on_worker_done(id, notification, result);
    });
  });
}

void Connection::on_worker_done(const nlohmann::json& id, bool notification, RpcResult result) {
  busy_ = false;
  if (closed_) return;
  if (!notification) send_line(result ? result_line(id, *result) : error_line(id, result.error()));
  if (closed_) return;
  dispatch_next();
  if (peer_done_ && may_close_after_eof()) close("client hung up");
}

RpcResult Connection::invoke(const RpcRequest& request, ClientContext& context) {
  if (!shared_->handler) return std::unexpected(RpcError{rpc_code::shutting_down, "shutting down", {}});
  // A handler's bug must cost one reply, not the daemon (and the machine it drives).
  try {
    return shared_->handler(request, context);
  } catch (const std::exception& e) {
    shared_->log->error("client {}: {} threw: {}", context.id, request.method, e.what());
    return std::unexpected(RpcError{rpc_code::internal_error, "internal error", e.what()});
  } catch (...) {
    shared_->log->error("client {}: {} threw a non-standard exception", context.id, request.method);
    return std::unexpected(RpcError{rpc_code::internal_error, "internal error", {}});
  }
}

void Connection::send_line(std::string line) { send(std::make_shared<const std::string>(std::move(line))); }

void Connection::refuse_oversize(std::size_t bytes) {
  const std::size_t limit = context_.via == Via::tcp && !authenticated_ ? shared_->settings.pre_auth_max_bytes
                                                                : shared_->settings.max_request_bytes;
  shared_->log->warn("client {} ({}): request of {} bytes over the limit of {}; closing", context_.id, peer_, bytes,
                     limit);
  partial_.clear();
  partial_.shrink_to_fit();
  refuse_and_hang_up(error_line(nullptr, RpcError{rpc_code::invalid_request,
                                                  fmt::format("request too large ({} bytes, limit {}{})", bytes, limit,
                                                              limit < shared_->settings.max_request_bytes
                                                                  ? " before a valid token"
                                                                  : ""),
                                                  {}}),
                     "request too large");
}

// The reply is written, input is read and discarded (closing with unread input would make TCP
// send a reset that can destroy the reply before the client reads it), and the connection
// closes on the client's EOF or when linger_ expires.
void Connection::refuse_and_hang_up(std::string line, std::string_view why) {
  draining_ = true;
  waiting_.clear();
  waiting_bytes_ = 0;
  send_line(std::move(line));
  if (closed_) return;  // the reply alone passed max_queued_bytes
  linger_.emplace(transport_->executor(), linger_after_refusal);
  linger_->async_wait([self = shared_from_this(), why = std::string(why)](const boost::system::error_code& error) {
    std::lock_guard lock(self->shared_->mutex);
    if (!error) self->close(fmt::format("did not hang up after: {}", why));
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
  // Everything queued goes to the transport at once (a socket writes it gathered).
  in_flight_.assign(std::make_move_iterator(queue_.begin()), std::make_move_iterator(queue_.end()));
  queue_.clear();
  writing_ = true;
  transport_->async_write(in_flight_, [self = shared_from_this()](const boost::system::error_code& error) {
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
  } else if (peer_done_ && may_close_after_eof()) {
    close("client hung up");
  } else if (draining_ && !peer_done_) {
    // The refusal is out: half-close so the client sees EOF, and keep discarding its input until
    // it hangs up too (or linger_ expires).
    transport_->shutdown_send();
  }
}

void Connection::close(std::string_view reason) {
  if (closed_) return;
  closed_ = true;
  const auto self = shared_from_this();  // on_closed_ may drop the server's reference to us
  shared_->log->debug("client {} ({}) closed: {}", context_.id, peer_, reason);
  // Before the socket closes: whoever sees the EOF must find the client gone from the count.
  if (auto on_closed = std::exchange(on_closed_, nullptr)) on_closed(context_.id);
  transport_->close();  // pending operations complete with operation_aborted
  if (linger_) linger_->cancel();
  if (idle_timer_) idle_timer_->cancel();
  queue_.clear();
  waiting_.clear();
  // in_flight_ stays: the aborted write's buffers point into it until its handler has run.
}

}  // namespace lamina::daemon::rpc_detail
