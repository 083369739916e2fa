#pragma once
// The rack as the layering sees it (issue 17, item 5): which thicknesses a layer may be cut from
// (its outlines fit a sheet of that thickness) and how many layers each thickness holds. Counts
// are learnt from the nesting: when it runs out of a thickness, that thickness is limited to the
// layers its sheets held whole and the stack is laid out again.
#include "lamina/core/layering.hpp"
#include "lamina/core/nest.hpp"
#include "lamina/core/stock.hpp"

#include <string>
#include <vector>

namespace lamina::cli {

// One entry per thickness whose sheets have a known size: the room a layer's outline has on each
// (the sheet less its margin on both sides and the kerf the part's footprint adds around the
// outline). Counts are not limited yet (max_layers = -1).
std::vector<ThicknessSupply> rack_supply(const Stock& stock, double margin_mm, double kerf_mm);

// Lowers the count of every thickness the nesting ran out of to the layers it placed whole
// (and at least one below what the layering used, so every round changes the plan), and says so
// in `warnings`. False when a shortage names a thickness the layering did not use (nothing to
// lower: the nesting's error stands).
bool lower_rack_limits(std::vector<ThicknessSupply>& supply, const std::vector<SheetShortage>& shortages,
                       const Layering& layering, const Stock& stock, std::vector<std::string>& warnings);

}  // namespace lamina::cli
