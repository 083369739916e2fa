#include "lamina/daemon/rpc_client.hpp"

#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <utility>

#include <fmt/format.h>

namespace lamina::daemon {
namespace {

using nlohmann::json;

std::int64_t now_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::int64_t deadline_after(double seconds) {
  if (!(seconds > 0)) return now_ms();  // also NaN: no waiting
  return now_ms() + static_cast<std::int64_t>(std::ceil(std::min(seconds, 1e9) * 1000.0));
}

int remaining_ms(std::int64_t deadline) {
  return static_cast<int>(std::clamp<std::int64_t>(deadline - now_ms(), 0, 1 << 30));
}

std::unexpected<RpcError> transport(std::string message) {
  return std::unexpected(RpcError{rpc_code::transport_error, std::move(message), {}});
}

bool is_notification(const json& message) {
  return message.is_object() && !message.contains("id") && message.contains("method");
}

}  // namespace

RpcClient::RpcClient(int fd, std::string token, bool via_tcp) : fd_(fd), token_(std::move(token)), via_tcp_(via_tcp) {}

RpcClient::RpcClient(RpcClient&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      token_(std::move(other.token_)),
      via_tcp_(other.via_tcp_),
      next_id_(other.next_id_),
      buffer_(std::move(other.buffer_)),
      notifications_(std::move(other.notifications_)) {}

RpcClient& RpcClient::operator=(RpcClient&& other) noexcept {
  if (this != &other) {
    close();
    fd_ = std::exchange(other.fd_, -1);
    token_ = std::move(other.token_);
    via_tcp_ = other.via_tcp_;
    next_id_ = other.next_id_;
    buffer_ = std::move(other.buffer_);
    notifications_ = std::move(other.notifications_);
  }
  return *this;
}

RpcClient::~RpcClient() { close(); }

void RpcClient::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

std::expected<RpcClient, std::string> RpcClient::connect_unix(const std::string& path) {
  sockaddr_un address{};
  if (path.size() >= sizeof address.sun_path) return std::unexpected(fmt::format("socket path too long: {}", path));
  address.sun_family = AF_UNIX;
  std::memcpy(address.sun_path, path.c_str(), path.size() + 1);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return std::unexpected(fmt::format("cannot create a socket: {}", std::strerror(errno)));
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    const int error = errno;
    ::close(fd);
    return std::unexpected(fmt::format("cannot connect to {}: {}", path, std::strerror(error)));
  }
  return RpcClient(fd, {}, false);
}

std::expected<RpcClient, std::string> RpcClient::connect_tcp(const std::string& host, int port, std::string token) {
  if (token.empty()) return std::unexpected(fmt::format("connecting to {}:{}: TCP needs a token", host, port));
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (const int rc = ::getaddrinfo(host.c_str(), service.c_str(), &hints, &found); rc != 0)
    return std::unexpected(fmt::format("cannot resolve {}: {}", host, ::gai_strerror(rc)));
  std::string last_error = "no address";
  int fd = -1;
  for (const addrinfo* candidate = found; candidate != nullptr && fd < 0; candidate = candidate->ai_next) {
    fd = ::socket(candidate->ai_family, candidate->ai_socktype | SOCK_CLOEXEC, candidate->ai_protocol);
    if (fd < 0) {
      last_error = std::strerror(errno);
      continue;
    }
    if (::connect(fd, candidate->ai_addr, candidate->ai_addrlen) != 0) {
      last_error = std::strerror(errno);
      ::close(fd);
      fd = -1;
    }
  }
  ::freeaddrinfo(found);
  if (fd < 0) return std::unexpected(fmt::format("cannot connect to {}:{}: {}", host, port, last_error));
  const int on = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);  // one small request, then wait
  return RpcClient(fd, std::move(token), true);
}

std::string RpcClient::send_all(const std::string& data, std::int64_t deadline_ms) {
  std::size_t sent = 0;
  while (sent < data.size()) {
    const ssize_t n = ::send(fd_, data.data() + sent, data.size() - sent, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      pollfd writable{fd_, POLLOUT, 0};
      const int rc = ::poll(&writable, 1, remaining_ms(deadline_ms));
      if (rc > 0 || (rc < 0 && errno == EINTR)) continue;
      if (rc == 0) return "timed out";
    }
    return n == 0 ? std::string("nothing sent") : std::string(std::strerror(errno));
  }
  return {};
}

