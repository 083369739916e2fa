// Framing and dialect words of the three controllers (docs/posts.md cites what was checked):
//   fanuc     %, O<number>(<title>), G21G90G94G17, [G43.4H1 … G49], M30, %; G4 P in milliseconds.
//   linuxcnc  (<title>), G21G90G94G17G40G49, M2; G4 P in seconds. RTCP is the machine's TCP
//             kinematics (switchable kins type 1): the program simply carries the tip.
//   grblhal   (<title>), G21G90G94G17, M2; G4 P in seconds. No RTCP: rtcp is an error.
#include "post/gcode_words.hpp"
#include "post/post_internal.hpp"

#include <fmt/format.h>

#include <array>
#include <cctype>
#include <cmath>
#include <string_view>

namespace lamina {

const ChoiceTable<PostDialect, PostDialectTraits>& post_dialects() {
  using Row = Choice<PostDialect, PostDialectTraits>;
  static constexpr Row rows[] = {
      {PostDialect::grblhal, "grblhal", "grblHAL: pivot coordinates and inverse-time feed (G93); no RTCP", {.controller = "grblHAL", .rtcp = false}},
      {PostDialect::fanuc, "fanuc", "Fanuc: O-number, G43.4 tool-centre point when the head does RTCP", {.controller = "Fanuc", .rtcp = true}},
      {PostDialect::linuxcnc, "linuxcnc", "LinuxCNC: TCP kinematics (switchable kins) or pivot coordinates",
       {.controller = "LinuxCNC", .rtcp = true}}};
  static constexpr ChoiceTable<PostDialect, PostDialectTraits> table{"post dialect", rows};
  return table;
}

const char* post_dialect_name(PostDialect dialect) { return post_dialects().name_of(dialect); }

namespace post_detail {

namespace {

// LinuxCNC acts on comments that start with these words (MSG, DEBUG, PRINT, LOG…, PROBEOPEN…):
// a title that starts with one is prefixed so it stays a plain comment.
bool active_comment_word(std::string_view text) {
  constexpr std::array<std::string_view, 8> words{"MSG", "DEBUG", "PRINT", "LOG", "PROBE", "PY", "ABORT", "ENDSUB"};
  for (std::string_view w : words)
    if (text.substr(0, w.size()) == w) return true;
  return false;
}

std::string title_comment(const PostParams& params, std::size_t room) {
  std::string t = comment_text(params.title, room);
  if (active_comment_word(t)) t = comment_text("JOB " + t, room);
  return t;
}

bool valid_m_codes(const std::string& codes) {
  const std::string line = m_code_line(codes);
  if (line.empty() || line.size() > max_line_chars) return false;
  for (char c : line)
    if (!((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '-')) return false;
  return line.front() == 'M';
}

}  // namespace

bool keeps_decimal_point(PostDialect dialect) { return dialect == PostDialect::fanuc; }

std::string m_code_line(const std::string& codes) {
  std::string out;
  for (char c : codes)
    if (c != ' ' && c != '\t') out += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

std::expected<void, Error> check_post_setup(const HeadKinematics& head, const PostParams& params) {
  const auto* dialect = post_dialects().find(params.dialect);
  if (!dialect) return std::unexpected(Error{ErrorCode::invalid_argument, "unknown post dialect"});
  if (head.rtcp && !dialect->traits.rtcp)
    return std::unexpected(Error{ErrorCode::unsupported,
                                 fmt::format("{} has no RTCP (G43.4); post with head.rtcp = false (pivot coordinates, G93)",
                                             dialect->name)});
  if (params.linear_decimals < 0 || params.linear_decimals > 6 || params.angular_decimals < 0 ||
      params.angular_decimals > 6 || params.feed_decimals < 0 || params.feed_decimals > 4)
    return std::unexpected(Error{ErrorCode::invalid_argument,
                                 "decimals out of range (linear and angular 0…6, feed 0…4)"});
  if (!valid_m_codes(params.jet_on) || !valid_m_codes(params.jet_off) ||
      m_code_line(params.jet_on) == m_code_line(params.jet_off))
    return std::unexpected(Error{ErrorCode::invalid_argument,
                                 fmt::format("jet M-codes '{}' / '{}' must be distinct M words (letters, digits)",
                                             params.jet_on, params.jet_off)});
  if (params.dialect == PostDialect::fanuc && (params.program_number < 1 || params.program_number > 9999))
    return std::unexpected(
        Error{ErrorCode::invalid_argument, fmt::format("fanuc program number {} not in 1…9999", params.program_number)});
  if (!(head.pivot_mm >= 0.0) || !std::isfinite(head.pivot_mm) || std::abs(head.a_sign) != 1 ||
      std::abs(head.c_sign) != 1 || !(head.a_min_rad <= head.a_max_rad) || !(head.c_min_rad < head.c_max_rad) ||
      !std::isfinite(head.c_offset_rad) || !(head.hold_c_below_rad >= 0.0))
    return std::unexpected(Error{ErrorCode::invalid_argument,
                                 "head kinematics: pivot ≥ 0, signs ±1, A and C limits ordered required"});
  return {};
}

std::vector<std::string> program_start(const HeadKinematics& head, const PostParams& params) {
  std::vector<std::string> lines;
  switch (params.dialect) {
    case PostDialect::fanuc: {
      lines.push_back("%");
      std::string o = fmt::format("O{:04d}", params.program_number);
      const std::string t = title_comment(params, max_line_chars - o.size() - 2);
      if (!t.empty()) o += "(" + t + ")";
      lines.push_back(o);
      lines.push_back("G21G90G94G17");
      if (head.rtcp) lines.push_back("G43.4H1");
      break;
    }
    case PostDialect::linuxcnc: {
      const std::string t = title_comment(params, max_line_chars - 2);
      if (!t.empty()) lines.push_back("(" + t + ")");
      lines.push_back("G21G90G94G17G40G49");
      if (head.rtcp) lines.push_back("(TIP COORDINATES: NEEDS TCP KINEMATICS)");
      break;
    }
    case PostDialect::grblhal: {
      const std::string t = title_comment(params, max_line_chars - 2);
      if (!t.empty()) lines.push_back("(" + t + ")");
      lines.push_back("G21G90G94G17");
      break;
    }
  }
  return lines;
}

std::vector<std::string> program_end(const HeadKinematics& head, const PostParams& params) {
  switch (params.dialect) {
    case PostDialect::fanuc:
      if (head.rtcp) return {"G49", "M30", "%"};
      return {"M30", "%"};
    case PostDialect::linuxcnc: return {"M2"};
    case PostDialect::grblhal: return {"M2"};
  }
  return {};
}

std::string dwell_line(double seconds, const PostParams& params) {
  if (params.dialect == PostDialect::fanuc)  // P: milliseconds, no decimal point
    return fmt::format("G4P{}", static_cast<long long>(std::llround(seconds * 1000.0)));
  return "G4P" + format_number(seconds, 3, false);  // grblHAL, LinuxCNC: P in seconds
}

}  // namespace post_detail
}  // namespace lamina
