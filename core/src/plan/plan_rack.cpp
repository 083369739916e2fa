// The rack as the layering sees it (issue 17, item 5): which thicknesses a layer may be cut from
// (its outlines fit a sheet of that thickness) and how many layers each thickness holds. Counts
// are learnt from the nesting: when it runs out of a thickness, that thickness is limited to the
// layers its sheets held whole and the stack is laid out again.
#include "lamina/core/plan_job.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace lamina {
namespace {

constexpr double kSameThicknessMm = 1e-9;

ThicknessSupply* find_supply(std::vector<ThicknessSupply>& supply, double thickness_mm) {
  for (ThicknessSupply& s : supply)
    if (std::abs(s.thickness_mm - thickness_mm) <= kSameThicknessMm) return &s;
  return nullptr;
}

std::string sheets_of(const Stock& stock, double thickness_mm) {
  std::string text;
  for (const SheetStock& s : stock.sheets)
    if (std::abs(s.thickness_mm - thickness_mm) <= kSameThicknessMm)
      text += fmt::format("{}{} of {:g} x {:g} mm", text.empty() ? "" : ", ", s.count, s.length_mm, s.width_mm);
  return text;
}

}  // namespace

std::vector<ThicknessSupply> rack_supply(const Stock& stock, double margin_mm, double kerf_mm) {
  std::vector<ThicknessSupply> supply;
  for (const SheetStock& s : stock.sheets) {
    if (!(s.width_mm > 0.0) || !(s.length_mm > 0.0)) continue;
    ThicknessSupply* entry = find_supply(supply, s.thickness_mm);
    if (!entry) {
      supply.push_back(ThicknessSupply{s.thickness_mm, -1, {}});
      entry = &supply.back();
    }
    const double length = std::max(s.length_mm, s.width_mm) - 2 * margin_mm - kerf_mm;
    const double width = std::min(s.length_mm, s.width_mm) - 2 * margin_mm - kerf_mm;
    entry->rooms.push_back({std::max(0.0, length), std::max(0.0, width)});
  }
  return supply;
}

bool lower_rack_limits(std::vector<ThicknessSupply>& supply, const std::vector<SheetShortage>& shortages,
                       const Layering& layering, const Stock& stock, std::vector<std::string>& warnings) {
  bool lowered = false;
  for (const SheetShortage& short_of : shortages) {
    const int used = static_cast<int>(std::count_if(layering.layers.begin(), layering.layers.end(), [&](const LayerSpan& l) {
      return std::abs(l.thickness_mm - short_of.thickness_mm) <= kSameThicknessMm;
    }));
    if (used == 0) continue;
    ThicknessSupply* s = find_supply(supply, short_of.thickness_mm);
    if (!s) {
      supply.push_back(ThicknessSupply{short_of.thickness_mm, -1, {}});
      s = &supply.back();
    }
    const int cap = std::clamp(short_of.layers_placed, 0, used - 1);
    if (s->max_layers >= 0 && s->max_layers <= cap) continue;
    s->max_layers = cap;
    lowered = true;
    warnings.push_back(fmt::format("the rack's {} mm sheets ({}) hold {} of the {} layer(s) the stack first took of "
                                   "them: the layers were chosen again with at most {}",
                                   short_of.thickness_mm, sheets_of(stock, short_of.thickness_mm),
                                   short_of.layers_placed, used, cap));
  }
  return lowered;
}

}  // namespace lamina
