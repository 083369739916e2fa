// What the rack can give (issue 17, item 5): per thickness, how many layers its sheets hold and
// whether a layer's outlines fit one of its sheets at all. The layering only takes a thickness
// where both allow it, so a plan fits the rack or says, before anything is written, which
// thickness runs out.
#include "layering/layering_internal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace lamina::layering_detail {

namespace {

// A supply entry belongs to a thickness when they agree to 1e-9 mm (as the stock's own rule).
const ThicknessSupply* supply_for(const LayeringParams& params, double thickness_mm) {
  for (const ThicknessSupply& s : params.supply)
    if (std::abs(s.thickness_mm - thickness_mm) <= 1e-9) return &s;
  return nullptr;
}

// Whether an outline of dx × dy fits one room, as the nesting turns parts (0° or 90°).
bool fits_a_room(double dx, double dy, const std::vector<ThicknessSupply::Room>& rooms) {
  constexpr double eps = 1e-9;
  return std::any_of(rooms.begin(), rooms.end(), [&](const ThicknessSupply::Room& r) {
    return (dx <= r.length_mm + eps && dy <= r.width_mm + eps) || (dy <= r.length_mm + eps && dx <= r.width_mm + eps);
  });
}

bool slice_fits(const Slice& slice, const std::vector<ThicknessSupply::Room>& rooms) {
  for (const Loop& l : slice.loops) {
    if (l.is_hole() || l.points.empty()) continue;
    Eigen::Vector2d lo = l.points.front(), hi = l.points.front();
    for (const Eigen::Vector2d& p : l.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    if (!fits_a_room(hi.x() - lo.x(), hi.y() - lo.y(), rooms)) return false;
  }
  return true;
}

}  // namespace

void Estimator::compute_supply() {
  const std::size_t n = thicknesses_.size();
  max_layers_.assign(n, -1);
  misfit_prefix_.assign(n, {});
  for (std::size_t i = 0; i < n; ++i) {
    const ThicknessSupply* s = supply_for(params_, thicknesses_[i]);
    if (!s) continue;
    max_layers_[i] = s->max_layers < 0 ? -1 : s->max_layers;
    if (s->rooms.empty()) continue;
    std::vector<int>& prefix = misfit_prefix_[i];
    prefix.assign(slices_.size() + 1, 0);
    for (std::size_t j = 0; j < slices_.size(); ++j) prefix[j + 1] = prefix[j] + (slice_fits(slices_[j], s->rooms) ? 0 : 1);
  }
}

bool Estimator::fits_supply(GridSpan span, int thickness_index) const {
  const std::vector<int>& prefix = misfit_prefix_[static_cast<std::size_t>(thickness_index)];
  if (prefix.empty()) return true;
  // A layer on lines [ka, kb] reads slices 2ka .. 2kb-1 (layering_internal.hpp).
  const int lo = std::clamp(2 * span.ka, 0, slice_count());
  const int hi = std::clamp(2 * span.kb, lo, slice_count());
  return prefix[static_cast<std::size_t>(hi)] == prefix[static_cast<std::size_t>(lo)];
}

SupplyCounter::SupplyCounter(const Estimator& est) {
  const std::vector<double>& t = est.thicknesses();
  digit_of_.assign(t.size(), -1);
  for (std::size_t i = 0; i < t.size(); ++i) {
    const int cap = est.max_layers(static_cast<int>(i));
    // A cap the model's height can never reach is no limit: it costs no DP states.
    const double most_needed = std::ceil(est.height() / t[i]) + 1;
    if (cap < 0 || cap >= most_needed) continue;
    if (states_ > kMaxUsageStates / (cap + 1)) {
      too_many_ = true;  // the usage would not fit one number; the DP refuses the rack
      break;
    }
    digit_of_[i] = static_cast<int>(digit_.size());
    digit_.push_back(static_cast<int>(i));
    cap_.push_back(cap);
    radix_.push_back(states_);
    states_ *= cap + 1;
  }
}

bool SupplyCounter::can_take(std::int64_t usage, int thickness_index) const {
  const int d = digit_of_[static_cast<std::size_t>(thickness_index)];
  if (d < 0) return true;
  const auto k = static_cast<std::size_t>(d);
  return (usage / radix_[k]) % (cap_[k] + 1) < cap_[k];
}

std::int64_t SupplyCounter::take(std::int64_t usage, int thickness_index) const {
  const int d = digit_of_[static_cast<std::size_t>(thickness_index)];
  return d < 0 ? usage : usage + radix_[static_cast<std::size_t>(d)];
}

}  // namespace lamina::layering_detail
