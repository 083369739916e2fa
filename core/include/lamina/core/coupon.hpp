#pragma once
// A calibration coupon (issue 20, docs/jet.md): straight test cuts on one sheet, each at a known
// fraction of the separation speed and a known tilt (a tilted cut crosses a longer path, so one
// sheet gives several paths), labelled so the person who measures them can tell them apart. Its
// toolpath goes through the machine's own post like any sheet; its cuts' list becomes the CSV to
// fill in (`lamina calibrate coupon`), whose measurements `lamina calibrate fit` reads back.
#include "lamina/core/error.hpp"
#include "lamina/core/feed.hpp"
#include "lamina/core/toolpath.hpp"

#include <expected>
#include <string>
#include <vector>

namespace lamina {

struct CouponParams {
  double thickness_mm = 10.0;
  std::vector<double> feed_ratios{0.15, 0.3, 0.5, 0.75, 1.0};  // of the separation speed at each cut's path
  std::vector<double> tilts_rad{0.0, 0.5235987755982988};      // 0° and 30°: paths t and t / cos 30°
  double cut_length_mm = 40.0;
  double spacing_mm = 12.0;  // between neighbouring cuts (room for the wider kerf and a caliper)
  double margin_mm = 15.0;   // from the sheet's corner to the first cut
};

struct CouponCut {
  std::string label;  // "T30-R0.50": tilt in degrees, feed ratio
  double tilt_rad = 0.0;
  double path_mm = 0.0;           // h_f = t / cos tilt
  double feed_ratio = 0.0;        // what the machine was asked for, after its feed limits
  double feed_mm_per_s = 0.0;
  double separation_feed_mm_per_s = 0.0;
  int contour = -1;               // in the toolpath (its marker in the program)
};

struct Coupon {
  SheetToolpath toolpath;
  std::vector<CouponCut> cuts;
  double width_mm = 0.0, length_mm = 0.0;  // the sheet it needs
};

// Errors: invalid_argument naming the value (no ratio or tilt, a ratio ≤ 0, a tilt beyond 60°,
// a length or spacing ≤ 0) or the feed model's own.
std::expected<Coupon, Error> calibration_coupon(const CouponParams& coupon, const Material& material,
                                                const ToolpathParams& params);

}  // namespace lamina
