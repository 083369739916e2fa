// The paper's layering (3-1), kept as a baseline: from the bottom up, slice at the thickest
// sheet and fall back to thinner ones while the layer fails the area-deviation or the staircase
// triangle criterion. One refinement a shop would make anyway: near the top, of the sheets
// that would reach the model's top only the thinnest is tried (a 10 mm sheet is not used for
// the last 2 mm when a 2.5 mm one reaches too). Where the stack may end follows the cut side
// (StackEnd), and the last layer's estimate includes how far it ends from the model's top. Only
// what the rack allows is tried (counts, sheet sizes: issue 17, item 5); a layer the rack has
// nothing for ends the attempt with no layers.
#include "layering/layering_internal.hpp"

#include <algorithm>
#include <cmath>

namespace lamina::layering_detail {

LayerChoice layer_greedy(Estimator& est, const LayeringParams& params) {
  const std::vector<double>& t = est.thicknesses();
  const double h = est.height();
  const SupplyCounter supply(est);
  LayerChoice out;
  if (supply.too_many()) {
    out.state_limit = true;
    return out;
  }
  std::int64_t usage = 0;
  std::vector<ChosenLayer>& layers = out.layers;
  double z = 0.0;
  // Every layer adds at least the thinnest sheet, so this bounds the loop.
  const std::size_t max_layers = static_cast<std::size_t>(std::ceil(h / t.front())) + 2;
  while (layers.size() < max_layers) {
    est.release_below(est.span(z, t.front()).ka);
    out.reached_mm = z;
    // What the rack allows here: the sheet's count and whether the layer fits one of its sheets.
    auto usable = [&](int i) {
      const double th = t[static_cast<std::size_t>(i)];
      return est.stack_end(z + th).allowed && est.fits_supply(est.span(z, th), i) && supply.can_take(usage, i);
    };
    int reach = -1;  // the thinnest usable sheet that ends the stack
    for (int i = 0; i < static_cast<int>(t.size()) && reach < 0; ++i)
      if (usable(i) && est.stack_end(z + t[static_cast<std::size_t>(i)]).final) reach = i;
    int chosen = -1, thinnest = -1;
    for (int i = static_cast<int>(t.size()) - 1; i >= 0; --i) {
      if ((reach >= 0 && i > reach) || !usable(i)) continue;
      thinnest = i;
      if (chosen >= 0) continue;
      const auto check = est.greedy_check(est.span(z, t[static_cast<std::size_t>(i)]), i);
      if (check.area_ok && check.triangle_ok) chosen = i;
    }
    if (thinnest < 0) {  // the rack has nothing for this layer: no stack ends the model
      layers.clear();
      return out;
    }
    const bool ok = chosen >= 0;
    if (!ok) chosen = thinnest;
    usage = supply.take(usage, chosen);
    const double th = t[static_cast<std::size_t>(chosen)];
    const StackEnd end = est.stack_end(z + th);
    // The last layer's estimate includes how far the stack ends from the model's top.
    const double estimate = std::max(est.estimate(est.span(z, th), chosen), end.final ? end.off_top_mm : 0.0);
    layers.push_back(ChosenLayer{z, chosen, estimate, ok, ok});
    if (end.final) break;
    z += th + params.bond_mm;
  }
  return out;
}

}  // namespace lamina::layering_detail
