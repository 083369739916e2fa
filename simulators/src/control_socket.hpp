#pragma once
// The simulator's loopback control socket: a test or an operator script connects and sends
// one text command per line (see docs/simulator.md); each gets one reply line. Several
// clients may connect; a client that sends more than 4 KiB without a newline is dropped.
#include <functional>
#include <string>
#include <vector>

namespace lamina::sim {

class ControlSocket {
 public:
  ControlSocket(const std::string& host, int port);  // throws on start-up failure
  ~ControlSocket();
  ControlSocket(const ControlSocket&) = delete;
  ControlSocket& operator=(const ControlSocket&) = delete;

  int port() const { return port_; }
  // Accept, read, and answer every complete command line with `handle(line)`.
  void serve(const std::function<std::string(const std::string&)>& handle);
  std::vector<int> poll_fds() const;

 private:
  struct Client {
    int fd;
    std::string pending;
  };
  int listen_fd_ = -1;
  int port_ = 0;
  std::vector<Client> clients_;
};

}  // namespace lamina::sim
