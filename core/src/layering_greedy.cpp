// The paper's layering (3-1), kept as a baseline: from the bottom up, slice at the thickest
// sheet and fall back to thinner ones while the layer fails the area-deviation or the staircase
// triangle criterion. One refinement a shop would make anyway: near the top, of the sheets
// that would reach the model's top only the thinnest is tried (a 10 mm sheet is not used for
// the last 2 mm when a 2.5 mm one reaches too). Where the stack may end follows the cut side
// (StackEnd), and the last layer's estimate includes how far it ends from the model's top.
#include "layering_internal.hpp"

#include <algorithm>
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
    int reach = -1;  // the thinnest sheet that ends the stack
    for (std::size_t i = 0; i < t.size() && reach < 0; ++i) {
      const StackEnd e = est.stack_end(z + t[i]);
      if (e.allowed && e.final) reach = static_cast<int>(i);
    }
    int chosen = -1;
    for (int i = static_cast<int>(t.size()) - 1; i >= 0 && chosen < 0; --i) {
      if ((reach >= 0 && i > reach) || !est.stack_end(z + t[static_cast<std::size_t>(i)]).allowed) continue;
      const auto check = est.greedy_check(est.span(z, t[static_cast<std::size_t>(i)]), i);
      if (check.area_ok && check.triangle_ok) chosen = i;
    }
    const bool ok = chosen >= 0;
    if (!ok) chosen = 0;
    const double th = t[static_cast<std::size_t>(chosen)];
    const StackEnd end = est.stack_end(z + th);
    // The last layer's estimate includes how far the stack ends from the model's top.
    const double estimate = std::max(est.estimate(est.span(z, th), chosen), end.final ? end.off_top_mm : 0.0);
    layers.push_back(ChosenLayer{z, chosen, estimate, ok, ok});
    if (end.final) break;
    z += th + params.bond_mm;
  }
  return layers;
}

}  // namespace lamina::layering_detail
