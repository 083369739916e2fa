// The sheet SVG's stylesheet and legend box (title, sheet, thickness, material, size, parts,
// utilisation, time, and the colour key drawn with the same classes as the drawing).
#include "svg/sheet_svg_internal.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <iterator>
#include <string_view>

namespace lamina::svg_detail {
namespace {

enum class Sample { line, dot, ring, mark };

struct KeyEntry {
  const char* cls;
  const char* label;
  Sample sample;
};

constexpr KeyEntry kKey[] = {
    {"sheet", "Sheet outline", Sample::line},
    {"top-outer", "Top contour, outer", Sample::line},
    {"top-hole", "Top contour, hole", Sample::line},
    {"bottom-outer", "Bottom contour, outer", Sample::line},
    {"bottom-hole", "Bottom contour, hole", Sample::line},
    {"footprint", "Footprint (nest clearance)", Sample::line},
    {"lead-in", "Lead-in", Sample::line},
    {"lead-out", "Lead-out", Sample::line},
    {"pierce", "Pierce point", Sample::dot},
    {"microjoint", "Microjoint", Sample::mark},
    {"dowel", "Dowel hole", Sample::ring},
    {"rapid", "Rapid", Sample::line},
    {"tilt-limited", "Held at the tilt limit (jet compensation)", Sample::line},
};

// A key row the sheet has nothing for is left out: rapids when not drawn, tilt-limited cuts
// when there are none.
bool shown(const KeyEntry& k, const LegendInfo& info) {
  const std::string_view cls = k.cls;
  return (cls != "rapid" || info.rapids) && (cls != "tilt-limited" || info.tilt_limited);
}

// Characters, not bytes: a rough width estimate for UTF-8 text.
std::size_t glyphs(std::string_view s) {
  return static_cast<std::size_t>(std::count_if(s.begin(), s.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

}  // namespace

std::string style_sheet(const Scale& s) {
  const double l = s.line;
  std::string css;
  auto out = std::back_inserter(css);
  fmt::format_to(out, "<style type=\"text/css\">\n");
  fmt::format_to(out, ".sheet{{fill:none;stroke:#000;stroke-width:{}}}\n", num(2 * l));
  fmt::format_to(out, ".top-outer,.top-hole,.bottom-outer,.bottom-hole,.lead-in,.lead-out,.dowel"
                      "{{fill:none;stroke-width:{};stroke-linejoin:round;stroke-linecap:round}}\n", num(l));
  fmt::format_to(out, ".top-outer{{stroke:#d62728}}.top-hole{{stroke:#ff7f0e}}"
                      ".bottom-outer{{stroke:#1f4e9c}}.bottom-hole{{stroke:#17a2b8}}\n");
  fmt::format_to(out, ".footprint{{fill:none;stroke:#808080;stroke-width:{};stroke-dasharray:{},{}}}\n",
                 num(l / 2), num(4 * l), num(2 * l));
  fmt::format_to(out, ".lead-in{{stroke:#2ca02c}}.lead-out{{stroke:#8c564b}}.dowel{{stroke:#9467bd}}\n");
  fmt::format_to(out, ".pierce{{fill:#2ca02c;stroke:#000;stroke-width:{}}}\n", num(l / 3));
  fmt::format_to(out, ".microjoint{{fill:none;stroke:#e377c2;stroke-width:{};stroke-linecap:round}}\n", num(3 * l));
  fmt::format_to(out, ".rapid{{fill:none;stroke:#7f7f7f;stroke-opacity:0.6;stroke-width:{};stroke-dasharray:{},{}}}\n",
                 num(l / 2), num(l), num(2 * l));
  fmt::format_to(out, ".tilt-limited{{fill:none;stroke:#ffbf00;stroke-opacity:0.7;stroke-width:{};stroke-linecap:round}}\n",
                 num(4 * l));
  fmt::format_to(out, ".label{{font-family:sans-serif;text-anchor:middle;fill:#000}}\n");
  fmt::format_to(out, ".legend-box{{fill:#fff;stroke:#000;stroke-width:{}}}\n", num(l / 2));
  fmt::format_to(out, ".legend{{font-family:sans-serif;font-size:{}px;fill:#000}}.legend-title{{font-weight:bold}}\n",
                 num(s.font));
  fmt::format_to(out, "</style>\n");
  return css;
}

Fragment legend(const LegendInfo& info, const Scale& s, double x, double y) {
  const double f = s.font, pad = 0.6 * f, row = 1.4 * f, sample_w = 2.5 * f;
  std::vector<std::string> facts;
  facts.push_back(fmt::format("Sheet {}", info.sheet));
  facts.push_back(fmt::format("Thickness: {} mm", num(info.thickness_mm)));
  facts.push_back(fmt::format("Material: {}", info.material.empty() ? std::string("(not given)") : info.material));
  facts.push_back(fmt::format("Size: {} x {} mm", num(info.length_mm), num(info.width_mm)));
  facts.push_back(fmt::format("Parts: {}", info.parts));
  facts.push_back(fmt::format("Utilisation: {:.1f} %", 100.0 * info.utilisation));
  facts.push_back(fmt::format("Estimated time: {} (h:mm:ss)", hms(info.time_s)));

  std::size_t widest = glyphs(info.title);
  for (const auto& t : facts) widest = std::max(widest, glyphs(t));
  for (const auto& k : kKey)
    if (shown(k, info)) widest = std::max(widest, glyphs(k.label) + 5);
  const double w = std::max(16.0 * f, 0.6 * f * static_cast<double>(widest) + 2 * pad);
  const int key_rows = static_cast<int>(std::count_if(std::begin(kKey), std::end(kKey), [&](const KeyEntry& k) { return shown(k, info); }));
  const int rows = (info.title.empty() ? 0 : 1) + static_cast<int>(facts.size()) + 1 + key_rows;
  const double h = rows * row + 2 * pad;

  std::string svg;
  auto out = std::back_inserter(svg);
  fmt::format_to(out, "<g class=\"legend\">\n<rect class=\"legend-box\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/>\n",
                 num(x), num(y), num(w), num(h));
  double baseline = y + pad + f;
  const double tx = x + pad;
  if (!info.title.empty()) {
    fmt::format_to(out, "<text class=\"legend-title\" x=\"{}\" y=\"{}\">{}</text>\n", num(tx), num(baseline), xml_escape(info.title));
    baseline += row;
  }
  for (const auto& t : facts) {
    fmt::format_to(out, "<text x=\"{}\" y=\"{}\">{}</text>\n", num(tx), num(baseline), xml_escape(t));
    baseline += row;
  }
  baseline += row;  // a blank row before the key
  for (const auto& k : kKey) {
    if (!shown(k, info)) continue;
    const double cy = baseline - 0.35 * f;
    switch (k.sample) {
      case Sample::line:
        fmt::format_to(out, "<polyline class=\"{}\" points=\"{},{} {},{}\"/>\n", k.cls, num(tx), num(cy), num(tx + sample_w), num(cy));
        break;
      case Sample::mark:
        fmt::format_to(out, "<line class=\"{}\" x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\"/>\n", k.cls, num(tx + 0.8 * f), num(cy),
                       num(tx + sample_w - 0.8 * f), num(cy));
        break;
      case Sample::dot:
        fmt::format_to(out, "<circle class=\"{}\" cx=\"{}\" cy=\"{}\" r=\"{}\"/>\n", k.cls, num(tx + sample_w / 2), num(cy), num(0.3 * f));
        break;
      case Sample::ring:
        fmt::format_to(out, "<circle class=\"{}\" cx=\"{}\" cy=\"{}\" r=\"{}\"/>\n", k.cls, num(tx + sample_w / 2), num(cy), num(0.45 * f));
        break;
    }
    fmt::format_to(out, "<text x=\"{}\" y=\"{}\">{}</text>\n", num(tx + sample_w + 0.7 * f), num(baseline), xml_escape(k.label));
    baseline += row;
  }
  svg += "</g>\n";
  return Fragment{std::move(svg), w, h};
}

}  // namespace lamina::svg_detail
