#pragma once
// The two files of a jet calibration (docs/jet.md), read and written at the CLI's edge:
//
// The measurements of a test coupon, CSV, one row per cut (a header names the columns, in any
// order; '#' starts a comment line):
//   label,path_mm,feed_ratio,top_width_mm,bottom_width_mm,trail_back_mm
//   h10-r0.50,10,0.5,0.93,0.88,0.31
//
// The calibrated kerf of each material, TOML, written by `lamina calibrate fit` (one [[kerf]]
// per material; fitting a material again replaces its table and keeps the others):
//   [[kerf]]
//   material = "aluminium 6061-T6"
//   top_width_mm = 0.95               # w0
//   top_width_per_ratio_mm = -0.08    # w1
//   taper_per_ratio = 0.05            # k
//   taper_free_ratio = 0.25           # r0
//   trail_back_factor = 0.15          # c
//   trail_back_exponent = 1.8         # m
//   cuts = 15                         # what it was fitted from, and how well
//   rms_width_mm = 0.011
//   rms_trail_back_mm = 0.02
//   measurements = "coupon-al-10.csv"
#include "lamina/core/error.hpp"
#include "lamina/core/kerf.hpp"

#include <expected>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace lamina::cli {

// parse_error "SOURCE:LINE: what" naming the column; values as the kerf fit checks them later.
std::expected<std::vector<KerfMeasurement>, Error> parse_kerf_measurements(std::string_view csv, const std::string& source);

struct KerfCalibration {
  KerfModel model;
  std::int64_t cuts = 0;
  double rms_width_mm = 0.0, rms_trail_back_mm = 0.0;
  std::string measurements;  // the file it was fitted from
};
using KerfCalibrations = std::map<std::string, KerfCalibration, std::less<>>;  // by material

std::expected<KerfCalibrations, Error> parse_kerf_toml(std::string_view text, const std::string& source);
std::string kerf_toml(const KerfCalibrations& calibrations);

}  // namespace lamina::cli
