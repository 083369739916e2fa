#pragma once
// The sheets a shop has on the rack. Layer thicknesses come from here (paper 3-1, section 5).
#include <string>
#include <vector>

namespace lamina {

struct SheetStock {
  double thickness_mm = 0.0;
  double width_mm = 0.0;   // 0 = not given (layering does not need it; nesting will)
  double length_mm = 0.0;
  int count = 0;           // sheets on the rack; 0 = not given / unlimited for planning
  std::string material;
  std::string slot;        // where the operator finds it ("R3", "rack 2 shelf B"); "" = not given
};

struct Stock {
  std::vector<SheetStock> sheets;
};

// Distinct thicknesses in ascending order (sheets of equal thickness but other sizes collapse).
std::vector<double> stock_thicknesses(const Stock& stock);

}  // namespace lamina
