#pragma once
// The jet's real kerf taken into a pass's lines (toolpath.hpp's JetCompensation, docs/jet.md).
#include "lamina/core/error.hpp"
#include "lamina/core/kerf.hpp"
#include "lamina/core/toolpath.hpp"
#include "cam/toolpath_ring.hpp"

#include <expected>
#include <span>
#include <vector>

namespace lamina::cam_detail {

struct JetCompensationInput {
  JetCompensationMode mode = JetCompensationMode::off;
  const KerfModel* kerf = nullptr;
  double thickness_mm = 0.0;
  double half_kerf_mm = 0.0;      // what compensate_pass offset every line by
  double tilt_max_rad = 0.0;
  bool closed = true;             // the points go all the way round (travel wraps)
};

// Each point (compensate_pass's, with its feed and corner factor) moved so the kerf the jet
// really leaves has its part-side wall on the planned line: the top by w_t/2 and the bottom by
// w_b/2 towards the scrap instead of both by half_kerf_mm, and (full) the bottom ahead along the
// travel by the trail-back. The feed ratio is the point's feed (corner factor included) over
// separation_mm_per_s[i]. Returns how many lines the tilt limit held back; errors name the point.
std::expected<std::size_t, Error> compensate_jet(std::vector<PathPoint>& points, std::span<const double> separation_mm_per_s,
                                                 const JetCompensationInput& in);

}  // namespace lamina::cam_detail
