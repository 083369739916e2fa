#pragma once
// Parts of a bevel plan (paper section 4, DESIGN "Parts and nest"): each outer outline of a layer
// together with its holes is one part, the piece that falls out of a sheet. Its footprint is what
// nesting must keep clear: every cut's top and bottom point plus half the kerf.
#include "lamina/core/bevel.hpp"
#include "lamina/core/error.hpp"
#include "lamina/core/polygon.hpp"

#include <Eigen/Core>

#include <expected>
#include <string>
#include <vector>

namespace lamina {

// Registration dowels: holes at the same XY in every layer, so the stack aligns on pins when it
// is bonded. Placed where every layer has material, as far apart as possible.
struct DowelParams {
  int count = 0;              // 0: none
  double diameter_mm = 6.0;
  double wall_mm = 3.0;       // material kept between a dowel hole and any cut of any layer
};

struct PartParams {
  double kerf_mm = 0.9;  // width of the slot the jet cuts (focusing tube ≈ 0.76–1.0 mm)
  DowelParams dowels;
};

struct Part {
  int layer_slot = 0;      // index into BevelPlan::layers
  int layer = 0;           // LayerPlan::index (what a person reads on the part: "L<layer>-<island>")
  int island = 1;          // 1-based number of the part within its layer, in outline order
  int outer = -1;          // index of the outer outline in LayerPlan::outlines
  std::vector<int> holes;  // indices of its holes in LayerPlan::outlines
  double thickness_mm = 0.0;
  double z_bottom_mm = 0.0;     // the layer's bottom in the build frame
  // In the layer's XY (build frame): the outer ring (CCW) of every cut's top and bottom points
  // offset by half the kerf — the region the part and its cuts occupy on the sheet.
  Polygon2 footprint_mm;
  double area_mm2 = 0.0;  // material of the part at its larger face (outer minus holes), for utilisation
  // The scrap inside its holes that no cut of the hole reaches on either face (every pass's top
  // and bottom ring of the hole intersected, less half the kerf), CCW rings in the layer's XY:
  // where nesting may put smaller parts. Empty rings are dropped.
  std::vector<Polygon2> free_holes_mm;
  std::vector<Eigen::Vector2d> dowels_mm;  // centres of its dowel holes (layer XY), cut as vertical holes
};

// Dowel centres (build-frame XY) for the plan: inside the material of every layer by at least
// radius + wall, spread out (farthest-point order). Error naming the shortfall when fewer fit.
std::expected<std::vector<Eigen::Vector2d>, Error> place_dowels(const BevelPlan& plan, const DowelParams& params);

// Every part of the plan, in layer order, then outline order. Fails on a plan whose outlines have
// no stations (nothing to cut) or a kerf that is not finite and ≥ 0.
std::expected<std::vector<Part>, Error> make_parts(const BevelPlan& plan, const PartParams& params);

// "L3-2": layer 3, island 2 — engraved nowhere, but printed on the SVG and in the program.
std::string part_label(const Part& part);

}  // namespace lamina
