#pragma once
// The sheet drawing an operator checks before cutting (DESIGN step 9): the sheet outline, every
// part with its number, top and bottom contours in two colours, lead-ins, pierce points,
// microjoints, dowel holes, and a legend with thickness and material. Units: 1 SVG user unit = 1 mm.
// The sheet's origin is at the drawing's bottom-left, as on the machine table (docs/sheet-svg.md).
#include "lamina/core/bevel.hpp"
#include "lamina/core/nest.hpp"
#include "lamina/core/parts.hpp"
#include "lamina/core/toolpath.hpp"

#include <span>
#include <string>

namespace lamina {

struct SheetSvgParams {
  std::string title;               // e.g. the model's file name (escaped on output)
  double estimated_time_s = 0.0;   // shown in the legend; 0: the toolpath's time.total_s
  double dowel_diameter_mm = 6.0;  // the parts' dowel holes (DowelParams::diameter_mm)
  bool show_rapids = true;         // rapids between contours as faint dotted lines
};

// An SVG 1.1 document (UTF-8) of one nested sheet. plan and parts are what the nest was made
// from; toolpath is the sheet's. Placements or contours that point outside plan/parts are skipped.
std::string sheet_svg(const BevelPlan& plan, std::span<const Part> parts, const NestedSheet& sheet,
                      const SheetToolpath& toolpath, const SheetSvgParams& params);

}  // namespace lamina
