#include "lamina/drivers/resume_point.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <optional>

#include <fmt/format.h>

namespace lamina::drivers {
namespace {

// The line without comments, upper-case, no spaces.
std::string words_of(std::string_view line) {
  std::string out;
  bool in_paren = false;
  for (char c : line) {
    if (in_paren) {
      in_paren = c != ')';
      continue;
    }
    if (c == '(') {
      in_paren = true;
      continue;
    }
    if (c == ';') break;
    if (!std::isspace(static_cast<unsigned char>(c))) out += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  return out;
}

std::optional<double> word_value(const std::string& words, char letter) {
  for (std::size_t i = 0; i < words.size(); ++i) {
    if (words[i] != letter) continue;
    std::size_t j = i + 1;
    while (j < words.size() && (std::isdigit(static_cast<unsigned char>(words[j])) || words[j] == '.' ||
                                words[j] == '-' || words[j] == '+'))
      ++j;
    try {
      return std::stod(words.substr(i + 1, j - i - 1));
    } catch (const std::exception&) {
      return std::nullopt;
    }
  }
  return std::nullopt;
}

bool has_g(const std::string& words, int code) {
  for (std::size_t i = 0; i < words.size(); ++i) {
    if (words[i] != 'G') continue;
    std::size_t j = i + 1;
    while (j < words.size() && (std::isdigit(static_cast<unsigned char>(words[j])) || words[j] == '.')) ++j;
    int value = -1;
    const auto text = words.substr(i + 1, j - i - 1);
    if (std::from_chars(text.data(), text.data() + text.size(), value).ec == std::errc() && value == code &&
        text.find('.') == std::string::npos)
      return true;
  }
  return false;
}

// `(CONTOUR n …)` → n.
std::optional<int> contour_marker(std::string_view line) {
  constexpr std::string_view kMarker = "(CONTOUR ";
  const auto at = line.find(kMarker);
  if (at == std::string_view::npos) return std::nullopt;
  int n = -1;
  const char* begin = line.data() + at + kMarker.size();
  if (std::from_chars(begin, line.data() + line.size(), n).ec != std::errc()) return std::nullopt;
  return n;
}

bool has_axis_word(const std::string& words) {
  return words.find_first_of("XYZAC") != std::string::npos;
}

// The last line of [start, end) that moves with the jet M-code on (M3/M4 … M5), not a dwell.
std::optional<std::size_t> last_cut_by_m_codes(const std::vector<std::string>& program, std::size_t start,
                                               std::size_t end) {
  bool jet = false;
  std::optional<std::size_t> last;
  for (std::size_t i = start; i < end; ++i) {
    const std::string words = words_of(program[i]);
    if (const auto m = word_value(words, 'M')) {
      if (*m == 3 || *m == 4) jet = true;
      if (*m == 5) jet = false;
    }
    if (jet && has_axis_word(words) && !has_g(words, 4)) last = i;
  }
  return last;
}

}  // namespace

bool takes_planner_block(std::string_view line) {
  const std::string words = words_of(line);
  return has_axis_word(words) || has_g(words, 4);
}

std::size_t first_unfinished_line(const std::vector<std::string>& program, std::size_t accepted_count,
                                  std::size_t queued_blocks) {
  std::size_t first = std::min(accepted_count, program.size());
  for (std::size_t remaining = queued_blocks; remaining > 0 && first > 0;) {
    --first;
    if (takes_planner_block(program[first])) --remaining;
  }
  // Lines between a finished block and the first queued one (comments, modal lines) were
  // already taken by the controller; the first unfinished line is the queued block itself.
  if (queued_blocks == 0) return first;
  while (first < accepted_count && !takes_planner_block(program[first])) ++first;
  return first;
}

ProgramMap program_map_from_markers(const std::vector<std::string>& program) {
  ProgramMap map;
  map.setup_end = program.size();
  for (std::size_t i = 0; i < program.size(); ++i)
    if (const auto n = contour_marker(program[i])) {
      map.setup_end = std::min(map.setup_end, i);
      map.contours.push_back({*n, i, std::nullopt});
    }
  for (std::size_t c = 0; c < map.contours.size(); ++c) {
    const std::size_t end = c + 1 < map.contours.size() ? map.contours[c + 1].start_index : program.size();
    map.contours[c].last_cut_index = last_cut_by_m_codes(program, map.contours[c].start_index, end);
  }
  return map;
}

std::expected<ResumePlan, LinkError> plan_resume(const std::vector<std::string>& program, const ProgramMap& map,
                                                 std::size_t first_unfinished, double safe_z_mm) {
  if (first_unfinished > program.size())
    return std::unexpected(LinkError{LinkErrorCode::bad_request,
                                     fmt::format("resume at line {} of a {}-line program", first_unfinished + 1,
                                                 program.size())});
  if (map.contours.empty() && first_unfinished > 0)
    return std::unexpected(LinkError{LinkErrorCode::bad_request,
                                     "the program has no contours marked (no map from its plan, no (CONTOUR n …) "
                                     "markers): no safe point to resume from"});
  ResumePlan plan;
  std::size_t at = map.contours.size();  // the contour the first unfinished line is in
  for (std::size_t c = 0; c < map.contours.size(); ++c)
    if (map.contours[c].start_index <= first_unfinished) at = c;
  if (at == map.contours.size()) return plan;  // nothing of a contour ran yet: start over from the top
  plan.restart_index = map.contours[at].start_index;
  plan.contour = map.contours[at].contour;
  // A contour whose cutting moves have all run is finished even if its jet-off and retract have
  // not: restarting it would cut it twice (the fault campaign: a pressure drop on contour 27's
  // last line). The resume goes on at the next contour, or after the cut if it was the last.
  const auto& last_cut = map.contours[at].last_cut_index;
  if (first_unfinished > plan.restart_index && (!last_cut || *last_cut < first_unfinished)) {
    if (at + 1 < map.contours.size()) {
      plan.restart_index = map.contours[at + 1].start_index;
      plan.contour = map.contours[at + 1].contour;
    } else {
      plan.restart_index = first_unfinished;
    }
  }
  // The set-up the program makes before its first contour, minus motion: units, distance and
  // feed modes. Then inverse time off (the contour may have ended in G93) and a retract.
  for (std::size_t i = 0; i < std::min(map.setup_end, program.size()); ++i) {
    const std::string words = words_of(program[i]);
    if (!words.empty() && !has_axis_word(words) && words.front() != '%' && words.front() != 'O')
      plan.preamble.push_back(program[i]);
  }
  plan.preamble.push_back("G94");
  double z = safe_z_mm;
  for (std::size_t i = plan.restart_index + 1; i < program.size() && i < plan.restart_index + 4; ++i) {
    const std::string words = words_of(program[i]);
    if (has_g(words, 0)) {
      if (auto v = word_value(words, 'Z')) z = *v;
      break;
    }
  }
  plan.preamble.push_back(fmt::format("G0Z{}", z));
  return plan;
}

}  // namespace lamina::drivers
