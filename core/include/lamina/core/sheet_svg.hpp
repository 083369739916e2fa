#pragma once
// The sheet drawing an operator checks before cutting (DESIGN step 9): the sheet outline, every
// part with its number, top and bottom contours in two colours, lead-ins, pierce points,
// microjoints, dowel holes, and a legend with thickness and material. Units: 1 SVG user unit = 1 mm.
#include "lamina/core/bevel.hpp"
#include "lamina/core/nest.hpp"
#include "lamina/core/parts.hpp"
#include "lamina/core/toolpath.hpp"

#include <span>
#include <string>

namespace lamina {

struct SheetSvgParams {
  std::string title;       // e.g. the model's file name
  double estimated_time_s = 0.0;
};

std::string sheet_svg(const BevelPlan& plan, std::span<const Part> parts, const NestedSheet& sheet,
                      const SheetToolpath& toolpath, const SheetSvgParams& params);

}  // namespace lamina
