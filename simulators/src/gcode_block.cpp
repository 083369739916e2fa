// The simulator's G-code line parser (grblHAL semantics, written from its documented behaviour).
//
// Choices where Grbl leaves room or the simulator is stricter (documented in gcode_block.hpp):
// - Spaces and tabs are removed before words are read (Grbl does the same), so `X 1 0` is X10.
// - An unterminated `(` comment is expected_command_letter: the rest of the line cannot be
//   trusted to be a comment, and a real controller would wait for the `)`.
// - A number is the longest run of `+-.0-9` after the letter; anything but [sign]digits[.digits]
//   (or .digits) is bad_number_format (`X1.2.3`, `X-`, `Xabc`, `X--1`).
// - G17 G40 G49 G54 G80 are accepted as no-ops (our posts and real programs carry them; this
//   machine has one plane, no cutter or length compensation, one work offset, no canned cycles).
// - G4 in a block with axis words is modal_group_violation: one motion per block here.
// - P without G4 is unused_words; arc words are checked by the executor (it knows the modal
//   motion). T and S are accepted and ignored (a waterjet has no tool changer or spindle speed).
// - B, D, E, H, L, Q, U, V, W are read as value words, as grblHAL's gc_execute_block keeps a
//   letter without an axis as a macro parameter; nothing here uses them, so the executor
//   answers unused_words (grblHAL's final "[Unused words]" check) once its other checks pass.
// - G4, G28 and G53 share grblHAL's non-modal group 0 (one per block).
// - Axis and arc words are kept as written: G20/G21 may come from an earlier line, so only the
//   executor can convert them to mm.
#include "gcode_block.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace lamina::sim {
namespace {

constexpr double kMaxLineNumber = 10000000;  // Grbl's MAX_LINE_NUMBER

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }
bool is_ascii_letter(char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'); }
char upper(char c) { return (c >= 'a' && c <= 'z') ? static_cast<char>(c - 'a' + 'A') : c; }
bool is_number_char(char c) { return (c >= '0' && c <= '9') || c == '.' || c == '+' || c == '-'; }

// Remove comments and spaces. Returns false for an unterminated `(`.
bool strip(std::string_view line, std::string& out) {
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == ';') break;
    if (c == '(') {
      const auto close = line.find(')', i + 1);
      if (close == std::string_view::npos) return false;
      i = close;
      continue;
    }
    if (!is_space(c)) out.push_back(c);
  }
  return true;
}

// [sign] digits [. digits] | [sign] . digits | [sign] digits .
bool parse_number(std::string_view text, double& value) {
  std::size_t i = 0;
  bool negative = false;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) negative = text[i++] == '-';
  double v = 0;
  int digits = 0;
  for (; i < text.size() && text[i] >= '0' && text[i] <= '9'; ++i, ++digits) v = v * 10 + (text[i] - '0');
  if (i < text.size() && text[i] == '.') {
    ++i;
    double scale = 0.1;
    for (; i < text.size() && text[i] >= '0' && text[i] <= '9'; ++i, ++digits, scale *= 0.1)
      v += (text[i] - '0') * scale;
  }
  if (digits == 0 || i != text.size()) return false;
  value = negative ? -v : v;
  return true;
}

bool is_integer(double v) { return std::abs(v - std::round(v)) < 1e-9; }

int axis_index(char letter) {
  for (int i = 0; i < kAxisCount; ++i)
    if (kAxisLetters[i] == letter) return i;
  return -1;
}

bool contains(const std::vector<int>& codes, int code) {
  return std::find(codes.begin(), codes.end(), code) != codes.end();
}

// Words seen so far (word_repeated) and modal groups used (modal_group_violation).
struct Seen {
  std::string letters;
  bool motion_group = false, units_group = false, distance_group = false, feed_mode_group = false;
  bool plane_group = false, comp_group = false, length_group = false, offset_group = false;
  bool jet_group = false, stop_group = false, spindle_group = false, coolant_group = false;
  bool non_modal_group = false;  // G4 G28 G53
};

