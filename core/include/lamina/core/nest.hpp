#pragma once
// Nesting parts on stock sheets (paper section 4 + true-shape nesting). Sheets of one thickness
// take the parts of the layers of that thickness; thin sheets come first (the paper cuts thin
// before thick). A placement maps a part's layer XY into the sheet frame:
//   sheet_xy = R(rotation_rad) · layer_xy + offset_mm
// Sheet frame: origin at the sheet's corner, x along its length, y along its width.
#include "lamina/core/choices.hpp"
#include "lamina/core/error.hpp"
#include "lamina/core/parts.hpp"
#include "lamina/core/stock.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <expected>
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace lamina {

enum class NestMethod : std::uint8_t { matrix, shape };
const ChoiceTable<NestMethod>& nest_methods();  // "shape", "matrix" (choices.hpp)
const char* nest_method_name(NestMethod method);

struct NestParams {
  NestMethod method = NestMethod::matrix;
  double spacing_mm = 6.0;   // clear gap between part footprints (leads and pierces of outer loops sit in it)
  double margin_mm = 10.0;   // clear band along the sheet's edges (clamps, the skeleton's frame)
  // Rotations tried by shape nesting, degrees at the edge, radians here. Matrix nesting uses 0 or 90°.
  std::vector<double> rotations_rad{0.0, 1.5707963267948966, 3.141592653589793, 4.71238898038469};
  bool parallel = true;
  // Put smaller parts inside the free holes (Part::free_holes_mm) of larger ones before packing,
  // at least spacing_mm from the hole's free ring and from each other (docs/nesting.md).
  bool fill_holes = true;
  // Called once for each part placed, in a hole or on a sheet, as it is placed (the progress of a
  // nest that takes minutes); from any thread, never two at once for one thickness, but the
  // thicknesses nest side by side. A part placed on a sheet beyond the stock's count is placed
  // again on the next kind of sheet, and counted again.
  std::function<void()> on_placed;
};

struct Placement {
  int part = -1;              // index into the parts span given to nest_parts
  double rotation_rad = 0.0;  // about +Z, applied before offset_mm
  Eigen::Vector2d offset_mm = Eigen::Vector2d::Zero();
  // Index in the sheet's placements of the part in whose free hole this one lies (-1: none).
  // The host's hole cut frees the slug this part sits on, so this part must be cut completely
  // before any cut of its host.
  int host = -1;
};

struct NestedSheet {
  int index = 0;             // 1-based, in cutting order (thin before thick)
  int stock_index = -1;      // which Stock::sheets entry it was taken from
  double thickness_mm = 0.0;
  double width_mm = 0.0;     // sheet y extent
  double length_mm = 0.0;    // sheet x extent
  std::string material;
  std::string slot;          // the rack slot of its stock entry; "" = not given
  // In the order the parts are numbered on the sheet. A part inside another's hole comes before
  // its host (children first, then the host, recursively), and the cutting order must keep that:
  // a placement is cut completely before placements[host] (Placement::host).
  std::vector<Placement> placements;
  double utilisation = 0.0;  // area of all its parts (those in holes too) / sheet area
};

struct Nest {
  std::vector<NestedSheet> sheets;
};

// A thickness the rack has too few sheets of (issue 17, item 5): how many of its layers found a
// place for every one of their parts on the sheets there are. The planner lowers that
// thickness's count in the layering to what was placed and lays the stack out again.
struct SheetShortage {
  double thickness_mm = 0.0;
  int layers = 0;         // layers (Part::layer_slot) of this thickness among the parts
  int layers_placed = 0;  // of them, those whose parts were all placed
};

// Place every part on a sheet of its thickness. Errors (ErrorCode::invalid_argument) name the
// thickness and what is missing: no sheet of that thickness, a sheet without a known size, a part
// larger than every sheet of its thickness, or not enough sheets (count) for all its parts.
// A stock count of 0 means the count is not known: as many sheets as needed. Too few sheets is
// ErrorCode::stock_exhausted; then, when `shortages` is given, it receives one entry for every
// thickness that ran out (not only the one the error names).
std::expected<Nest, Error> nest_parts(std::span<const Part> parts, const Stock& stock, const NestParams& params,
                                      std::vector<SheetShortage>* shortages = nullptr);

// A part's footprint placed on its sheet.
Polygon2 placed_footprint(const Part& part, const Placement& placement);
Eigen::Vector2d place_point(const Placement& placement, const Eigen::Vector2d& layer_xy);

}  // namespace lamina
