#pragma once
// Where the CNC's serial line ends on the simulator's side: a PTY master whose slave is
// symlinked at --link PATH, or one TCP connection on a loopback port (grblHAL's telnet-style
// stream). The loop paces the bytes; a port only moves them and tells who is there.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace lamina::sim {

enum class PortChange { none, client_connected, client_gone };

class CncPort {
 public:
  virtual ~CncPort() = default;
  // Check whether a client came or went (PTY slave opened / closed, TCP accept / EOF).
  virtual PortChange update() = 0;
  virtual bool client_present() const = 0;
  // Non-blocking; 0 when nothing is there; -1 when the client is gone.
  virtual long read_some(std::uint8_t* buffer, std::size_t size) = 0;
  virtual long write_some(const std::uint8_t* data, std::size_t size) = 0;
  // Bytes the client wrote that are waiting to be read (FIONREAD); 0 when none or no client.
  virtual std::size_t input_waiting() const = 0;
  // Fault: pull the cable (close the PTY and remove the link / drop the TCP client and stop
  // listening). replug() brings the port back (a new PTY at the same link path).
  virtual void unplug() = 0;
  virtual void replug() = 0;
  virtual bool plugged() const = 0;
  virtual int poll_fd() const = 0;  // -1 when there is nothing to wait on
  virtual std::string describe() const = 0;
};

// Throws std::runtime_error (naming the path and errno) when the PTY or link cannot be made.
std::unique_ptr<CncPort> open_pty_port(const std::string& link_path);
std::unique_ptr<CncPort> open_tcp_port(const std::string& host, int port);
int tcp_port_number(const CncPort& port);  // the bound port of a TCP CncPort (0 for a PTY)

}  // namespace lamina::sim
