#include "coupon_reading.hpp"

#include "program_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

namespace lamina::sim {
namespace {

// The label of a test cut's marker, or "" for any other line.
std::string test_cut_label(std::string_view line) {
  const auto open = line.find("(CONTOUR ");
  if (open == std::string_view::npos || line.find(" TEST CUT") == std::string_view::npos) return {};
  const auto number_end = line.find(' ', open + 9);
  const auto label_end = line.find(' ', number_end + 1);
  if (number_end == std::string_view::npos || label_end == std::string_view::npos) return {};
  return std::string(line.substr(number_end + 1, label_end - number_end - 1));
}

struct LongestCut {
  double travel_mm = 0.0, feed_mm_per_s = 0.0, axis_z = 1.0;
};

}  // namespace

std::expected<std::vector<CouponReading>, std::string> read_coupon(std::string_view program, MachineConfig machine,
                                                                   const HeadGeometry& head, const JetPhysics& jet,
                                                                   const ReadingParams& params) {
  std::vector<std::string> order;
  std::map<std::string, LongestCut> cuts;
  std::string label;
  ProgramCallbacks callbacks;
  callbacks.on_line = [&](std::string_view line) {
    if (auto l = test_cut_label(line); !l.empty()) {
      label = l;
      if (!cuts.contains(label)) order.push_back(label);
      cuts[label];
    }
  };
  callbacks.on_block = [&](const ExecutedBlock& b) {
    if (!b.jet || label.empty() || b.t_end_s <= b.t_start_s) return;
    const JetPose from = jet_pose(b.start, head), to = jet_pose(b.end, head);
    const double travel = std::hypot(to.tip_mm[0] - from.tip_mm[0], to.tip_mm[1] - from.tip_mm[1], to.tip_mm[2] - from.tip_mm[2]);
    LongestCut& c = cuts[label];
    if (travel > c.travel_mm) c = {travel, travel / (b.t_end_s - b.t_start_s), to.axis[2]};
  };
  if (auto ran = run_program(program, std::move(machine), callbacks); !ran) return std::unexpected(ran.error());
  std::mt19937_64 rng(params.seed);
  std::normal_distribution<double> caliper(0.0, params.width_noise_mm), gauge(0.0, params.trail_back_noise);
  std::vector<CouponReading> out;
  for (const std::string& l : order) {
    const LongestCut& c = cuts[l];
    if (c.travel_mm <= 0.0) return std::unexpected(fmt::format("test cut {}: the jet never moved while on", l));
    const CutWall wall = cut_wall(jet, params.sheet_thickness_mm / c.axis_z, c.feed_mm_per_s);
    // A caliper reads no less than nothing. A slot that did not cut through has no bottom and no
    // exit to read a trail-back from: both 0, as a person writes them.
    CouponReading reading{l, std::max(wall.top_width_mm + caliper(rng), 0.0), 0.0, 0.0};
    if (wall.bottom_width_mm > 0.0) {
      reading.bottom_width_mm = std::max(wall.bottom_width_mm + caliper(rng), 0.0);
      reading.trail_back_mm = std::max(wall.trail_back_mm * (1.0 + gauge(rng)), 0.0);
    }
    if (reading.bottom_width_mm == 0.0) reading.trail_back_mm = 0.0;
    out.push_back(std::move(reading));
  }
  return out;
}

}  // namespace lamina::sim
