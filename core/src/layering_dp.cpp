// The optimal layering: a dynamic programme over the positions where a layer can start.
//
// States are the heights (above the model's bottom) where the next layer starts, deduplicated
// at 1 µm; every edge adds one sheet (and the bond after it), so heights only grow and visiting
// the states in increasing height is a topological order. From a state the edges are the
// thicknesses whose estimated achievable deviation is within tolerance; when none is, only the
// thinnest (a shortfall). A layer that ends the stack (stack_end, layering_internal.hpp: at the
// model's top as the cut side allows) is judged the same way on its surface, and is an edge
// however far its top lies from the model's; but that distance is part of its estimate, so a
// stack that ends 3 mm above the model is a layer 3 mm out of tolerance, not a free one (issue
// 17, item 3), and one that ends nearer wins. The objective is lexicographic: a top within half
// the thinnest sheet of the model's (or the nearest the stock allows), fewest layers out of
// tolerance, then fewest layers, then least total estimated deviation, then the top nearest the
// model's; remaining ties prefer thinner sheets higher up (thicker sheets lower in the stack).
#include "layering_internal.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

namespace lamina::layering_detail {

namespace {

struct Node {
  double z = 0.0;          // start of the next layer (open) or top of the stack (final)
  int failed = 0;          // layers out of tolerance
  int count = 0;
  double deviation = 0.0;  // sum of the layers' estimates
  std::int64_t pred = -1;  // key of the open state the last layer started from
  ChosenLayer layer;       // the last layer
};

std::int64_t key_of(double z) { return std::llround(z / kPositionQuantum); }

// Is (failed, count, deviation, last thickness) better than the node's?
bool better(const Node& cand, const Node& cur, const std::vector<double>& t) {
  if (cand.failed != cur.failed) return cand.failed < cur.failed;
  if (cand.count != cur.count) return cand.count < cur.count;
  if (std::abs(cand.deviation - cur.deviation) > kDeviationEps) return cand.deviation < cur.deviation;
  return t[static_cast<std::size_t>(cand.layer.thickness_index)] < t[static_cast<std::size_t>(cur.layer.thickness_index)];
}

// The best final state. First the stack that ends nearest the model's top beyond half the
// thinnest sheet (issue 17, item 3: with 1 mm sheets stocked, six 10 mm sheets 6.7 mm over the
// top are not "fewer layers" than seven ending 0.2 mm over); within that, as better(), then the
// top nearest the model's.
const Node* best_final(const std::map<std::int64_t, Node>& finals, const Estimator& est) {
  const double half_thinnest = 0.5 * est.thicknesses().front();
  auto miss = [&](const Node& n) { return std::max(0.0, est.stack_end(n.z).off_top_mm - half_thinnest); };
  auto off = [&](const Node& n) { return std::abs(n.z - est.height()); };
  auto rank = [&](const Node& n) {
    return std::make_tuple(std::llround(miss(n) / kPositionQuantum), n.failed, n.count,
                           std::llround(n.deviation / kDeviationEps), std::llround(off(n) / kPositionQuantum));
  };
  const Node* best = nullptr;
  for (const auto& [k, n] : finals)
    if (!best || rank(n) < rank(*best)) best = &n;
  return best;
}

}  // namespace

std::vector<ChosenLayer> layer_optimal(Estimator& est, const LayeringParams& params) {
  const std::vector<double>& t = est.thicknesses();
  const double tol = params.tolerance_mm;
  std::map<std::int64_t, Node> open, finals;
  open.emplace(0, Node{});

  std::vector<std::pair<GridSpan, int>> cands(t.size());
  std::vector<double> dev(t.size());
  std::vector<StackEnd> ends(t.size());
  for (auto it = open.begin(); it != open.end(); ++it) {
    const Node cur = it->second;
    est.release_below(est.span(cur.z, t.front()).ka);
    for (std::size_t i = 0; i < t.size(); ++i) {
      cands[i] = {est.span(cur.z, t[i]), static_cast<int>(i)};
      ends[i] = est.stack_end(cur.z + t[i]);
    }
    // Failing layers may stop early (their value is not needed) ...
    est.estimate(cands, dev, tol);
    bool any = false;
    for (std::size_t i = 0; i < t.size(); ++i) any |= ends[i].allowed && dev[i] <= tol;
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (!ends[i].allowed) continue;
      // ... unless none passes: then the thinnest is used and its deviation reported.
      if (any ? dev[i] > tol : i != 0) continue;
      const bool surface_ok = any;
      double d = any ? dev[i] : est.estimate(cands[i].first, 0);
      if (ends[i].final) d = std::max(d, ends[i].off_top_mm);
      const bool ok = d <= tol;
      const double top = cur.z + t[i];
      Node next;
      next.failed = cur.failed + (ok ? 0 : 1);
      next.count = cur.count + 1;
      next.deviation = cur.deviation + d;
      next.pred = it->first;
      next.layer = ChosenLayer{cur.z, static_cast<int>(i), d, ok, surface_ok};
      next.z = ends[i].final ? top : top + params.bond_mm;
      auto& states = ends[i].final ? finals : open;
      auto [slot, inserted] = states.try_emplace(key_of(next.z), next);
      if (!inserted && better(next, slot->second, t)) slot->second = next;
    }
  }

  std::vector<ChosenLayer> layers;
  for (const Node* n = best_final(finals, est); n; n = n->pred >= 0 ? &open.at(n->pred) : nullptr) {
    if (n->pred < 0) break;
    layers.push_back(n->layer);
  }
  return {layers.rbegin(), layers.rend()};
}

}  // namespace lamina::layering_detail
