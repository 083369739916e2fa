#pragma once
// Emulated line speed: a byte may cross the wire only when the wire has had time to carry it.
// 8N1 framing puts 10 bits on the wire per byte, so baud/10 bytes per second. A small burst
// allowance absorbs the event loop waking late without changing the long-run rate.
#include <algorithm>
#include <cstddef>

namespace lamina::sim {

class BytePacer {
 public:
  BytePacer(double bytes_per_s, double burst_s)
      : bytes_per_s_(bytes_per_s), burst_s_(burst_s), burst_bytes_(std::max(1.0, bytes_per_s * burst_s)) {}

  // Bytes that may cross now (wall seconds). Credit accrues while the wire idles, capped.
  std::size_t allowance(double now_s) {
    if (last_s_ < 0) last_s_ = now_s;
    const double gap_s = now_s - last_s_;
    if (gap_s > burst_s_) late_bytes_ += gap_s * bytes_per_s_;
    credit_ = std::min(burst_bytes_, credit_ + gap_s * bytes_per_s_);
    last_s_ = now_s;
    return static_cast<std::size_t>(credit_);
  }
  void consume(std::size_t bytes) { credit_ -= static_cast<double>(bytes); }
  // Nothing was waiting to cross: the wire idled, and a byte written from now on takes its own
  // time on the wire. Without this, bytes written after a pause crossed at once on the saved
  // credit (up to the burst), and a real-time byte behind them looked faster than a UART.
  void idle() {
    credit_ = std::min(credit_, 0.0);
    late_bytes_ = 0;
  }
  // How far a sender pacing on its own clock may be ahead of this emulated wire: what the wire
  // carries in one burst (the loop's normal jitter) plus what it would have carried while the
  // caller woke later than that, since the wire last idled. A real line would already have
  // delivered those bytes; here they wait in the port.
  std::size_t bytes_behind_bound() const { return static_cast<std::size_t>(burst_bytes_ + late_bytes_); }
  // Seconds until one more byte may cross (for the loop's sleep).
  double seconds_to_next_byte() const { return credit_ >= 1 ? 0 : (1 - credit_) / bytes_per_s_; }
  double bytes_per_s() const { return bytes_per_s_; }

 private:
  double bytes_per_s_;
  double burst_s_;
  double burst_bytes_;
  double late_bytes_ = 0;
  double credit_ = 0;
  double last_s_ = -1;
};

}  // namespace lamina::sim
