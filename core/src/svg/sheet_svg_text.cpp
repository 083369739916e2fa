// Number and text formatting for the sheet SVG, and the drawing's scale.
#include "svg/sheet_svg_internal.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace lamina::svg_detail {

std::string num(double v) {
  if (!std::isfinite(v)) return "0";
  std::string s = fmt::format("{:.3f}", v);
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  if (s == "-0" || s.empty()) return "0";
  return s;
}

std::string xml_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default:
        // XML 1.0 allows no control characters but tab, newline and carriage return.
        if (c < 0x20 && ch != '\t' && ch != '\n' && ch != '\r') break;
        out += ch;
    }
  }
  return out;
}

std::string points(std::span<const Eigen::Vector2d> pts) {
  std::string out;
  for (const auto& p : pts) {
    if (!out.empty()) out += ' ';
    out += num(p.x());
    out += ',';
    out += num(p.y());
  }
  return out;
}

Scale scale_for(double length_mm, double width_mm) {
  const double size = std::max({length_mm, width_mm, 1.0});
  return Scale{std::clamp(size / 3000.0, 0.15, 1.0), std::clamp(size / 80.0, 3.0, 40.0)};
}

std::string hms(double seconds) {
  const long total = std::isfinite(seconds) && seconds > 0.0 ? std::lround(seconds) : 0;
  return fmt::format("{}:{:02}:{:02}", total / 3600, (total / 60) % 60, total % 60);
}

}  // namespace lamina::svg_detail
