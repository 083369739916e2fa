// Number formatting and comment sanitising of G-code words.
#include "post/gcode_words.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>

namespace lamina::post_detail {

std::string format_number(double value, int decimals, bool keep_point) {
  decimals = std::clamp(decimals, 0, 9);
  std::string s = fmt::format("{:.{}f}", value, decimals);
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  if (keep_point && s.find('.') == std::string::npos) s += '.';
  return s;
}

std::string format_significant(double value, int significant, int max_decimals, bool keep_point) {
  const double magnitude = std::abs(value);
  int decimals = max_decimals;
  if (magnitude > 0.0 && std::isfinite(magnitude)) {
    const int leading = static_cast<int>(std::floor(std::log10(magnitude))) + 1;  // digits before the point
    decimals = std::clamp(significant - leading, 0, max_decimals);
    // Fewer decimals still, where the value written stays within the relative error that
    // `significant` digits promise at worst (half a unit of the last digit of 10^(significant−1)):
    // 898.9 is written 899 (1e-4 off), 150.4 stays as it is.
    const double promised = 0.5 * std::pow(10.0, 1 - significant) * magnitude;
    while (decimals > 0) {
      const double scale = std::pow(10.0, decimals - 1);
      if (std::abs(std::round(value * scale) / scale - value) > promised) break;
      --decimals;
    }
  }
  return format_number(value, decimals, keep_point);
}

std::string comment_text(std::string_view text, std::size_t max_chars) {
  std::string out;
  for (char raw : text) {
    const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(raw)));
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '-' || c == '+' ||
                    c == '_' || c == '/' || c == ':' || c == '=' || c == '#';
    const char keep = ok ? c : ' ';
    if (keep == ' ' && (out.empty() || out.back() == ' ')) continue;
    out += keep;
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  if (out.size() > max_chars) out.resize(max_chars);
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

}  // namespace lamina::post_detail
