// make_knob_step OUT.step: examples/knob.step, the demo knob (examples/knob.scad) as an exact
// B-rep written with OpenCASCADE: what `scripts/demo examples/knob.step` plans.
#include "occt_shapes.hpp"

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_knob_step OUT.step\n");
    return 2;
  }
  try {
    lamina::step_testing::write_named_step(lamina::step_testing::knob(), "knob", argv[1]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_knob_step: %s\n", e.what());
    return 1;
  }
  return 0;
}
