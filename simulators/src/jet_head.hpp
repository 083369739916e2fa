#pragma once
// Where the jet is (issue 20): the simulated machine's own head, from the axes it executes. The
// simulator never links Lamina's core (sim-machine.toml is the machine, the planner must not
// read it and the simulator must not share its code), so this is a second implementation of an
// AC tilting head, written from the machine's description rather than from kinematics.hpp: the
// nozzle hangs pivot_mm below the A/C pivot; C turns the head about the vertical, A tilts it
// about the head's own x axis. Without RTCP the programmed X Y Z are the pivot's, shifted so they
// equal the tip's at A = 0.
#include <array>

#include "gcode_block.hpp"

namespace lamina::sim {

struct HeadGeometry {
  double pivot_mm = 150.0;
  int a_sign = 1;
  int c_sign = 1;
  double c_offset_deg = 0.0;
  bool rtcp = false;  // the controller keeps the tip (the program's X Y Z are the tip's)
};

struct JetPose {
  std::array<double, 3> tip_mm{};
  std::array<double, 3> axis{};  // unit, from the tip up the jet to the nozzle
};

JetPose jet_pose(const AxisValues& axes, const HeadGeometry& head);

}  // namespace lamina::sim
