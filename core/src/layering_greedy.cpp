// The paper's layering (3-1), kept as a baseline: from the bottom up, slice at the thickest
// sheet and fall back to thinner ones while the layer fails the area-deviation or the staircase
// triangle criterion. One refinement a shop would make anyway: near the top, of the sheets
// that would reach the model's top only the thinnest is tried (a 10 mm sheet is not used for
// the last 2 mm when a 2.5 mm one reaches too).
#include "layering_internal.hpp"

#include <cmath>

namespace lamina::layering_detail {

std::vector<ChosenLayer> layer_greedy(Estimator& est, const LayeringParams& params) {
  const std::vector<double>& t = est.thicknesses();
  const double h = est.height();
  std::vector<ChosenLayer> layers;
  double z = 0.0;
  // Every layer adds at least the thinnest sheet, so this bounds the loop.
  const std::size_t max_layers = static_cast<std::size_t>(std::ceil(h / t.front())) + 2;
  while (layers.size() < max_layers) {
    est.release_below(est.span(z, t.front()).ka);
    int reach = -1;  // the thinnest sheet that reaches the top
    for (std::size_t i = 0; i < t.size() && reach < 0; ++i)
      if (z + t[i] >= h - kReachEps) reach = static_cast<int>(i);
    int chosen = -1;
    for (int i = static_cast<int>(t.size()) - 1; i >= 0 && chosen < 0; --i) {
      if (reach >= 0 && i > reach) continue;
      const auto check = est.greedy_check(est.span(z, t[static_cast<std::size_t>(i)]), i);
      if (check.area_ok && check.triangle_ok) chosen = i;
    }
    const bool ok = chosen >= 0;
    if (!ok) chosen = 0;
    const double th = t[static_cast<std::size_t>(chosen)];
    layers.push_back(ChosenLayer{z, chosen, est.estimate(est.span(z, th), chosen), ok});
    if (z + th >= h - kReachEps) break;
    z += th + params.bond_mm;
  }
  return layers;
}

}  // namespace lamina::layering_detail
