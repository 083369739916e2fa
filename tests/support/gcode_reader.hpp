#pragma once
// Test oracle: reads the G-code the posts write (grblHAL, LinuxCNC, Fanuc subsets) into the
// machine state after every motion line. Written from the controllers' rules, not from the post's
// code: strict on purpose — unknown words, spaces, lower case, a G1 without a defined F, a G0 in
// G93, a Fanuc number without its decimal point are errors.
#include <cmath>
#include <cstddef>
#include <expected>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace gcode_reader {

struct Options {
  bool fanuc = false;          // % framing, O number, G4 P in ms, decimal point required on reals
  std::string jet_on = "M3";   // whole-line M-code text (spaces ignored) that opens the jet
  std::string jet_off = "M5";
};

struct MotionLine {
  std::size_t line = 0;       // 1-based
  int motion = 0;             // 0: G0, 1: G1
  bool inverse_time = false;  // G93
  bool tcp = false;           // G43.4 active
  double x = 0, y = 0, z = 0, a_deg = 0, c_deg = 0;
  double f = 0;               // the F in force (1/min in G93, mm/min in G94)
  bool f_on_line = false;
  bool has_rotary = false;    // A or C on this line
  bool jet_on = false;
  double dwell_before_s = 0;  // dwells since the previous motion line
  std::string text;
};

struct Comment {
  std::size_t line = 0;
  std::string text;
};

struct Program {
  std::vector<MotionLine> motions;
  std::vector<Comment> comments;
  std::size_t lines = 0;
  std::size_t jet_on_count = 0, jet_off_count = 0;
  bool ended = false;  // M2 / M30 seen
  bool tcp_at_end = false;
  bool jet_at_end = false;
};

namespace detail {

inline std::string squeeze(std::string_view s) {
  std::string out;
  for (char c : s)
    if (c != ' ' && c != '\t') out += c;
  return out;
}

inline bool parse_number(std::string_view s, double& value, bool& has_point) {
  if (s.empty()) return false;
  std::size_t i = 0;
  if (s[i] == '+' || s[i] == '-') ++i;
  bool digits = false;
  has_point = false;
  for (; i < s.size(); ++i) {
    if (s[i] >= '0' && s[i] <= '9') {
      digits = true;
    } else if (s[i] == '.' && !has_point) {
      has_point = true;
    } else {
      return false;
    }
  }
  if (!digits) return false;
  value = std::stod(std::string(s));
  return true;
}

}  // namespace detail

