#pragma once
// Test helpers for code that drives a Transport: run the io_context in short slices until bytes
// or an error arrive, write and wait, and TCP peers that refuse or never answer.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>

#include "lamina/drivers/transport.hpp"

namespace lamina::drivers::testing {

inline double elapsed_s(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Keeps one read pending and collects what arrives; the handler refers to this object, so it is
// declared after the transport (destroyed first, and the io_context never runs again by then).
class Reader {
 public:
  Reader(boost::asio::io_context& io, Transport& transport) : io_(io), transport_(transport) {}

  // Runs the io_context in short slices until `text` was read, the link failed, or time is up.
  bool wait_for(const std::string& text, double wait_s) {
    return run_until([&] { return text_.find(text) != std::string::npos; }, wait_s);
  }
  // Until the pending read completes with an error.
  bool wait_for_error(double wait_s) {
    return run_until([&] { return static_cast<bool>(error_); }, wait_s);
  }
  void start() {
    if (pending_ || error_) return;
    pending_ = true;
    transport_.async_read_some(buffer_, [this](std::error_code ec, std::size_t n) {
      pending_ = false;
      if (ec) error_ = ec;
      else text_.append(reinterpret_cast<const char*>(buffer_.data()), n);
    });
  }
  const std::string& text() const { return text_; }
  std::error_code error() const { return error_; }
  bool pending() const { return pending_; }

 private:
  template <class Done>
  bool run_until(Done done, double wait_s) {
    const auto t0 = std::chrono::steady_clock::now();
    while (!done() && elapsed_s(t0) < wait_s) {
      start();
      io_.restart();
      io_.run_for(std::chrono::milliseconds(20));
      if (error_ && !done()) return false;
    }
    return done();
  }

  boost::asio::io_context& io_;
  Transport& transport_;
  std::array<std::uint8_t, 256> buffer_{};
  std::string text_;
  std::error_code error_;
  bool pending_ = false;
};

// Writes `text` and runs the io_context until the write handler has run.
inline std::error_code write_all(boost::asio::io_context& io, Transport& t, const std::string& text) {
  std::optional<std::error_code> done;
  t.async_write({reinterpret_cast<const std::uint8_t*>(text.data()), text.size()},
                [&](std::error_code ec, std::size_t) { done = ec; });
  const auto t0 = std::chrono::steady_clock::now();
  while (!done && elapsed_s(t0) < 3.0) {
    io.restart();
    io.run_for(std::chrono::milliseconds(20));
  }
  return done.value_or(std::make_error_code(std::errc::timed_out));
}

// A port nobody listens on: bind one, note it, let it go.
inline int closed_tcp_port() {
  boost::asio::io_context io;
  boost::asio::ip::tcp::acceptor a(io, {boost::asio::ip::make_address("127.0.0.1"), 0});
  return a.local_endpoint().port();
}

// A peer that never answers a SYN. 10.255.255.1 would be the classic choice, but this machine's
// gateway accepts connections to any outside address; a listener whose accept queue is full is
// silent everywhere (Linux drops the SYN), so it stands in for the unreachable controller.
class SilentListener {
 public:
  SilentListener() {
    listener_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    ::inet_pton(AF_INET, "127.0.0.1", &addr.sin_addr);
    socklen_t len = sizeof addr;
    if (::bind(listener_, reinterpret_cast<sockaddr*>(&addr), len) != 0 || ::listen(listener_, 0) != 0)
      throw std::runtime_error("cannot listen");
    ::getsockname(listener_, reinterpret_cast<sockaddr*>(&addr), &len);
    port_ = ntohs(addr.sin_port);
    for (int i = 0; i < 4; ++i) {  // fill the queue (backlog 0 holds one); never accepted
      const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
      ::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
      fillers_.push_back(fd);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ~SilentListener() {
    for (int fd : fillers_) ::close(fd);
    ::close(listener_);
  }
  int port() const { return port_; }

 private:
  int listener_ = -1;
  int port_ = 0;
  std::vector<int> fillers_;
};

}  // namespace lamina::drivers::testing