// Claim a modal group: false when the block already used it.
bool claim(bool& group) {
  if (group) return false;
  group = true;
  return true;
}

GrblStatus apply_g(int code, Block& b, Seen& seen) {
  if ((code == 4 || code == 28 || code == 53) && !claim(seen.non_modal_group))
    return GrblStatus::modal_group_violation;
  switch (code) {
    case 28:
      b.go_home = true;
      return GrblStatus::ok;
    case 53:
      b.machine_coords = true;
      return GrblStatus::ok;
    case 0: case 1: case 2: case 3: case 4: case 80: {
      // G80 (motion cancel) shares group 1 with G0-G3; G4 is non-modal but a block carries one
      // motion here, so it takes the same slot.
      if (!claim(seen.motion_group)) return GrblStatus::modal_group_violation;
      static constexpr MotionMode kModes[] = {MotionMode::rapid, MotionMode::linear, MotionMode::arc_cw,
                                              MotionMode::arc_ccw, MotionMode::dwell};
      if (code != 80) b.motion = kModes[code];
      return GrblStatus::ok;
    }
    case 20: case 21:
      if (!claim(seen.units_group)) return GrblStatus::modal_group_violation;
      b.set_inches = code == 20;
      return GrblStatus::ok;
    case 90: case 91:
      if (!claim(seen.distance_group)) return GrblStatus::modal_group_violation;
      b.set_relative = code == 91;
      return GrblStatus::ok;
    case 93: case 94:
      if (!claim(seen.feed_mode_group)) return GrblStatus::modal_group_violation;
      b.set_inverse_time = code == 93;
      return GrblStatus::ok;
    case 17: return claim(seen.plane_group) ? GrblStatus::ok : GrblStatus::modal_group_violation;
    case 40: return claim(seen.comp_group) ? GrblStatus::ok : GrblStatus::modal_group_violation;
    case 49: return claim(seen.length_group) ? GrblStatus::ok : GrblStatus::modal_group_violation;
    case 54: return claim(seen.offset_group) ? GrblStatus::ok : GrblStatus::modal_group_violation;
    default: return GrblStatus::unsupported_command;
  }
}

// M3/M4/M5 are grblHAL's spindle group, M7/M8/M9 its coolant group; the jet follows the
// configured jet codes (by default the spindle's M3/M4 on, M5 off). A configured jet code that
// is no spindle code (a Fanuc's M62/M63, say) only switches the jet.
GrblStatus apply_m(int code, Block& b, Seen& seen, const ParseParams& params) {
  if (code == 2 || code == 30) {
    if (!claim(seen.stop_group)) return GrblStatus::modal_group_violation;
    b.program_end = true;
    return GrblStatus::ok;
  }
  const bool on = contains(params.jet_on_mcodes, code), off = contains(params.jet_off_mcodes, code);
  if (on || off) b.jet_on = on;
  switch (code) {
    case 3: case 4: case 5:
      if (!claim(seen.spindle_group)) return GrblStatus::modal_group_violation;
      b.spindle = code == 3 ? SpindleCommand::cw : code == 4 ? SpindleCommand::ccw : SpindleCommand::off;
      return GrblStatus::ok;
    case 7: case 8: case 9:
      if (!claim(seen.coolant_group)) return GrblStatus::modal_group_violation;
      b.coolant = code == 7 ? CoolantCommand::mist : code == 8 ? CoolantCommand::flood : CoolantCommand::off;
      return GrblStatus::ok;
    default: break;
  }
  if (!on && !off) return GrblStatus::unsupported_command;
  if (!claim(seen.jet_group)) return GrblStatus::modal_group_violation;
  return GrblStatus::ok;
}

