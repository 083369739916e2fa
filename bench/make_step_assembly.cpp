// make_step_assembly OUT.step N: a STEP (AP214, mm) assembly of N distinct parts for the reader's
// size benchmark (docs/performance.md, "STEP: a 50 MB assembly"). Every part is its own product
// (a plate with filleted edges, a tube or a filleted block, each of its own size), so the file
// grows with N (about 25 KB a part) rather than repeating one product by reference, as a real
// machine's assembly of many different parts does. Parts stand 100 mm apart on a grid 40 wide
// (the largest is 82 mm long at N = 1050): no two overlap.
#include "occt_shapes.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <exception>
#include <string>
#include <vector>

using namespace lamina::step_testing;

namespace {

TopoDS_Shape part_number(int i) {
  const double s = 1.0 + 0.001 * i;  // each its own size: no two products alike
  switch (i % 3) {
    case 0: return filleted_box(40 * s, 25 * s, 6, 1.5);
    case 1: return tube(8 * s, 5 * s, 20);
    default: return filleted_box(15 * s, 15 * s, 15 * s, 3);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: make_step_assembly OUT.step PARTS\n");
    return 2;
  }
  try {
    const int n = std::stoi(argv[2]);
    std::vector<PlacedPart> parts;
    for (int i = 0; i < n; ++i)
      parts.push_back({fmt::format("part {}", i + 1), part_number(i), 100.0 * (i % 40), 100.0 * (i / 40), 0});
    write_assembly_of(parts, argv[1]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_step_assembly: %s\n", e.what());
    return 1;
  }
  return 0;
}
