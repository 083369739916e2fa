#include "exec_log.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

namespace lamina::sim {
namespace {

nlohmann::json axes_json(const AxisValues& axes) {
  auto out = nlohmann::json::array();
  for (double v : axes) out.push_back(std::round(v * 1e6) / 1e6);  // 1 nm / 1 µdeg is plenty
  return out;
}

}  // namespace

nlohmann::json to_json_record(const MachineEvent& event, const std::optional<HeadGeometry>& head) {
  if (const auto* b = std::get_if<ExecutedBlock>(&event)) {
    nlohmann::json r{{"seq", b->seq},       {"line", b->line},       {"start", axes_json(b->start)},
                     {"end", axes_json(b->end)}, {"jet", b->jet}, {"t_start", b->t_start_s},
                     {"t_end", b->t_end_s}};
    if (!b->completed) r["completed"] = false;
    if (head) {
      const JetPose pose = jet_pose(b->end, *head);
      r["tip"] = pose.tip_mm;
      r["axis"] = pose.axis;
    }
    return r;
  }
  if (const auto* s = std::get_if<StarvationEvent>(&event))
    return {{"event", "starvation"}, {"t", s->t_s}, {"after_seq", s->after_seq}};
  const auto& a = std::get<AlarmEvent>(event);
  return {{"event", "alarm"}, {"t", a.t_s}, {"code", static_cast<int>(a.code)}, {"seq", a.seq}};
}

ExecLog::ExecLog(const std::string& path, std::optional<HeadGeometry> head) : head_(head) {
  if (path.empty()) return;
  file_ = std::fopen(path.c_str(), "w");
  if (!file_)
    throw std::runtime_error(fmt::format("cannot open the execution log {}: {}", path, std::strerror(errno)));
}

ExecLog::~ExecLog() {
  if (file_) std::fclose(file_);
}

void ExecLog::write(const MachineEvent& event) { write_line(to_json_record(event, head_)); }

void ExecLog::write_event(std::string_view name, double t_s, nlohmann::json fields) {
  fields["event"] = name;
  fields["t"] = t_s;
  write_line(fields);
}

void ExecLog::write_line(const nlohmann::json& record) {
  if (!file_) return;
  // Invalid UTF-8 from a garbled line is replaced, never thrown: the log must not stop the sim.
  const std::string text = record.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::fputs(text.c_str(), file_);
  std::fputc('\n', file_);
  std::fflush(file_);
}

}  // namespace lamina::sim