RpcClient::ReadStatus RpcClient::read_line(std::string& line, std::int64_t deadline_ms) {
  for (;;) {
    if (const auto newline = buffer_.find('\n'); newline != std::string::npos) {
      line.assign(buffer_, 0, newline);
      buffer_.erase(0, newline + 1);
      return ReadStatus::line;
    }
    if (fd_ < 0) return ReadStatus::closed;
    pollfd readable{fd_, POLLIN, 0};
    const int rc = ::poll(&readable, 1, remaining_ms(deadline_ms));
    if (rc < 0 && errno == EINTR) continue;
    if (rc < 0) return ReadStatus::closed;
    if (rc == 0) return ReadStatus::timeout;
    char chunk[64 * 1024];
    const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
    if (n > 0) {
      buffer_.append(chunk, static_cast<std::size_t>(n));
    } else if (n == 0 || (errno != EINTR && errno != EAGAIN)) {
      return ReadStatus::closed;
    }
  }
}

std::expected<json, RpcError> RpcClient::call(const std::string& method, json params, double timeout_s) {
  if (fd_ < 0) return transport("not connected");
  // Over TCP the daemon reads only a few KiB of a line until a request has shown the token: a
  // large first request (an upload chunk) goes after a small one that does.
  constexpr std::size_t kSmallFirstRequest = 2048;
  if (via_tcp_ && next_id_ == 1 && method != "server.info" && params.dump().size() > kSmallFirstRequest) {
    auto hello = call("server.info", json::object(), timeout_s);
    if (!hello && (hello.error().code == rpc_code::unauthorized || fd_ < 0)) return hello;
  }
  const std::int64_t id = next_id_++;
  if (via_tcp_) {
    if (params.is_null()) params = json::object();
    if (params.is_object()) params["token"] = token_;  // an array cannot carry it: the server refuses
  }
  const json request{{"jsonrpc", "2.0"}, {"id", id}, {"method", method}, {"params", std::move(params)}};
  const std::int64_t deadline = deadline_after(timeout_s);
  if (const std::string why = send_all(request.dump(-1, ' ', false, json::error_handler_t::replace) + "\n", deadline);
      !why.empty()) {
    close();  // part of a request may be on the wire: the stream is no longer usable
    return transport(fmt::format("cannot send {}: {}", method, why));
  }
  for (;;) {
    std::string line;
    const ReadStatus status = read_line(line, deadline);
    if (status == ReadStatus::timeout) return transport(fmt::format("no reply to {} within {} s", method, timeout_s));
    if (status == ReadStatus::closed) {
      close();
      return transport(fmt::format("the server closed the connection during {}", method));
    }
    json message = json::parse(line, nullptr, /*allow_exceptions=*/false);
    if (message.is_discarded() || !message.is_object()) {
      close();
      return transport(fmt::format("unreadable reply to {}", method));
    }
    if (is_notification(message)) {
      notifications_.push_back(std::move(message));
      continue;
    }
    const auto reply_id = message.find("id");
    if (reply_id == message.end()) continue;
    const auto error = message.find("error");
    // A null id: the server could not read the request (too large, say), and ours is the only
    // one outstanding. Another id: the late reply to a call that timed out.
    if (*reply_id != id && !(reply_id->is_null() && error != message.end())) continue;
    if (error != message.end()) {
      RpcError failure;
      if (!error->is_object()) return transport(fmt::format("malformed error in the reply to {}", method));
      const auto code = error->find("code");
      const auto text = error->find("message");
      failure.code = code != error->end() && code->is_number_integer() ? code->get<int>() : rpc_code::internal_error;
      failure.message = text != error->end() && text->is_string() ? text->get<std::string>() : std::string();
      if (const auto data = error->find("data"); data != error->end()) failure.data = *data;
      return std::unexpected(std::move(failure));
    }
    const auto result = message.find("result");
    return result != message.end() ? std::move(*result) : json();
  }
}

std::optional<json> RpcClient::next_notification(double timeout_s) {
  const std::int64_t deadline = deadline_after(timeout_s);
  while (notifications_.empty()) {
    std::string line;
    const ReadStatus status = read_line(line, deadline);
    if (status == ReadStatus::timeout) return std::nullopt;
    if (status == ReadStatus::closed) {
      close();
      return std::nullopt;
    }
    json message = json::parse(line, nullptr, /*allow_exceptions=*/false);
    if (is_notification(message)) notifications_.push_back(std::move(message));
    // Anything else is a reply to no outstanding call (a timed-out one): dropped.
  }
  json next = std::move(notifications_.front());
  notifications_.pop_front();
  return next;
}

}  // namespace lamina::daemon
