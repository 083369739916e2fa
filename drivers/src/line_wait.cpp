// Which lines a Grbl-family controller answers only after the motion before them: grblHAL's
// gc_execute_block calls protocol_buffer_synchronize() (directly, or through spindle_sync /
// coolant_sync / mc_dwell / the settings write of a stored offset) before it acts on them.
#include "lamina/drivers/line_wait.hpp"

#include <cctype>
#include <charconv>
#include <optional>

namespace lamina::drivers {
namespace {

struct Word {
  char letter = 0;
  double value = 0;
};

// One word at `text[at]` (after comments and spaces were skipped); advances `at`.
std::optional<Word> read_word(std::string_view text, std::size_t& at) {
  Word w;
  w.letter = static_cast<char>(std::toupper(static_cast<unsigned char>(text[at++])));
  while (at < text.size() && text[at] == ' ') ++at;
  const std::size_t begin = at;
  while (at < text.size() && (std::isdigit(static_cast<unsigned char>(text[at])) || text[at] == '.' ||
                              text[at] == '-' || text[at] == '+'))
    ++at;
  std::string_view number = text.substr(begin, at - begin);
  if (!number.empty() && number.front() == '+') number.remove_prefix(1);
  const auto [end, ec] = std::from_chars(number.data(), number.data() + number.size(), w.value);
  if (ec != std::errc() || end != number.data() + number.size()) return std::nullopt;
  return w;
}

bool near(double v, double code) { return v > code - 0.05 && v < code + 0.05; }

}  // namespace

LineWait grbl_line_wait(std::string_view line) {
  LineWait out;
  bool dwell = false, offset_store = false;
  std::optional<double> p_word, l_word;
  for (std::size_t at = 0; at < line.size();) {
    const char c = line[at];
    if (c == '(') {
      const auto close = line.find(')', at);
      at = close == std::string_view::npos ? line.size() : close + 1;
      continue;
    }
    if (c == ';') break;
    if (!std::isalpha(static_cast<unsigned char>(c))) {
      ++at;
      continue;
    }
    const auto w = read_word(line, at);
    if (!w) return {};
    switch (w->letter) {
      case 'G':
        if (near(w->value, 4)) dwell = true;
        if (near(w->value, 10)) offset_store = true;  // with L2 / L20, checked below
        if (near(w->value, 28.1) || near(w->value, 30.1)) out.syncs = true;
        break;
      case 'M': {
        const double m = w->value;
        for (double code : {0.0, 1.0, 2.0, 30.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 66.0})
          if (near(m, code)) out.syncs = true;
        break;
      }
      case 'S': out.syncs = true; break;  // a speed change syncs as a spindle change does
      case 'P': p_word = w->value; break;
      case 'L': l_word = w->value; break;
      default: break;
    }
  }
  if (offset_store && l_word && (near(*l_word, 2) || near(*l_word, 20))) out.syncs = true;
  if (dwell) {
    out.syncs = true;
    out.dwell_s = p_word && *p_word > 0 ? *p_word : 0;
  }
  return out;
}

}  // namespace lamina::drivers
