#pragma once
// `lamina plan --progress-fd N`: one JSON line per phase as it starts, on a descriptor the
// caller opened (laminad passes a pipe), so a job's planning shows as steps rather than one long
// "planning". Lines: {"phase":"planning bevels","step":3,"steps":7}; the last is "done". Inside
// a long phase, its steps as they finish (issue 18): {"phase":"measuring deviation","step":5,
// "steps":7,"done":2,"total":3}.
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace lamina::cli {

class PlanProgress {
 public:
  PlanProgress(int fd, int steps) : fd_(fd), steps_(steps) {
    // A reader that went away must not kill the planner (SIGPIPE): the plan still gets written.
    if (fd_ >= 0) ::signal(SIGPIPE, SIG_IGN);
  }
  void phase(std::string_view name) { emit(nlohmann::json{{"phase", name}, {"step", ++step_}, {"steps", steps_}}); }
  // A step of the current phase finished: `done` of `total`.
  void within(std::string_view name, int done, int total) {
    emit(nlohmann::json{{"phase", name}, {"step", step_}, {"steps", steps_}, {"done", done}, {"total", total}});
  }
  void done() { emit(nlohmann::json{{"phase", "done"}, {"step", steps_}, {"steps", steps_}}); }

 private:
  void emit(const nlohmann::json& j) {
    if (fd_ < 0) return;
    const std::string line = j.dump() + "\n";
    for (std::size_t off = 0; off < line.size();) {
      const ssize_t n = ::write(fd_, line.data() + off, line.size() - off);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        fd_ = -1;  // progress is a courtesy: stop reporting, keep planning
        return;
      }
      off += static_cast<std::size_t>(n);
    }
  }
  int fd_;
  int steps_;
  int step_ = 0;
};

}  // namespace lamina::cli