inline std::expected<Program, std::string> read_gcode(std::string_view text, const Options& opt) {
  Program prog;
  bool inverse_time = false, tcp = false, jet = false;
  int motion = -1;
  double feed = 0;             // the F in force
  bool feed_defined = false;   // F defined for the next G1
  double pos[5] = {0, 0, 0, 0, 0};
  bool known[5] = {false, false, false, false, false};
  double dwell = 0;
  bool saw_percent_start = false, saw_percent_end = false;
  const std::string jet_on = detail::squeeze(opt.jet_on), jet_off = detail::squeeze(opt.jet_off);

  std::size_t line_no = 0;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t nl = text.find('\n', start);
    if (nl == std::string_view::npos) nl = text.size();
    const std::string_view raw = text.substr(start, nl - start);
    start = nl + 1;
    ++line_no;
    auto fail = [&](const std::string& why) {
      return std::unexpected(std::string("line ") + std::to_string(line_no) + " '" + std::string(raw) + "': " + why);
    };
    if (raw.empty()) return fail("empty line");
    if (raw.size() >= 70) return fail("line of 70 characters or more");
    if (saw_percent_end) return fail("text after the closing %");
    if (raw == "%") {
      if (!opt.fanuc) return fail("% outside fanuc");
      if (line_no == 1) {
        saw_percent_start = true;
      } else {
        if (!prog.ended) return fail("closing % before the program end");
        saw_percent_end = true;
      }
      continue;
    }
    if (opt.fanuc && !saw_percent_start) return fail("fanuc program must start with %");
    if (prog.ended) return fail("text after M2/M30");

    // Comments.
    std::string code;
    for (std::size_t i = 0; i < raw.size(); ++i) {
      const char c = raw[i];
      if (c == '(') {
        const std::size_t close = raw.find(')', i + 1);
        if (close == std::string_view::npos) return fail("unclosed comment");
        const std::string_view body = raw.substr(i + 1, close - i - 1);
        if (body.find('(') != std::string_view::npos) return fail("nested comment");
        prog.comments.push_back({line_no, std::string(body)});
        i = close;
      } else if (c == ')') {
        return fail("stray )");
      } else if (c == ' ' || c == '\t') {
        return fail("space outside a comment");
      } else if (c == ';') {
        return fail("; comment");
      } else if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) {
        return fail("non-printable character");
      } else if (c >= 'a' && c <= 'z') {
        return fail("lower case");
      } else {
        code += c;
      }
    }
    if (code.empty()) continue;
    if (code == jet_on) {
      jet = true;
      ++prog.jet_on_count;
      continue;
    }
    if (code == jet_off) {
      jet = false;
      ++prog.jet_off_count;
      continue;
    }

    // Words.
    struct Word {
      char letter;
      double value;
      bool point;
      std::string digits;
    };
    std::vector<Word> words;
    for (std::size_t i = 0; i < code.size();) {
      const char letter = code[i];
      if (letter < 'A' || letter > 'Z') return fail(std::string("expected a letter at '") + letter + "'");
      std::size_t j = i + 1;
      while (j < code.size() && !(code[j] >= 'A' && code[j] <= 'Z')) ++j;
      Word w{letter, 0.0, false, code.substr(i + 1, j - i - 1)};
      if (!detail::parse_number(w.digits, w.value, w.point)) return fail(std::string("bad number after ") + letter);
      words.push_back(w);
      i = j;
    }

    bool is_dwell = false, end_program = false, axis_words = false, f_on_line = false, rotary = false;
    std::optional<double> p_word;
    int new_motion = motion;
    bool motion_word = false;
    bool mode_switch_to_94 = false;
    double next[5];
    for (int k = 0; k < 5; ++k) next[k] = pos[k];
    for (const Word& w : words) {
      const bool real_address = w.letter == 'X' || w.letter == 'Y' || w.letter == 'Z' || w.letter == 'A' ||
                                w.letter == 'C' || w.letter == 'F';
      if (opt.fanuc && real_address && !w.point) return fail(std::string("fanuc ") + w.letter + " without decimal point");
      switch (w.letter) {
        case 'G': {
          const std::string& g = w.digits;
          if (g == "0" || g == "1") {
            if (motion_word) return fail("two motion words");
            motion_word = true;
            new_motion = g == "0" ? 0 : 1;
          } else if (g == "4") {
            is_dwell = true;
          } else if (g == "93") {
            inverse_time = true;
          } else if (g == "94") {
            if (inverse_time) mode_switch_to_94 = true;
            inverse_time = false;
          } else if (g == "43.4") {
            if (!opt.fanuc) return fail("G43.4 outside fanuc");
            tcp = true;
          } else if (g == "49") {
            tcp = false;
          } else if (g == "17" || g == "21" || g == "90" || g == "40") {
            // plane, mm, absolute, no cutter compensation
          } else {
            return fail("unknown G" + g);
          }
          break;
        }
        case 'M':
          if (w.digits == "2" || w.digits == "30") {
            end_program = true;
          } else {
            return fail("unknown M" + w.digits);
          }
          break;
        case 'O':
          if (!opt.fanuc || line_no != 2) return fail("O word outside the fanuc header");
          break;
        case 'H':
          if (!tcp) return fail("H without G43.4");
          break;
        case 'P':
          p_word = w.value;
          if (opt.fanuc && w.point) return fail("fanuc G4 P takes milliseconds, no decimal point");
          break;
        case 'F':
          feed = w.value;
          feed_defined = true;
          f_on_line = true;
          break;
        case 'X': next[0] = w.value; axis_words = true; known[0] = true; break;
        case 'Y': next[1] = w.value; axis_words = true; known[1] = true; break;
        case 'Z': next[2] = w.value; axis_words = true; known[2] = true; break;
        case 'A': next[3] = w.value; axis_words = true; rotary = true; known[3] = true; break;
        case 'C': next[4] = w.value; axis_words = true; rotary = true; known[4] = true; break;
        default: return fail(std::string("unknown word ") + w.letter);
      }
    }
    if (mode_switch_to_94 && !f_on_line) feed_defined = false;
    if (is_dwell) {
      if (!p_word || axis_words || motion_word) return fail("G4 needs P alone");
      dwell += opt.fanuc ? *p_word / 1000.0 : *p_word;
      continue;
    }
    if (p_word) return fail("P without G4");
    if (end_program) {
      prog.ended = true;
      continue;
    }
    motion = new_motion;
    if (!axis_words) continue;
    if (motion < 0) return fail("axis words without G0/G1");
    if (motion == 0 && inverse_time) return fail("G0 in G93 (Grbl then wants an F)");
    if (motion == 1) {
      if (inverse_time && !f_on_line) return fail("G1 in G93 without F");
      if (!feed_defined) return fail("G1 without a defined F");
    }
    for (int k = 0; k < 5; ++k) pos[k] = next[k];
    MotionLine m;
    m.line = line_no;
    m.motion = motion;
    m.inverse_time = inverse_time;
    m.tcp = tcp;
    m.x = pos[0], m.y = pos[1], m.z = pos[2], m.a_deg = pos[3], m.c_deg = pos[4];
    m.f = feed_defined ? feed : 0.0;
    m.f_on_line = f_on_line;
    m.has_rotary = rotary;
    m.jet_on = jet;
    m.dwell_before_s = dwell;
    m.text = std::string(raw);
    dwell = 0;
    if (prog.motions.empty() && !(known[0] && known[1] && known[2] && known[3] && known[4]))
      return fail("first motion line must give X Y Z A C");
    prog.motions.push_back(m);
  }
  prog.lines = line_no;
  if (!prog.ended) return std::unexpected(std::string("no M2/M30"));
  if (opt.fanuc && !saw_percent_end) return std::unexpected(std::string("fanuc program must end with %"));
  prog.tcp_at_end = tcp;
  prog.jet_at_end = jet;
  return prog;
}

}  // namespace gcode_reader