// A value word other than G and M (each letter once a block); axis words set `any_axis`.
GrblStatus apply_word(char letter, double value, Block& b, Seen& seen, bool& any_axis, const ParseParams& params) {
  if (seen.letters.find(letter) != std::string::npos) return GrblStatus::word_repeated;
  seen.letters.push_back(letter);
  switch (letter) {
    case 'N':
      if (value < 0 || value > kMaxLineNumber || !is_integer(value)) return GrblStatus::invalid_line_number;
      b.line_number = static_cast<std::int64_t>(std::llround(value));
      break;
    case 'F':
      if (value < 0) return GrblStatus::negative_value;
      b.feed_word = value;
      break;
    case 'P':
      if (value < 0) return GrblStatus::negative_value;
      b.dwell_s = value * params.dwell_p_unit_s;
      break;
    case 'I': b.i_mm = value; break;
    case 'J': b.j_mm = value; break;
    case 'K': b.k_mm = value; break;
    case 'R': b.r_mm = value; break;
    case 'T': case 'S': break;  // accepted, no meaning on a waterjet
    case 'B': case 'D': case 'E': case 'H': case 'L': case 'Q': case 'U': case 'V': case 'W':
      b.unused_word = true;
      break;
    case 'O':
      if (!is_integer(value) || value < 0) return GrblStatus::command_value_not_integer;
      break;
    default:
      b.axis_words[static_cast<std::size_t>(axis_index(letter))] = value;
      any_axis = true;
  }
  return GrblStatus::ok;
}

// The words of a stripped, non-empty line, one after the other.
GrblStatus parse_words(const std::string& text, Block& b, Seen& seen, bool& any_axis, const ParseParams& params) {
  for (std::size_t i = 0; i < text.size();) {
    const char raw = text[i];
    if (!is_ascii_letter(raw)) return GrblStatus::expected_command_letter;
    const char letter = upper(raw);
    std::size_t j = i + 1;
    while (j < text.size() && is_number_char(text[j])) ++j;
    const std::string_view number(text.data() + i + 1, j - i - 1);
    i = j;
    // Unknown letters are refused before their number is looked at: the letter is the problem.
    static constexpr std::string_view kKnown = "GMNFPXYZACIJKRTSBDEHLQUVW";
    const bool program_number = letter == 'O' && params.accept_program_number;
    if (kKnown.find(letter) == std::string_view::npos && !program_number) return GrblStatus::unsupported_command;
    double value = 0;
    if (!parse_number(number, value)) return GrblStatus::bad_number_format;
    GrblStatus s = GrblStatus::ok;
    if (letter == 'G' || letter == 'M') {
      if (!is_integer(value)) return GrblStatus::command_value_not_integer;
      const int code = static_cast<int>(std::lround(value));
      s = letter == 'G' ? apply_g(code, b, seen) : apply_m(code, b, seen, params);
    } else {
      s = apply_word(letter, value, b, seen, any_axis, params);
    }
    if (s != GrblStatus::ok) return s;
  }
  return GrblStatus::ok;
}

}  // namespace

ParseResult parse_block(std::string_view line, const ParseParams& params) {
  ParseResult r;
  r.block.source = std::string(line);
  auto fail = [&r](GrblStatus s) {
    r.status = s;
    return r;
  };
  if (line.size() > params.max_line_chars) return fail(GrblStatus::overflow);
  std::string text;
  if (!strip(line, text)) return fail(GrblStatus::expected_command_letter);
  if (text == "%") {
    r.block.percent = true;
    return r;
  }
  if (text.empty()) {
    r.block.comment_only = true;
    return r;
  }
  Block& b = r.block;
  Seen seen;
  bool any_axis = false;
  if (const GrblStatus s = parse_words(text, b, seen, any_axis, params); s != GrblStatus::ok) return fail(s);
  // grblHAL: G28 sets the axis command itself, a motion command beside it is a conflict.
  if (b.go_home && seen.motion_group) return fail(GrblStatus::axis_command_conflict);
  if (b.motion == MotionMode::dwell) {
    if (!b.dwell_s) return fail(GrblStatus::value_word_missing);
    if (any_axis) return fail(GrblStatus::modal_group_violation);
  } else if (b.dwell_s) {
    return fail(GrblStatus::unused_words);
  }
  return r;
}

}  // namespace lamina::sim
