#pragma once
// Adaptive layers from stock (paper 3-1): which sheet thickness each layer of the stack is cut
// from. The paper's greedy rule is kept as a baseline; the default is a dynamic programme over a
// z grid that minimises the number of layers subject to each layer's *achievable* deviation
// (after bevelling, at the tilt limit) being within tolerance. Its grid estimates are a first
// guess: the layers it chooses are planned and measured (3-D distance, as the plan reports it)
// and the choice is made again on the measures until it stands on them (layering_verify.cpp).
// The rack (LayeringParams::supply) bounds how many layers of a thickness may be used and which
// layers a thickness's sheets can hold.
#include "lamina/core/choices.hpp"
#include "lamina/core/bevel_profile.hpp"
#include "lamina/core/error.hpp"
#include "lamina/core/mesh.hpp"
#include "lamina/core/model_index.hpp"

#include <cstdint>
#include <expected>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace lamina {

struct BevelPlan;

enum class LayeringMethod : std::uint8_t { optimal, greedy };
const ChoiceTable<LayeringMethod>& layering_methods();  // "optimal", "greedy" (choices.hpp)
const char* layering_method_name(LayeringMethod method);

// What the rack can give of one thickness (issue 17, item 5): how many layers its sheets hold,
// and the room each sheet size leaves a part (its usable length and width, after the sheet's
// margins and the kerf). A layer is only cut from this thickness if every outer loop of its
// sections fits one of those sizes (at 0° or 90°, as the nesting turns parts) — a necessary
// condition: the nesting still has the last word.
struct ThicknessSupply {
  double thickness_mm = 0.0;
  int max_layers = -1;  // -1: as many as needed
  struct Room {
    double length_mm = 0.0, width_mm = 0.0;
  };
  std::vector<Room> rooms;  // empty: the sizes are not known (no size check)
};

struct LayeringParams {
  std::vector<double> thicknesses_mm;  // stock thicknesses available (any order, > 0)
  // Limits per thickness; a thickness not listed here is not limited.
  std::vector<ThicknessSupply> supply;
  double bond_mm = 0.0;                // bonding gap between consecutive layers (adhesive)
  double sub_slice_mm = 0.5;           // z grid of the thin slices
  double tolerance_mm = 0.1;           // allowed achievable deviation per layer (optimal)
  LayeringMethod method = LayeringMethod::optimal;
  ProfileFitParams fit;                // how layers will be bevelled (side, strategy, tilt limit)
  // Greedy (paper): split while the area deviation between a layer's top and bottom contours
  // exceeds this fraction, or the staircase triangle (½·thickness·horizontal step between top
  // and bottom at a station) exceeds the allowed area (the paper's form: 0.005 in²).
  double greedy_area_deviation = 0.15;
  double greedy_triangle_area_mm2 = 3.2258;
  bool parallel = true;
  // Called as the optimal layering's verification plans each layer: done layers of the total
  // asked so far (a round that asks for more layers raises it). From the planning threads, one
  // call at a time: a progress bar's steps.
  std::function<void(int done, int total)> on_round;
  // The mesh's triangle tree, when the caller has one (a whole plan builds it once for the
  // layering and the deviation); the verification builds its own without it.
  std::shared_ptr<const ModelDistanceIndex> model_index;
};

struct LayerSpan {
  double z_bottom_mm = 0.0;
  double thickness_mm = 0.0;
  // The layering's own (grid) estimate of the achievable deviation; for the last layer it includes
  // how far the stack's top lies from the model's (a sheet 3 mm above the model is 3 mm off).
  double estimated_deviation_mm = 0.0;
  bool within_tolerance = true;  // the estimate met the tolerance (optimal) / criteria (greedy)
  // No sheet met the tolerance (criteria) here and the thinnest was used. A last layer can be out
  // of tolerance for where it ends alone: then this is false.
  bool shortfall = false;
  double z_top_mm() const { return z_bottom_mm + thickness_mm; }
};

// A z range where no stock thickness met the tolerance: the thinnest was used there.
struct Shortfall {
  double z_from_mm = 0.0, z_to_mm = 0.0;
  double deviation_mm = 0.0;  // the deviation reached with the thinnest sheet
};

struct Layering {
  std::vector<LayerSpan> layers;        // bottom to top; layer i+1 starts bond_mm above layer i's top
  double model_height_mm = 0.0;
  double stack_height_mm = 0.0;         // sheets + bonds: top of the last layer
  std::vector<Shortfall> shortfalls;
  std::vector<std::string> warnings;
  // The optimal layering plans the layers it chooses (issue 17, item 4): their bevel plan, as
  // plan_bevels(mesh, layers, BevelParams{fit, sub_slice_mm, tolerance_mm, parallel} with the
  // other fields at their defaults) would make it; null when not every layer was planned.
  std::shared_ptr<BevelPlan> plan;
};

// Errors: invalid parameters (ErrorCode::invalid_argument), and a supply that cannot make a stack
// of the model's height (ErrorCode::stock_exhausted, naming each limited thickness and how high
// the most the stock allows reaches).
std::expected<Layering, Error> choose_layers(const Mesh& mesh, const LayeringParams& params);

}  // namespace lamina
