#pragma once
// The daemon's own warnings and errors, the last few hundred, for the people at the cell (the
// console's Warnings, `server.warnings`): an spdlog sink beside the journal's, so whatever any
// part of laminad warns about reaches the screen without each part knowing about the screen.
#include <spdlog/sinks/base_sink.h>

#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

namespace lamina::daemon {

struct LoggedWarning {
  std::uint64_t seq = 0;  // 1, 2, … in the order logged: a client asks for what came after its last
  std::int64_t t_unix_ms = 0;
  std::string level;      // "warning", "error", "critical"
  std::string source;     // the logger: laminad, jobs, cut, rpc, store
  std::string message;
};

class WarningLog final : public spdlog::sinks::base_sink<std::mutex> {
 public:
  static constexpr std::size_t kDefaultCapacity = 200;
  explicit WarningLog(std::size_t capacity = kDefaultCapacity);

  // Oldest first, those with seq > after only.
  std::vector<LoggedWarning> since(std::uint64_t after) const;

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override;
  void flush_() override {}

 private:
  std::size_t capacity_;
  mutable std::mutex entries_mutex_;  // base_sink's mutex guards sink_it_ only; readers take this one
  std::uint64_t next_seq_ = 1;
  std::deque<LoggedWarning> entries_;
};

}  // namespace lamina::daemon
