#include "warning_log.hpp"

#include <chrono>

namespace lamina::daemon {
namespace {

const char* level_name(spdlog::level::level_enum level) {
  switch (level) {
    case spdlog::level::warn: return "warning";
    case spdlog::level::err: return "error";
    case spdlog::level::critical: return "critical";
    default: return "info";
  }
}

}  // namespace

WarningLog::WarningLog(std::size_t capacity) : capacity_(capacity == 0 ? 1 : capacity) {
  set_level(spdlog::level::warn);
}

void WarningLog::sink_it_(const spdlog::details::log_msg& msg) {
  LoggedWarning w;
  w.t_unix_ms = std::chrono::duration_cast<std::chrono::milliseconds>(msg.time.time_since_epoch()).count();
  w.level = level_name(msg.level);
  w.source.assign(msg.logger_name.begin(), msg.logger_name.end());
  w.message.assign(msg.payload.begin(), msg.payload.end());
  std::lock_guard lock(entries_mutex_);
  w.seq = next_seq_++;
  entries_.push_back(std::move(w));
  while (entries_.size() > capacity_) entries_.pop_front();
}

std::vector<LoggedWarning> WarningLog::since(std::uint64_t after) const {
  std::lock_guard lock(entries_mutex_);
  std::vector<LoggedWarning> out;
  for (const LoggedWarning& w : entries_)
    if (w.seq > after) out.push_back(w);
  return out;
}

}  // namespace lamina::daemon
