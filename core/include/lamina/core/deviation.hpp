#pragma once
// How far the layered part (as cut) is from the CAD model: the volume of their symmetric
// difference, integrated from Clipper XOR areas of fine horizontal sections, and the largest
// distance between the two surfaces.
#include "lamina/core/bevel.hpp"
#include "lamina/core/error.hpp"
#include "lamina/core/mesh.hpp"
#include "lamina/core/polygon.hpp"

#include <Eigen/Core>

#include <expected>
#include <vector>

namespace lamina {

// The material a layer keeps at height z (z inside the layer): every outline's ring at that
// height, cleaned (self-overlaps and collapsed parts removed). Outer rings CCW, holes CW.
std::vector<Polygon2> layer_section(const LayerPlan& layer, double z_mm);

struct DeviationParams {
  double step_mm = 0.1;             // spacing of the sections integrated over z
  double distance_sample_mm = 0.5;  // spacing of the surface points used for the largest distance
  bool parallel = true;
};

struct Deviation {
  double model_volume_mm3 = 0.0;
  double stack_volume_mm3 = 0.0;
  double volume_mm3 = 0.0;   // symmetric difference
  double volume_pct = 0.0;   // of the model's volume
  double max_mm = 0.0;       // largest distance between stack and model surfaces (both ways)
};

std::expected<Deviation, Error> measure_deviation(const Mesh& mesh, const BevelPlan& plan,
                                                  const DeviationParams& params);

}  // namespace lamina
