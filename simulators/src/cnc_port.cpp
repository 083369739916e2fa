#include "cnc_port.hpp"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <stdexcept>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <fmt/format.h>

#include "net_util.hpp"

namespace lamina::sim {
namespace {

std::size_t bytes_readable(int fd) {
  int n = 0;
  if (fd < 0 || ::ioctl(fd, FIONREAD, &n) != 0 || n < 0) return 0;
  return static_cast<std::size_t>(n);
}

class PtyPort final : public CncPort {
 public:
  explicit PtyPort(std::string link) : link_(std::move(link)) { open_pty(); }
  ~PtyPort() override { close_pty(); }

  PortChange update() override {
    if (master_ < 0) return PortChange::none;
    // With no process holding the slave open the master reports POLLHUP: that is how we see
    // a client open the port (like DTR on a real adapter) and close it again.
    pollfd p{master_, POLLIN, 0};
    ::poll(&p, 1, 0);
    const bool present = (p.revents & POLLHUP) == 0;
    if (present == present_) return PortChange::none;
    present_ = present;
    if (present) {
      // Drop what the controller said while nobody listened; keep the input — the client may
      // already have written before we noticed it opened the port.
      ::tcflush(master_, TCOFLUSH);
      return PortChange::client_connected;
    }
    return PortChange::client_gone;
  }
  bool client_present() const override { return present_; }

  long read_some(std::uint8_t* buffer, std::size_t size) override {
    if (master_ < 0 || !present_) return -1;
    const ssize_t n = ::read(master_, buffer, size);
    if (n > 0) return n;
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return 0;
    return -1;
  }
  long write_some(const std::uint8_t* data, std::size_t size) override {
    if (master_ < 0 || !present_) return -1;
    const ssize_t n = ::write(master_, data, size);
    if (n >= 0) return n;
    return (errno == EAGAIN || errno == EINTR) ? 0 : -1;
  }
  std::size_t input_waiting() const override { return present_ ? bytes_readable(master_) : 0; }
  void unplug() override { close_pty(); }
  void replug() override {
    if (master_ < 0) open_pty();
  }
  bool plugged() const override { return master_ >= 0; }
  int poll_fd() const override { return present_ ? master_ : -1; }
  std::string describe() const override { return fmt::format("pty {} -> {}", link_, slave_name_); }

 private:
  void open_pty() {
    int slave = -1;
    char name[256] = {};
    termios raw{};
    cfmakeraw(&raw);
    if (::openpty(&master_, &slave, name, &raw, nullptr) != 0)
      throw std::runtime_error(fmt::format("openpty: {}", std::strerror(errno)));
    // The simulator keeps no slave descriptor: POLLHUP on the master then tells whether a
    // client has it open.
    ::close(slave);
    ::fcntl(master_, F_SETFL, ::fcntl(master_, F_GETFL) | O_NONBLOCK);
    ::fcntl(master_, F_SETFD, FD_CLOEXEC);
    slave_name_ = name;
    ::unlink(link_.c_str());
    if (::symlink(slave_name_.c_str(), link_.c_str()) != 0) {
      const int err = errno;
      close_pty();
      throw std::runtime_error(fmt::format("cannot link {} to {}: {}", link_, slave_name_, std::strerror(err)));
    }
    present_ = false;
  }
  void close_pty() {
    if (master_ >= 0) {
      ::close(master_);
      ::unlink(link_.c_str());
    }
    master_ = -1;
    present_ = false;
  }

  std::string link_;
  std::string slave_name_;
  int master_ = -1;
  bool present_ = false;
};

class TcpPort final : public CncPort {
 public:
  TcpPort(std::string host, int port) : host_(std::move(host)) {
    listen_fd_ = listen_loopback(host_, port);
    port_ = bound_port(listen_fd_);
  }
  ~TcpPort() override {
    drop_client();
    if (listen_fd_ >= 0) ::close(listen_fd_);
  }

  PortChange update() override {
    if (listen_fd_ < 0) return PortChange::none;
    for (int fd; (fd = accept_nonblocking(listen_fd_)) >= 0;) {
      if (client_ >= 0) {
        // One stream at a time, as a controller's telnet port: later ones are turned away.
        ::close(fd);
        continue;
      }
      client_ = fd;
      return PortChange::client_connected;
    }
    if (gone_) {
      gone_ = false;
      return PortChange::client_gone;
    }
    return PortChange::none;
  }
  bool client_present() const override { return client_ >= 0; }

  long read_some(std::uint8_t* buffer, std::size_t size) override {
    if (client_ < 0) return -1;
    const ssize_t n = ::recv(client_, buffer, size, 0);
    if (n > 0) return n;
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return 0;
    drop_client();
    gone_ = true;
    return -1;
  }
  long write_some(const std::uint8_t* data, std::size_t size) override {
    if (client_ < 0) return -1;
    const ssize_t n = ::send(client_, data, size, MSG_NOSIGNAL);
    if (n >= 0) return n;
    if (errno == EAGAIN || errno == EINTR) return 0;
    drop_client();
    gone_ = true;
    return -1;
  }
  void unplug() override {
    drop_client();
    if (listen_fd_ >= 0) ::close(listen_fd_);
    listen_fd_ = -1;
  }
  void replug() override {
    if (listen_fd_ < 0) listen_fd_ = listen_loopback(host_, port_);
  }
  bool plugged() const override { return listen_fd_ >= 0; }
  std::size_t input_waiting() const override { return bytes_readable(client_); }
  int poll_fd() const override { return client_; }
  std::string describe() const override { return fmt::format("tcp {}:{}", host_, port_); }
  int port() const { return port_; }

 private:
  void drop_client() {
    if (client_ >= 0) ::close(client_);
    client_ = -1;
  }

  std::string host_;
  int port_ = 0;
  int listen_fd_ = -1;
  int client_ = -1;
  bool gone_ = false;
};

}  // namespace

std::unique_ptr<CncPort> open_pty_port(const std::string& link_path) {
  return std::make_unique<PtyPort>(link_path);
}
std::unique_ptr<CncPort> open_tcp_port(const std::string& host, int port) {
  return std::make_unique<TcpPort>(host, port);
}
int tcp_port_number(const CncPort& port) {
  const auto* tcp = dynamic_cast<const TcpPort*>(&port);
  return tcp ? tcp->port() : 0;
}

}  // namespace lamina::sim
