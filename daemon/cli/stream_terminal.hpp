#pragma once
// The operator's side of `lamina stream`: keys from a raw terminal and a one-line progress bar.
#include <termios.h>

#include <chrono>
#include <cstddef>

#include "lamina/drivers/cut_job.hpp"

namespace lamina::cli {

enum class Key { none, hold, resume, quit };

// Puts stdin in non-canonical, no-echo mode while alive, when stdin is a terminal.
class KeyboardControl {
 public:
  KeyboardControl();
  ~KeyboardControl();
  KeyboardControl(const KeyboardControl&) = delete;
  KeyboardControl& operator=(const KeyboardControl&) = delete;
  bool interactive() const { return interactive_; }
  Key poll();                  // h / space → hold, r → resume, q → quit
  Key wait_resume_or_quit();   // blocks for R or Q

 private:
  bool interactive_ = false;
  termios saved_{};
};

// "[#####-----] 1234/20000 lines  6.2 %  ETA 3:12" on stderr, redrawn in place.
class ProgressLine {
 public:
  ProgressLine(std::size_t total_lines, bool enabled);
  void update(const drivers::CutReport& report);
  void clear();

 private:
  std::size_t total_;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace lamina::cli
