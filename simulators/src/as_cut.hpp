#pragma once
// What the simulated jet really cut out of a sheet (issue 20): from every jet-on block the
// controller executes (the head's tip and axis, the feed it really moved at), the kerf this
// machine's jet leaves (jet_physics.hpp) at several depths, with its taper, its trail-back (the
// jet's lower part dragged behind the nozzle, cutting inside at corners) and its cross-section
// widened by the tilt. What the kerfs enclose are the pieces the sheet falls into:
// parts, slugs and whatever else a cut closed. They are written per program as sections in the
// sheet frame (the program's X Y; depth measured down from the top face), and Lamina maps them
// back onto the CAD model (`lamina plan --as-cut`, docs/jet.md).
#include <array>
#include <cstddef>
#include <expected>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "jet_head.hpp"
#include "jet_physics.hpp"
#include "machine.hpp"

namespace lamina::sim {

struct AsCutParams {
  double sheet_thickness_mm = 10.0;
  int sections = 8;               // depths: the middles of this many equal slabs of the sheet
  double segment_mm = 0.25;       // a block is followed in steps no longer than this (5-axis moves curve; the drag)
  double width_step_mm = 0.0005;  // half widths are rounded to this (each value swept at once)
};

using Ring = std::vector<std::array<double, 2>>;  // closed, not repeated; outer CCW, holes CW

struct AsCutPiece {
  std::vector<Ring> rings;  // the outer ring first, then its holes
};

struct AsCutSection {
  double depth_mm = 0.0;  // below the sheet's top face
  std::vector<AsCutPiece> pieces;
};

struct AsCut {
  double sheet_thickness_mm = 0.0;
  std::size_t cut_blocks = 0;  // jet-on blocks that moved the tip
  std::vector<AsCutSection> sections;
};

// Cuts the program on the simulated controller. Errors name the line the controller refused, or a
// parameter out of range.
std::expected<AsCut, std::string> cut_program(std::string_view program, MachineConfig machine,
                                              const HeadGeometry& head, const JetPhysics& jet,
                                              const AsCutParams& params);

// {"format":"lamina-sim as-cut 1","program":NAME,"program_fnv1a64":HEX,"sheet_thickness_mm":…,
//  "cut_blocks":…,"sections":[{"depth_mm":…,"pieces":[[[x,y,x,y,…],[hole…]],…]},…]}
nlohmann::json as_cut_json(const AsCut& cut, std::string_view program_name, std::string_view program);

}  // namespace lamina::sim
