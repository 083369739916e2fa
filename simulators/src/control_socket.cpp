#include "control_socket.hpp"

#include <cerrno>
#include <sys/socket.h>
#include <unistd.h>

#include "net_util.hpp"

namespace lamina::sim {

ControlSocket::ControlSocket(const std::string& host, int port) {
  listen_fd_ = listen_loopback(host, port);
  port_ = bound_port(listen_fd_);
}

ControlSocket::~ControlSocket() {
  for (auto& c : clients_) ::close(c.fd);
  if (listen_fd_ >= 0) ::close(listen_fd_);
}

std::vector<int> ControlSocket::poll_fds() const {
  std::vector<int> fds{listen_fd_};
  for (const auto& c : clients_) fds.push_back(c.fd);
  return fds;
}

void ControlSocket::serve(const std::function<std::string(const std::string&)>& handle) {
  for (int fd; (fd = accept_nonblocking(listen_fd_)) >= 0;) clients_.push_back({fd, {}});
  constexpr std::size_t kMaxLine = 4096;
  for (auto it = clients_.begin(); it != clients_.end();) {
    char buffer[1024];
    bool drop = false;
    for (;;) {
      const ssize_t n = ::recv(it->fd, buffer, sizeof buffer, 0);
      if (n > 0) {
        it->pending.append(buffer, static_cast<std::size_t>(n));
        continue;
      }
      if (n == 0 || (errno != EAGAIN && errno != EINTR)) drop = true;
      break;
    }
    for (std::size_t eol; (eol = it->pending.find('\n')) != std::string::npos;) {
      std::string line = it->pending.substr(0, eol);
      it->pending.erase(0, eol + 1);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      const std::string reply = handle(line) + "\n";
      // Replies are short; a client that does not read them loses them rather than block us.
      if (::send(it->fd, reply.data(), reply.size(), MSG_NOSIGNAL) < 0 && errno != EAGAIN) drop = true;
    }
    if (it->pending.size() > kMaxLine) drop = true;
    if (drop) {
      ::close(it->fd);
      it = clients_.erase(it);
    } else {
      ++it;
    }
  }
}

}  // namespace lamina::sim
