#include "lamina/daemon/job_model.hpp"

#include <array>
#include <utility>

namespace lamina::daemon {
namespace {

constexpr std::array<std::pair<JobState, const char*>, 11> kJobStates{{
    {JobState::queued, "queued"},
    {JobState::planning, "planning"},
    {JobState::planned, "planned"},
    {JobState::waiting_sheet, "waiting_sheet"},
    {JobState::cutting, "cutting"},
    {JobState::paused, "paused"},
    {JobState::sheet_done, "sheet_done"},
    {JobState::completed, "completed"},
    {JobState::failed, "failed"},
    {JobState::cancelled, "cancelled"},
    {JobState::interrupted, "interrupted"},
}};

constexpr std::array<std::pair<SheetState, const char*>, 5> kSheetStates{{
    {SheetState::pending, "pending"},
    {SheetState::cutting, "cutting"},
    {SheetState::paused, "paused"},
    {SheetState::done, "done"},
    {SheetState::interrupted, "interrupted"},
}};

template <typename Enum, std::size_t N>
const char* name_of(const std::array<std::pair<Enum, const char*>, N>& table, Enum value) {
  for (const auto& [e, name] : table)
    if (e == value) return name;
  return "?";
}

template <typename Enum, std::size_t N>
std::optional<Enum> value_of(const std::array<std::pair<Enum, const char*>, N>& table, const std::string& text) {
  for (const auto& [e, name] : table)
    if (text == name) return e;
  return std::nullopt;
}

}  // namespace

const char* to_string(JobState state) { return name_of(kJobStates, state); }
std::optional<JobState> job_state_from_string(const std::string& text) { return value_of(kJobStates, text); }
bool is_terminal(JobState s) { return s == JobState::completed || s == JobState::failed || s == JobState::cancelled; }

const char* to_string(SheetState state) { return name_of(kSheetStates, state); }
std::optional<SheetState> sheet_state_from_string(const std::string& text) { return value_of(kSheetStates, text); }

nlohmann::json to_json(const SheetRecord& s) {
  nlohmann::json j{{"index", s.index},
                   {"program", s.program_path},
                   {"svg", s.svg_path},
                   {"material", s.material},
                   {"thickness_mm", s.thickness_mm},
                   {"lines", s.lines_total},
                   {"state", to_string(s.state)},
                   {"last_acked_line", s.last_acked_line},
                   {"resume_line", s.first_unfinished_line + 1},
                   {"contour", s.contour},
                   {"cut_seconds", s.cut_seconds}};
  return j;
}

nlohmann::json to_json(const JobRecord& job) {
  nlohmann::json sheets = nlohmann::json::array();
  for (const SheetRecord& s : job.sheets) sheets.push_back(to_json(s));
  nlohmann::json j{{"id", job.id},
          {"state", to_string(job.state)},
          {"name", job.name},
          {"model", job.model_path},
          {"settings", job.plan_settings},
          {"artefacts", job.artefact_dir},
          {"error", job.error},
          {"current_sheet", job.current_sheet},
          {"sheets", sheets},
          {"summary", job.summary},
          {"created_unix_ms", job.created_unix_ms},
          {"updated_unix_ms", job.updated_unix_ms}};
  if (job.state == JobState::planning && !job.planning.is_null()) j["planning"] = job.planning;
  return j;
}

nlohmann::json to_json(const JobEvent& e) {
  return {{"job", e.job_id}, {"t_unix_ms", e.t_unix_ms}, {"kind", e.kind}, {"data", e.data}};
}

}  // namespace lamina::daemon
