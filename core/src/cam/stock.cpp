// The distinct sheet thicknesses on the rack.
#include "lamina/core/stock.hpp"

#include <algorithm>
#include <cmath>

namespace lamina {

std::vector<double> stock_thicknesses(const Stock& stock) {
  // Thicknesses that differ by no more than this are the same sheet gauge (1e-9 mm: far below
  // any real tolerance, above the noise of a value that went through a unit conversion).
  constexpr double same_mm = 1e-9;
  std::vector<double> t;
  t.reserve(stock.sheets.size());
  for (const SheetStock& s : stock.sheets)
    if (std::isfinite(s.thickness_mm)) t.push_back(s.thickness_mm);  // NaN would break the sort
  std::sort(t.begin(), t.end());
  // Collapse runs: a value within same_mm of the first of its run joins the run (no chaining).
  std::vector<double> out;
  for (double v : t) {
    if (out.empty() || v - out.back() > same_mm) out.push_back(v);
  }
  return out;
}

}  // namespace lamina
