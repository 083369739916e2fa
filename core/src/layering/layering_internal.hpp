#pragma once
// Internal parts of choose_layers (layering.cpp): the z grid with its sub-slices, stations and
// the achievable-deviation estimate (layering_grid.cpp), the dynamic programme
// (layering_dp.cpp) and the paper's greedy rule (layering_greedy.cpp). Not public API.
//
// The grid. Grid line k sits at z_line(k) = k·s above the model's bottom for k < top_line(),
// and the last line sits at the model's top H (so the top slice reads the model just below its
// top even when H is not a multiple of s). Around each line the mesh is cut twice, δ above and
// δ below, so a layer [line a, line b] reads its material from the slices strictly inside it
// (flat faces on a grid line are read from the correct side):
//     slice 2k     = z_line(k) + δ   ("above k", k = 0 .. top_line()-1)
//     slice 2k - 1 = z_line(k) - δ   ("below k", k = 1 .. top_line())
// A layer on lines [ka, kb] uses the contiguous slices 2ka .. 2kb-1.
//
// Stations. Points on the loops of a slice (contour vector midpoints, evenly spaced along the
// loop, at most kMaxStationsPerLoop per loop) with the horizontal outward normal. A layer's
// estimate reads the profile at the stations of its bottom slice, of its top slice and of every
// slice inside it where the section changes abruptly (loops appear or vanish, a flat face) —
// between those, the boundary stations' lines see the gradual changes of the surface.
#include "lamina/core/bevel.hpp"
#include "lamina/core/layering.hpp"
#include "lamina/core/section_lines.hpp"
#include "lamina/core/slice.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <expected>
#include <limits>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <tuple>
#include <vector>

namespace lamina::layering_detail {

inline constexpr int kMaxStationsPerLoop = 128;
// Positions closer than this are one DP state (1 µm).
inline constexpr double kPositionQuantum = 1e-3;
// A stack whose top is within this of the model's top reaches it (float meshes).
inline constexpr double kReachEps = 1e-5;
// Two estimates (sums of estimates) closer than this are equal for the objective.
inline constexpr double kDeviationEps = 1e-9;

// A layer mapped onto the grid: lines ka < kb.
struct GridSpan {
  int ka = 0, kb = 0;
  auto operator<=>(const GridSpan&) const = default;
};

struct Station {
  Eigen::Vector2d point;
  Eigen::Vector2d normal;  // horizontal, unit, pointing out of the material
};

// Where the surface crosses a station's line on one slice; u is NaN when it does not (within
// the search width).
struct Sample {
  double u = 0.0;
  double slope = 0.0;
};

// Whether a layer whose top is at a height (above the model's bottom) may end the stack, and how
// far that top is from the model's (issue 17, item 3). The cut side decides which way it may
// miss: outside keeps the whole model (a stack ends at or above its top), inside never leaves
// material beyond it (at or below, ending when no thinnest sheet fits any more), mixed ends
// within half the thinnest sheet either way. off_top_mm is a deviation of the last layer: the
// model's top face is that far from the stack's, or the stack's from the model's.
struct StackEnd {
  bool allowed = true;  // inside: a top above the model's is not
  bool final = false;
  double off_top_mm = 0.0;
};

class Estimator {
 public:
  // Validated params; thicknesses sorted ascending without duplicates.
  static std::expected<std::unique_ptr<Estimator>, Error> create(const Mesh& mesh, const LayeringParams& params,
                                                                 std::vector<double> thicknesses);

  double z_base() const { return z_base_; }                 // the model's bottom (build frame)
  double height() const { return height_; }                 // H
  const std::vector<double>& thicknesses() const { return thicknesses_; }
  int top_line() const { return top_line_; }
  double z_line(int k) const;                               // above the model's bottom
  // Nearest grid line to a height above the model's bottom, in [0, top_line()].
  int nearest_line(double z_rel) const;
  // The grid lines a layer [z_rel, z_rel + thickness] is estimated on (never empty: a layer
  // starting within half a step of the top still reads the last step).
  GridSpan span(double z_rel, double thickness) const;
  StackEnd stack_end(double top_rel) const;

  // Achievable-deviation estimates of several layers at once (memoized; parallel inside when
  // params.parallel; the values do not depend on it). With a finite fail_above, a layer whose
  // estimate exceeds it may stop early: its value is then only known to be > fail_above (and is
  // not exact); values <= fail_above are always exact.
  void estimate(std::span<const std::pair<GridSpan, int>> layers, std::span<double> out,
                double fail_above = std::numeric_limits<double>::infinity());
  double estimate(GridSpan span, int thickness_index);

  // The paper's two criteria for a layer of thickness_index on span.
  struct GreedyCheck {
    bool area_ok = false;
    bool triangle_ok = false;
    double area_deviation = 0.0;  // |A_top - A_bottom| / max
    double worst_triangle_mm2 = 0.0;
  };
  GreedyCheck greedy_check(GridSpan span, int thickness_index);

  // Positions only grow: caches of slices below grid line k are no longer needed. A new pass
  // of a method over the grid starts again from the bottom (restart; released caches are
  // rebuilt on demand, estimates stay memoized).
  void release_below(int k);
  void restart() { released_ = 0; }

