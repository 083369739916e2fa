#pragma once
// The kerf an abrasive jet really leaves (issue 20): wider at the top than at the bottom (taper;
// reversed at very low speed in soft material) and an exit that trails behind the entry
// (trail-back, or lag). Both grow with how fast the jet moves relative to the speed that just
// separates the sheet at this path length, r = v / v_s(h_f), which is how shops think of it
// (OMAX's and WARDJet's quality levels are fractions of the separation speed; Zeng & Kim's model,
// feed.hpp, gives v_s as its quality-1 feed).
//
// The planner's model, per material, coefficients in data (docs/jet.md):
//   top width       w_t = w0 + w1 · r                       (mm)
//   taper           (w_t − w_b) / h_f = k · (r − r0)        (twice the tangent of the wall's lean;
//                                                            negative below r0: reversed)
//   trail-back      lag = c · h_f · r^m                     (mm, at the exit, along the travel)
// Each is linear in its coefficients (the last after taking logarithms), so test cuts fit them by
// least squares (fit_kerf_model).
#include "lamina/core/error.hpp"

#include <expected>
#include <span>
#include <string>
#include <vector>

namespace lamina {

struct KerfModel {
  double top_width_mm = 0.9;          // w0: the top width at r = 0 (≈ the focusing tube)
  double top_width_per_ratio_mm = 0.0;  // w1
  double taper_per_ratio = 0.04;      // k
  double taper_free_ratio = 0.2;      // r0: no taper here; reversed below
  double trail_back_factor = 0.12;    // c
  double trail_back_exponent = 2.0;   // m
};

struct KerfShape {
  double top_width_mm = 0.0;
  double bottom_width_mm = 0.0;
  double wall_lean_rad = 0.0;  // each wall's lean from the jet axis, + when the bottom is narrower
  double trail_back_mm = 0.0;  // how far the exit trails the entry, along the travel
};

// The kerf at a path length h_f (mm, t / cos tilt) and a feed ratio r = v / v_s (> 0; 1 at the
// separation speed). Errors name the value: h_f or r not finite and > 0, or a bottom width ≤ 0
// (the jet would not cut through: a model or a ratio beyond what was calibrated).
std::expected<KerfShape, Error> kerf_at(const KerfModel& model, double path_mm, double feed_ratio);

// One cut of a calibration coupon, as measured (docs/jet.md, `lamina calibrate`).
struct KerfMeasurement {
  std::string label;  // the cut's label on the coupon, for the residuals
  double path_mm = 0.0;
  double feed_ratio = 0.0;
  double top_width_mm = 0.0;
  double bottom_width_mm = 0.0;
  double trail_back_mm = 0.0;
};

struct KerfResidual {
  std::string label;
  double top_width_mm = 0.0, bottom_width_mm = 0.0, trail_back_mm = 0.0;  // measured − model
  bool through = true;  // false: the cut did not go through (bottom read 0); only its top was fitted
};

struct KerfFit {
  KerfModel model;
  std::vector<KerfResidual> residuals;
  double rms_width_mm = 0.0, rms_trail_back_mm = 0.0;
};

// Least squares over the measurements. Needs at least two distinct feed ratios among the cuts
// that went through, each measurement with finite path, ratio > 0, a top width > 0, and a bottom
// width and trail-back > 0 (the lag of a real cut is never zero; a zero is a missing reading) —
// except a cut that did not go through, read as a bottom width of exactly 0: its top width is
// fitted, its taper and trail-back are not (they were not there to measure). An error names the
// first bad row by its label.
std::expected<KerfFit, Error> fit_kerf_model(std::span<const KerfMeasurement> cuts);

}  // namespace lamina
