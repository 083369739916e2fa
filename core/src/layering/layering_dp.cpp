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
//
// The rack (issue 17, item 5): a thickness is an edge only where the layer's outlines fit one of
// its sheets, and only while its count allows (the state then carries the usage). When no stack
// can end the model, the choice is empty and says how high the rack reaches.
#include "layering/layering_internal.hpp"

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
  std::pair<std::int64_t, std::int64_t> pred{-1, -1};  // (position, usage) the last layer started from
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

// The edges from one position: for each thickness, its span, where its top would end the stack,
// and its estimate (only what the rack allows is asked for).
struct Reach {
  std::vector<std::pair<GridSpan, int>> cands;
  std::vector<double> dev;
  std::vector<StackEnd> ends;
  std::vector<char> fits;  // the layer's outlines fit a sheet of that thickness
};

void reach_from(Estimator& est, double z, double tol, Reach& r) {
  const std::vector<double>& t = est.thicknesses();
  for (std::size_t i = 0; i < t.size(); ++i) {
    r.cands[i] = {est.span(z, t[i]), static_cast<int>(i)};
    r.ends[i] = est.stack_end(z + t[i]);
    r.fits[i] = est.fits_supply(r.cands[i].first, static_cast<int>(i));
  }
  // Failing layers may stop early (their value is not needed, unless none passes).
  est.estimate(r.cands, r.dev, tol);
}

}  // namespace

// States are (position, usage): the usage counts the layers taken of each thickness the rack
// limits (SupplyCounter; 0 when none is limited, so the states are the positions alone).
LayerChoice layer_optimal(Estimator& est, const LayeringParams& params) {
  const std::vector<double>& t = est.thicknesses();
  const double tol = params.tolerance_mm;
  const SupplyCounter supply(est);
  LayerChoice out;
  if (supply.too_many()) {
    out.state_limit = true;
    return out;
  }
  using Key = std::pair<std::int64_t, std::int64_t>;  // (position, usage)
  std::map<Key, Node> open, finals_by_state;
  std::map<std::int64_t, Node> finals;
  open.emplace(Key{0, 0}, Node{});

  Reach r{std::vector<std::pair<GridSpan, int>>(t.size()), std::vector<double>(t.size()),
          std::vector<StackEnd>(t.size()), std::vector<char>(t.size())};
  std::int64_t reach_key = -1;
  for (auto it = open.begin(); it != open.end(); ++it) {
    const Node cur = it->second;
    const auto [pos, usage] = it->first;
    out.reached_mm = std::max(out.reached_mm, cur.z);
    if (pos != reach_key) {  // states at one position share their edges' estimates
      est.release_below(est.span(cur.z, t.front()).ka);
      reach_from(est, cur.z, tol, r);
      reach_key = pos;
    }
    auto usable = [&](std::size_t i) { return r.ends[i].allowed && r.fits[i] && supply.can_take(usage, static_cast<int>(i)); };
    bool any = false;
    int thinnest = -1;
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (!usable(i)) continue;
      any |= r.dev[i] <= tol;
      if (thinnest < 0) thinnest = static_cast<int>(i);
    }
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (!usable(i)) continue;
      // Only passing layers, unless none passes: then the thinnest usable, its deviation reported.
      // The thinnest sheet that ends the stack is an edge even when it fails: where the stack ends
      // ranks first (best_final), and the layer that ends it nearest may be out of tolerance (a
      // cup's rim inside its last 1 mm sheet). Not a thicker one: one thick failing layer would
      // outrank several thin ones at a pole flatter than the tilt limit.
      const bool passes = r.dev[i] <= tol;
      const bool thinnest_end = r.ends[i].final && static_cast<int>(i) == thinnest;
      if (any ? !passes && !thinnest_end : static_cast<int>(i) != thinnest) continue;
      double d = any && passes ? r.dev[i] : est.estimate(r.cands[i].first, static_cast<int>(i));
      if (r.ends[i].final) d = std::max(d, r.ends[i].off_top_mm);
      const bool ok = d <= tol;
      const double top = cur.z + t[i];
      Node next;
      next.failed = cur.failed + (ok ? 0 : 1);
      next.count = cur.count + 1;
      next.deviation = cur.deviation + d;
      next.pred = it->first;
      next.layer = ChosenLayer{cur.z, static_cast<int>(i), d, ok, any};
      next.z = r.ends[i].final ? top : top + params.bond_mm;
      const Key key{key_of(next.z), supply.take(usage, static_cast<int>(i))};
      auto& states = r.ends[i].final ? finals_by_state : open;
      auto [slot, inserted] = states.try_emplace(key, next);
      if (!inserted && better(next, slot->second, t)) slot->second = next;
    }
    if (open.size() + finals_by_state.size() > kMaxDpStates) {
      out.state_limit = true;
      return out;
    }
  }
  // Per final position, the best over usages (then best_final ranks the positions).
  for (const auto& [key, n] : finals_by_state) {
    auto [slot, inserted] = finals.try_emplace(key.first, n);
    if (!inserted && better(n, slot->second, t)) slot->second = n;
  }
  const Node* best = best_final(finals, est);
  if (!best) return out;
  // Walk back: a final state's predecessors are open states, down to (0, 0).
  for (const Node* n = best; n->pred.first >= 0; n = &open.at(n->pred)) out.layers.push_back(n->layer);
  std::reverse(out.layers.begin(), out.layers.end());
  return out;
}

}  // namespace lamina::layering_detail