  // What the bevel planner measured for a layer (issue 17, item 4): from then on the layer's
  // estimate is that measure (layering_verify.cpp). Returns whether it was new.
  bool set_measured(GridSpan span, int thickness_index, double deviation_mm);
  bool is_measured(GridSpan span, int thickness_index) const {
    return measured_.count(std::make_tuple(span.ka, span.kb, thickness_index)) > 0;
  }

  // The supply (layering_supply.cpp): how many layers of a thickness the rack holds (-1: no
  // limit), and whether every outer loop of a layer's sections fits one of its rooms.
  int max_layers(int thickness_index) const { return max_layers_[static_cast<std::size_t>(thickness_index)]; }
  bool fits_supply(GridSpan span, int thickness_index) const;

  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  Estimator() = default;
  struct SliceCache {
    int lo = 0, hi = -1;           // slice window the samples cover
    std::vector<Sample> samples;   // [station][slice - lo]
    bool ready = false;
  };
  double search_width(int thickness_index) const;
  int slice_count() const { return static_cast<int>(slices_.size()); }
  void ensure_samples(std::vector<int> slices);
  void fill_samples(int slice, std::size_t station);
  // Stations a layer is read at: (slice, station index within it).
  void stations_of(GridSpan span, std::vector<std::pair<int, std::uint32_t>>& out) const;
  double station_deviation(GridSpan span, int thickness_index, int slice, std::uint32_t station) const;
  const Sample& sample(int station_slice, std::uint32_t station, int at_slice) const;
  void compute_stations();
  void compute_novelty();
  void compute_supply();

  LayeringParams params_;
  std::vector<double> thicknesses_;
  double z_base_ = 0.0, height_ = 0.0, step_ = 0.0, delta_ = 0.0;
  double tan_reach_ = 1.0;        // max(tan(tilt limit), 1)
  int top_line_ = 0;
  int max_span_ = 1;              // most grid steps a layer can cover
  std::vector<Slice> slices_;
  std::vector<SectionLines> lines_;
  std::vector<double> net_area_;
  std::vector<std::uint32_t> station_begin_;  // CSR: slice → stations
  std::vector<Station> stations_;
  std::vector<char> novel_;                    // per slice: the section changes abruptly next to it
  // Per slice: an odd slice (just below an interior line) whose section equals the one just
  // above the line; its samples are read there (2δ higher) instead of querying it.
  std::vector<char> same_as_next_;
  std::vector<int> novel_list_;
  std::vector<int> max_layers_;                // per thickness
  // Per thickness with known rooms: prefix counts of slices with an outer loop no room takes
  // (empty: every slice fits), so a span's check is one subtraction.
  std::vector<std::vector<int>> misfit_prefix_;
  std::vector<SliceCache> cache_;
  int released_ = 0;                           // caches below this slice were dropped
  struct Memo {
    double value = 0.0;
    bool exact = true;
  };
  std::map<std::tuple<int, int, int>, Memo> memo_;
  std::map<std::tuple<int, int, int>, double> measured_;  // (ka, kb, thickness) → planner's measure
  std::vector<std::string> warnings_;
};

// One layer as chosen, in the model's frame relative to its bottom.
struct ChosenLayer {
  double z_rel = 0.0;
  int thickness_index = 0;
  double estimate = 0.0;  // of the surface, and for the last layer also how far it ends from the top
  bool within = true;     // the estimate (optimal) or the criteria (greedy) met
  bool surface_within = true;  // the same without the distance to the top (false: a shortfall)
};

// The layers of a method, bottom to top. Empty when the supply cannot make a stack that ends
// the model (a limited count runs out first); reached_mm is then the highest top it allows.
struct LayerChoice {
  std::vector<ChosenLayer> layers;
  double reached_mm = 0.0;
  bool state_limit = false;  // the rack's counts gave more DP states than kMaxDpStates
  std::vector<LayerPlan> plans;  // layer_verified: the chosen layers as planned (empty: not all were)
};

// More (position, usage) states than this is a rack whose counts the DP cannot search.
inline constexpr std::size_t kMaxDpStates = 4'000'000;

// Layers used per limited thickness, as one number (mixed radix over the limited thicknesses),
// so that a DP state is (position, usage) and the usage only grows.
class SupplyCounter {
 public:
  explicit SupplyCounter(const Estimator& est);
  bool limited() const { return !digit_.empty(); }
  bool can_take(std::int64_t usage, int thickness_index) const;
  std::int64_t take(std::int64_t usage, int thickness_index) const;
  std::int64_t states() const { return states_; }  // distinct usages
  bool too_many() const { return too_many_; }

 private:
  static constexpr std::int64_t kMaxUsageStates = std::int64_t{1} << 50;
  std::vector<int> digit_of_;          // per thickness: its digit, -1 unlimited
  std::vector<int> digit_;             // per digit: the thickness
  std::vector<int> cap_;
  std::vector<std::int64_t> radix_;
  std::int64_t states_ = 1;
  bool too_many_ = false;
};

LayerChoice layer_optimal(Estimator& est, const LayeringParams& params);
LayerChoice layer_greedy(Estimator& est, const LayeringParams& params);
// The optimal layering, its chosen layers planned and measured by the bevel planner until the
// choice rests on measures only (layering_verify.cpp). Errors are the planner's.
std::expected<LayerChoice, Error> layer_verified(Estimator& est, const Mesh& mesh, const LayeringParams& params);

}  // namespace lamina::layering_detail
