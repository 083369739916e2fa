#pragma once
// A controller personality: what the CNC does with the bytes that arrive on its serial (or
// TCP) line and what it answers. The link (link.hpp) delivers bytes at the emulated baud and
// drains output at the same rate; the personality decides what a byte means.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>

#include "machine.hpp"

namespace lamina::sim {

struct ProtocolFaults {
  std::optional<std::uint64_t> drop_ok_index;  // 1-based: the k-th `ok` is never sent
};

struct ProtocolCounters {
  std::uint64_t lines_received = 0;    // complete lines taken out of the receive buffer
  std::uint64_t bytes_received = 0;    // bytes that reached the receive buffer (not dropped)
  std::uint64_t bytes_dropped = 0;     // bytes lost to a full receive buffer (overflow)
  std::uint64_t oks_sent = 0;
  std::uint64_t oks_dropped = 0;
  std::uint64_t errors_sent = 0;
};

class CncProtocol {
 public:
  virtual ~CncProtocol() = default;
  // A client connected (PTY opened / TCP accepted) or the controller powered up: banner.
  virtual void on_connect(double now_s) = 0;
  // One byte arrived off the wire. Real-time bytes act at once; others go into the receive
  // buffer, or are lost when it is full.
  virtual void on_byte(std::uint8_t byte, double now_s) = 0;
  // Move complete lines from the receive buffer into the machine while it has room (not while
  // stalled), answer them, and report what the machine did (alarms, resets).
  virtual void poll(double now_s) = 0;
  // Bytes to send to the client, in order (the link paces them).
  virtual std::string take_output() = 0;
  // That many more of those bytes have crossed the wire (or were lost with nobody listening):
  // a flow-control stop counts from when the sender could see it, not from when it was said.
  virtual void on_output_sent(std::size_t /*bytes*/) {}
  // Fault: stop taking lines out of the receive buffer (the machine still runs its queue).
  virtual void set_stalled(bool stalled) = 0;
  // Operator-side reset / e-stop arrive through the PLC or the control socket.
  virtual void external_reset(double now_s) = 0;
  virtual std::size_t rx_free() const = 0;
  // Flow control against the emulation's own lateness. On a real line the controller's UART
  // takes bytes one at a time and turns the line round (DC3) at the byte that crosses its mark;
  // this loop may wake late and find a burst waiting. input_room(): how many bytes the link may
  // deliver now before asking again (unlimited unless the personality flow-controls).
  // set_bytes_in_transit(n), called every loop: n bytes the sender wrote while the emulation
  // was behind are waiting — on a real wire they had crossed before a stop could be sent.
  virtual std::size_t input_room() const { return std::numeric_limits<std::size_t>::max(); }
  virtual void set_bytes_in_transit(std::size_t /*bytes*/) {}
  virtual const ProtocolCounters& counters() const = 0;
};

}  // namespace lamina::sim
