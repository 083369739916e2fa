#include "stream_terminal.hpp"

#include <poll.h>
#include <unistd.h>

#include <cctype>
#include <string>

#include <fmt/format.h>

namespace lamina::cli {

KeyboardControl::KeyboardControl() {
  if (!::isatty(STDIN_FILENO) || ::tcgetattr(STDIN_FILENO, &saved_) != 0) return;
  termios raw = saved_;
  raw.c_lflag &= static_cast<tcflag_t>(~(ICANON | ECHO));
  raw.c_cc[VMIN] = 0;
  raw.c_cc[VTIME] = 0;
  interactive_ = ::tcsetattr(STDIN_FILENO, TCSANOW, &raw) == 0;
}

KeyboardControl::~KeyboardControl() {
  if (interactive_) ::tcsetattr(STDIN_FILENO, TCSANOW, &saved_);
}

Key KeyboardControl::poll() {
  if (!interactive_) return Key::none;
  pollfd p{STDIN_FILENO, POLLIN, 0};
  if (::poll(&p, 1, 0) <= 0) return Key::none;
  char c = 0;
  if (::read(STDIN_FILENO, &c, 1) != 1) return Key::none;
  switch (std::tolower(static_cast<unsigned char>(c))) {
    case 'h':
    case ' ': return Key::hold;
    case 'r': return Key::resume;
    case 'q': return Key::quit;
    default: return Key::none;
  }
}

Key KeyboardControl::wait_resume_or_quit() {
  for (;;) {
    const Key k = poll();
    if (k == Key::resume || k == Key::quit) return k;
    pollfd p{STDIN_FILENO, POLLIN, 0};
    ::poll(&p, 1, 200);
  }
}

ProgressLine::ProgressLine(std::size_t total_lines, bool enabled) : total_(total_lines), enabled_(enabled) {}

void ProgressLine::update(const drivers::CutReport& report) {
  if (!enabled_ || total_ == 0) return;
  const double fraction = static_cast<double>(report.lines_accepted) / static_cast<double>(total_);
  const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::string eta = "--:--";
  if (fraction > 0.01) {
    const auto left = static_cast<long>(elapsed_s * (1 - fraction) / fraction);
    eta = fmt::format("{}:{:02}", left / 60, left % 60);
  }
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(fraction * kWidth);
  fmt::print(stderr, "\r[{}{}] {}/{} lines {:5.1f} %  ETA {}  {}   ", std::string(static_cast<std::size_t>(filled), '#'),
             std::string(static_cast<std::size_t>(kWidth - filled), '-'), report.lines_accepted, total_,
             100 * fraction, eta, drivers::to_string(report.state));
  drawn_ = true;
}

void ProgressLine::clear() {
  if (drawn_) fmt::print(stderr, "\r{}\r", std::string(100, ' '));
  drawn_ = false;
}

}  // namespace lamina::cli
