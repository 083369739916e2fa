#pragma once
// Private to the sheet SVG (sheet_svg*.cpp): number and text formatting, the drawing's scale
// (line widths and font size follow the sheet's size), the stylesheet and the legend.
#include <Eigen/Core>

#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace lamina::svg_detail {

// At most 3 decimals, no trailing zeros, never "-0"; non-finite values print as 0.
std::string num(double v);
// Text or attribute value for XML: & < > " ' escaped, control characters XML 1.0 forbids dropped.
std::string xml_escape(std::string_view text);
// "x,y x,y …" for polyline/polygon points.
std::string points(std::span<const Eigen::Vector2d> pts);

struct Scale {
  double line = 0.3;  // contour stroke width, mm
  double font = 4.0;  // legend font size, mm
};
Scale scale_for(double length_mm, double width_mm);

// The <style> element: one class per kind of mark (sheet, top-outer, top-hole, bottom-outer,
// bottom-hole, footprint, lead-in, lead-out, pierce, microjoint, dowel, rapid, label, legend…).
std::string style_sheet(const Scale& s);

struct LegendInfo {
  std::string title;
  int sheet = 0;
  double thickness_mm = 0.0;
  std::string material;
  double length_mm = 0.0, width_mm = 0.0;
  int parts = 0;
  double utilisation = 0.0;  // fraction
  double time_s = 0.0;
  bool rapids = true;
  bool tilt_limited = false;  // some cut's jet compensation was held at the tilt limit
};

struct Fragment {
  std::string svg;
  double width = 0.0, height = 0.0;
};
// The legend box with its top-left corner at (x, y) in SVG (y-down) coordinates.
Fragment legend(const LegendInfo& info, const Scale& s, double x, double y);

// "1:02:05" (h:mm:ss), rounded to the second.
std::string hms(double seconds);

}  // namespace lamina::svg_detail
