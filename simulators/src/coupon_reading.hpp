#pragma once
// What a person would read off a calibration coupon the simulated machine cut (issue 20): for
// each test cut (a "(CONTOUR n LABEL TEST CUT …)" marker in the program), its top and bottom
// width and its trail-back from the simulator's own jet (jet_physics.hpp) at the feed and path
// the machine really cut it at, with a caliper's noise. The labels are the program's, so the
// readings go into the CSV `lamina calibrate coupon` wrote, row by row, as a person's would.
#include <cstdint>
#include <expected>
#include <string>
#include <string_view>
#include <vector>

#include "jet_head.hpp"
#include "jet_physics.hpp"
#include "machine.hpp"

namespace lamina::sim {

struct CouponReading {
  std::string label;
  double top_width_mm = 0.0, bottom_width_mm = 0.0, trail_back_mm = 0.0;
};

struct ReadingParams {
  double sheet_thickness_mm = 10.0;  // what lies on the table
  double width_noise_mm = 0.01;      // a caliper's spread (one standard deviation)
  double trail_back_noise = 0.03;    // relative, reading drag lines
  std::uint64_t seed = 1;
};

// Errors name the program's line the simulated controller refused.
std::expected<std::vector<CouponReading>, std::string> read_coupon(std::string_view program, MachineConfig machine,
                                                                   const HeadGeometry& head, const JetPhysics& jet,
                                                                   const ReadingParams& params);

}  // namespace lamina::sim
