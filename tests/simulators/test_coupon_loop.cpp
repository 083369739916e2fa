// The calibration loop against a machine whose jet the planner does not know (issue 20): Lamina
// writes a coupon, lamina-sim cuts it with its own physics (jet_physics.hpp, a different form
// from kerf.hpp) and "measures" it, the readings go into Lamina's CSV as a person's would, and
// `lamina calibrate fit` learns the machine. Two machines: a hard material's jet (V taper at
// every speed but the slowest) and a soft one's (reversed taper up to a faster speed).
#include "coupon_loop.hpp"

#include <gtest/gtest.h>

namespace {

using coupon_loop::calibrate_on;
using coupon_loop::number_after;

TEST(CouponLoop, TheFitLearnsEachSimulatedJet) {
  const auto [hard, hard_out] = calibrate_on("hard", "jet_separation_mm_per_s_at_10mm = 30\njet_taper_gain = 0.04\njet_taper_offset = 0.002\n");
  const auto [soft, soft_out] = calibrate_on("soft", "jet_separation_mm_per_s_at_10mm = 36\njet_taper_gain = 0.05\njet_taper_offset = 0.012\n"
                                                     "jet_lag_max_deg = 18\njet_slow_widening = 0.3\n");
  for (const auto& [kerf, out] : {std::pair{hard, hard_out}, std::pair{soft, soft_out}}) {
    ASSERT_NE(out.find("wrote the kerf"), std::string::npos) << out;
    // The planner's form is not the machine's: what is left over is that difference and the
    // noise, small beside the widths (about 1 mm) and trail-backs (up to about 4 mm) described.
    EXPECT_LT(number_after(kerf, "rms_width_mm"), 0.03) << out;
    EXPECT_LT(number_after(kerf, "rms_trail_back_mm"), 0.2) << out;
    EXPECT_GT(number_after(kerf, "taper_per_ratio"), 0.0) << kerf;
  }
  // The soft machine's taper reverses up to a faster speed than the hard one's: the fit sees it.
  EXPECT_GT(number_after(soft, "taper_free_ratio"), number_after(hard, "taper_free_ratio") + 0.05) << hard << soft;
}

}  // namespace
