// The optimal layering: a dynamic programme over the positions where a layer can start.
//
// States are the heights (above the model's bottom) where the next layer starts, deduplicated
// at 1 µm; every edge adds one sheet (and the bond after it), so heights only grow and visiting
// the states in increasing height is a topological order. From a state the edges are the
// thicknesses whose estimated achievable deviation is within tolerance; when none is, only the
// thinnest (flagged). A layer whose top reaches the model's top ends the stack (a final state,
// keyed by that top). The objective is lexicographic: fewest layers, then least total estimated
// deviation, then least overshoot of the stack above the model; remaining ties prefer thinner
// sheets higher up (thicker sheets lower in the stack).
#include "layering_internal.hpp"

#include <cmath>
#include <map>

namespace lamina::layering_detail {

namespace {

struct Node {
  double z = 0.0;          // start of the next layer (open) or top of the stack (final)
  int count = 0;
  double deviation = 0.0;  // sum of the layers' estimates
  std::int64_t pred = -1;  // key of the open state the last layer started from
  ChosenLayer layer;       // the last layer
};

std::int64_t key_of(double z) { return std::llround(z / kPositionQuantum); }

// Is (count, deviation, last thickness) better than the node's?
bool better(const Node& cand, const Node& cur, const std::vector<double>& t) {
  if (cand.count != cur.count) return cand.count < cur.count;
  if (std::abs(cand.deviation - cur.deviation) > kDeviationEps) return cand.deviation < cur.deviation;
  return t[static_cast<std::size_t>(cand.layer.thickness_index)] < t[static_cast<std::size_t>(cur.layer.thickness_index)];
}

}  // namespace

std::vector<ChosenLayer> layer_optimal(Estimator& est, const LayeringParams& params) {
  const std::vector<double>& t = est.thicknesses();
  const double h = est.height();
  const double bond = params.bond_mm;
  std::map<std::int64_t, Node> open, finals;
  open.emplace(0, Node{});

  std::vector<std::pair<GridSpan, int>> cands(t.size());
  std::vector<double> dev(t.size());
  for (auto it = open.begin(); it != open.end(); ++it) {
    const Node cur = it->second;
    est.release_below(est.span(cur.z, t.front()).ka);
    for (std::size_t i = 0; i < t.size(); ++i) cands[i] = {est.span(cur.z, t[i]), static_cast<int>(i)};
    // Failing layers may stop early (their value is not needed) ...
    est.estimate(cands, dev, params.tolerance_mm);
    bool any = false;
    for (std::size_t i = 0; i < t.size(); ++i) any |= dev[i] <= params.tolerance_mm;
    // ... unless none passes: then the thinnest is used and its deviation reported.
    if (!any) dev[0] = est.estimate(cands[0].first, 0);
    for (std::size_t i = 0; i < t.size(); ++i) {
      const bool ok = dev[i] <= params.tolerance_mm;
      if (any ? !ok : i != 0) continue;
      const double top = cur.z + t[i];
      Node next;
      next.count = cur.count + 1;
      next.deviation = cur.deviation + dev[i];
      next.pred = it->first;
      next.layer = ChosenLayer{cur.z, static_cast<int>(i), dev[i], ok};
      const bool final = top >= h - kReachEps;
      next.z = final ? top : top + bond;
      auto& states = final ? finals : open;
      auto [slot, inserted] = states.try_emplace(key_of(next.z), next);
      if (!inserted && better(next, slot->second, t)) slot->second = next;
    }
  }

  const Node* best = nullptr;
  for (const auto& [k, n] : finals) {
    if (!best || n.count < best->count ||
        (n.count == best->count && (n.deviation < best->deviation - kDeviationEps ||
                                    (std::abs(n.deviation - best->deviation) <= kDeviationEps && n.z < best->z - kReachEps))))
      best = &n;
  }
  std::vector<ChosenLayer> layers;
  for (const Node* n = best; n; n = n->pred >= 0 ? &open.at(n->pred) : nullptr) {
    if (n->pred < 0) break;
    layers.push_back(n->layer);
  }
  return {layers.rbegin(), layers.rend()};
}

}  // namespace lamina::layering_detail
