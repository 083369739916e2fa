// The layering chooses from what the plan will measure (issue 17, item 4). The grid estimate
// reads each layer at a few stations on its faces; the bevel planner reads it at every station of
// every sub-slice, and where a surface turns across the layer (a twisted prism) the two disagreed
// both ways: 0.010 estimated vs 0.28 mm measured for 2.5 mm layers, 1.085 vs 0.375 for 5 mm.
//
// So the estimate is only the DP's first guess. Every layer the DP chooses is planned by the bevel
// planner itself (plan_bevels, the same parameters the plan will use) and its measure replaces
// the estimate; the DP runs again on the corrected values until the layers it chooses are all
// measured ones. Each round measures at least one new layer, so it ends; kMaxRounds bounds it
// (the last choice is then kept, its unmeasured layers flagged by estimate != measure in the
// report). A round costs one plan_bevels of the chosen layers and a DP over memoized estimates.
//
// Estimates that were too pessimistic are corrected too: in every round, at each chosen layer's
// start that is within tolerance, the next thicker sheet is planned as well. The layers of a round
// overlap, so each is planned on its own (plan_layers_apart: one slicing pass, one pool of tasks,
// the thickest first; on the 1M sphere 2.2 → 1.7 s against batches of layers that do not overlap).
#include "layering/layering_internal.hpp"

#include "bevel/plan_layers.hpp"
#include "lamina/core/bevel.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <optional>

namespace lamina::layering_detail {

namespace {

constexpr int kMaxRounds = 12;

BevelParams bevel_params_of(const LayeringParams& params) {
  BevelParams p;
  p.fit = params.fit;
  p.sub_slice_mm = params.sub_slice_mm;
  p.tolerance_mm = params.tolerance_mm;
  p.parallel = params.parallel;
  return p;
}

struct Candidate {
  double z_rel = 0.0;
  int thickness_index = 0;
};

// The layers the verification has planned, for the progress bar: each round adds its own to the
// total, and every layer planned moves the bar (serialized: the layers plan on several threads).
class LayerCounter {
 public:
  explicit LayerCounter(const std::function<void(int, int)>& report) : report_(report) {}
  void add_to_total(std::size_t n) {
    const std::lock_guard lock(mutex_);
    total_ += static_cast<int>(n);
  }
  void one_more() {
    const std::lock_guard lock(mutex_);
    ++done_;
    if (report_) report_(done_, std::max(done_, total_));
  }

 private:
  const std::function<void(int, int)>& report_;
  std::mutex mutex_;
  int done_ = 0, total_ = 0;
};

// The plans made, by (start in µm, thickness index): the chosen layers' plans are handed on.
using PlanCache = std::map<std::pair<std::int64_t, int>, LayerPlan>;
std::pair<std::int64_t, int> plan_key(double z_rel, int thickness_index) {
  return {std::llround(z_rel * 1e6), thickness_index};
}

// Plans the candidates, each on its own (they may overlap: a chosen layer and the thicker sheet
// at its start), and records each measure in the order of their heights. Returns how many were
// new.
std::expected<int, Error> measure(Estimator& est, const Mesh& mesh, const bevel_detail::MeshIndexes& indexes,
                                  const LayeringParams& params, std::vector<Candidate> todo, PlanCache& plans,
                                  LayerCounter& counter) {
  const std::vector<double>& t = est.thicknesses();
  auto thickness = [&](const Candidate& c) { return t[static_cast<std::size_t>(c.thickness_index)]; };
  std::sort(todo.begin(), todo.end(), [](const Candidate& a, const Candidate& b) { return a.z_rel < b.z_rel; });
  std::vector<LayerSpan> spans;
  for (const Candidate& c : todo) spans.push_back(LayerSpan{est.z_base() + c.z_rel, thickness(c)});
  BevelParams bp = bevel_params_of(params);
  bp.on_layer = [&counter] { counter.one_more(); };
  auto planned = bevel_detail::plan_layers_apart(mesh, indexes, spans, bp);
  if (!planned) return std::unexpected(planned.error());
  int fresh = 0;
  for (std::size_t i = 0; i < todo.size(); ++i) {
    LayerPlan& layer = (*planned)[i];
    layer.index = 0;  // as a plan of the layer alone
    const GridSpan span = est.span(todo[i].z_rel, thickness(todo[i]));
    fresh += est.set_measured(span, todo[i].thickness_index, layer.max_deviation_mm) ? 1 : 0;
    plans.insert_or_assign(plan_key(todo[i].z_rel, todo[i].thickness_index), std::move(layer));
  }
  return fresh;
}

// The chosen layers not measured yet, and at each chosen layer's start the next thicker sheet.
std::vector<Candidate> unmeasured(const Estimator& est, const LayerChoice& choice) {
  const std::vector<double>& t = est.thicknesses();
  std::vector<Candidate> out;
  for (const ChosenLayer& l : choice.layers) {
    const int i = l.thickness_index;
    if (!est.is_measured(est.span(l.z_rel, t[static_cast<std::size_t>(i)]), i)) out.push_back({l.z_rel, i});
    // Where the chosen sheet itself is out of tolerance a thicker one will not do better.
    const int thicker = i + 1;
    if (l.within && thicker < static_cast<int>(t.size()) && l.z_rel + t[static_cast<std::size_t>(thicker)] <= est.height() + 1e-9 &&
        !est.is_measured(est.span(l.z_rel, t[static_cast<std::size_t>(thicker)]), thicker))
      out.push_back({l.z_rel, thicker});
  }
  return out;
}

}  // namespace

std::expected<LayerChoice, Error> layer_verified(Estimator& est, const Mesh& mesh, const LayeringParams& params) {
  LayerChoice choice = layer_optimal(est, params);
  std::optional<geometry_detail::TriangleTree> own_model;  // built once, for every round's plans, unless given
  const geometry_detail::TriangleTree* model =
      params.model_index && params.model_index->indexes(mesh) ? &params.model_index->tree() : nullptr;
  std::optional<bevel_detail::FacetsByZ> facets_by_z;  // built once, for every round's plans
  PlanCache plans;
  LayerCounter counter(params.on_round);
  for (int round = 0; round < kMaxRounds; ++round) {
    if (choice.layers.empty() || choice.state_limit) break;
    const std::vector<Candidate> todo = unmeasured(est, choice);
    if (todo.empty()) break;  // every chosen layer stands on its measure
    if (!model) model = &own_model.emplace(mesh.vertices, mesh.faces, geometry_detail::threads_for(params.parallel));
    if (!facets_by_z) facets_by_z.emplace(mesh, params.sub_slice_mm);
    counter.add_to_total(todo.size());
    auto fresh = measure(est, mesh, {model, &*facets_by_z}, params, todo, plans, counter);
    if (!fresh) return std::unexpected(fresh.error());
    if (*fresh == 0) break;
    est.restart();
    choice = layer_optimal(est, params);
  }
  // The chosen layers as planned, when every one was (the bevel phase need not plan them again).
  for (std::size_t i = 0; i < choice.layers.size(); ++i) {
    const auto it = plans.find(plan_key(choice.layers[i].z_rel, choice.layers[i].thickness_index));
    if (it == plans.end()) {
      choice.plans.clear();
      break;
    }
    choice.plans.push_back(std::move(it->second));  // the cache ends here
    choice.plans.back().index = static_cast<int>(i);
  }
  return choice;
}

}  // namespace lamina::layering_detail
