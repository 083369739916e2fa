#pragma once
// What the toolpath tests share: a material the feed models know, and one hand-built layer nested
// on a 500 x 500 sheet.
#include "hand_plans.hpp"

#include <lamina/core/parts.hpp>
#include <lamina/core/toolpath.hpp>

#include <gtest/gtest.h>

#include <vector>

namespace lamina {

inline Material aluminium() {
  Material m;
  m.name = "aluminium";
  m.density_kg_per_m3 = 2700;
  m.specific_energy_j_per_m3 = 1.5e10;
  m.machinability = 213;
  return m;
}

struct Fixture {
  BevelPlan plan;
  std::vector<Part> parts;
  NestedSheet sheet;
};

inline Fixture one_part(LayerPlan layer, double rotation_rad, Eigen::Vector2d offset, double kerf = 1.0) {
  Fixture f;
  f.plan.layers.push_back(std::move(layer));
  auto parts = make_parts(f.plan, PartParams{.kerf_mm = kerf, .dowels = {}});
  EXPECT_TRUE(parts) << parts.error().message;
  f.parts = *parts;
  f.sheet.index = 1;
  f.sheet.thickness_mm = f.plan.layers[0].thickness_mm;
  f.sheet.width_mm = 500;
  f.sheet.length_mm = 500;
  for (std::size_t i = 0; i < f.parts.size(); ++i) f.sheet.placements.push_back({static_cast<int>(i), rotation_rad, offset});
  return f;
}

}  // namespace lamina
