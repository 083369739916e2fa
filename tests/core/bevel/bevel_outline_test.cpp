// The layer outline's simplification (BevelParams::outline_simplify_mm): a finely tessellated
// model gets stations spaced by the station spacing, not one at each of its corners, standing
// off the material, and the cut is as near the model as the one from every corner.
#include "lamina/core/bevel.hpp"
#include "lamina/core/mesh.hpp"
#include "lamina/core/mesh_io.hpp"

#include "bevel_checks.hpp"
#include "mesh_checks.hpp"
#include "revolve.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>

namespace lamina {
namespace {

using test_shapes::revolve;

Mesh built_usable(const TriangleSoup& soup) {
  Mesh m = mesh_test::build_checked(soup);
  EXPECT_TRUE(m.usable());
  return m;
}

BevelPlan planned_with(const Mesh& mesh, const std::vector<LayerSpan>& layers, const BevelParams& p) {
  auto r = plan_bevels(mesh, layers, p);
  EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message);
  if (!r) return {};
  return std::move(*r);
}

std::size_t station_count(const BevelPlan& p) {
  std::size_t n = 0;
  for (const LayerPlan& l : p.layers)
    for (const LayerOutline& o : l.outlines) n += o.stations.size();
  return n;
}

TEST(BevelOutline, AFineConeGetsStationsAStationSpacingApartOffItsMaterial) {
  // A frustum R 30 → 25 over 10 mm in 2000 facets round: 0.094 mm between corners.
  constexpr int kCorners = 2000;
  const Mesh mesh = built_usable(revolve({{0, 0}, {30, 0}, {25, 10}, {0, 10}}, kCorners));
  const std::vector<LayerSpan> layer{{0.0, 10.0, 0.0, true}};
  const BevelParams simplified;
  BevelParams every_corner;
  every_corner.outline_simplify_mm = 0.0;
  const BevelPlan fewer = planned_with(mesh, layer, simplified), all = planned_with(mesh, layer, every_corner);
  ASSERT_EQ(fewer.layers.size(), 1u);
  ASSERT_EQ(all.layers.size(), 1u);
  EXPECT_TRUE(fewer.layers[0].outline_simplified);
  EXPECT_FALSE(all.layers[0].outline_simplified);
  EXPECT_GE(station_count(all), static_cast<std::size_t>(kCorners));
  // Round R 30: chords of ~1.1 mm (0.005 mm off the arc), then stations every 1 mm at most.
  const double perimeter = 2.0 * std::numbers::pi * 30.0;
  EXPECT_LT(station_count(fewer), static_cast<std::size_t>(kCorners / 4));
  EXPECT_GE(station_count(fewer), static_cast<std::size_t>(perimeter / simplified.station_spacing_mm));

  // Off the material (the bottom section is the widest), by at most twice the simplification.
  const double r_inscribed = 30.0 * std::cos(std::numbers::pi / kCorners);
  for (const LayerOutline& o : fewer.layers[0].outlines)
    for (const CutStation& st : o.stations) {
      EXPECT_GE(st.base_mm.norm(), r_inscribed - 1e-6);
      EXPECT_LE(st.base_mm.norm(), 30.0 + 2.0 * simplified.outline_simplify_mm + 1e-3);
    }
  // No cut takes part material, and the cut is as near the model as the one from every corner.
  const auto removed = bevel_test::material_removed(mesh, fewer, 1e-3);
  EXPECT_EQ(removed.inside, 0u) << removed.first;
  EXPECT_TRUE(fewer.layers[0].within_tolerance);
  EXPECT_NEAR(fewer.layers[0].max_deviation_mm, all.layers[0].max_deviation_mm, 2.0 * simplified.outline_simplify_mm);
}

TEST(BevelOutline, ACoarseModelKeepsEveryCorner) {
  // 96 facets round: a corner every 2 mm, 0.05 mm off the chord of its neighbours.
  const Mesh mesh = built_usable(revolve({{0, 0}, {30, 0}, {25, 10}, {0, 10}}, 96));
  const std::vector<LayerSpan> layer{{0.0, 10.0, 0.0, true}};
  BevelParams every_corner;
  every_corner.outline_simplify_mm = 0.0;
  const BevelPlan a = planned_with(mesh, layer, BevelParams{}), b = planned_with(mesh, layer, every_corner);
  ASSERT_EQ(a.layers.size(), 1u);
  ASSERT_EQ(b.layers.size(), 1u);
  EXPECT_FALSE(a.layers[0].outline_simplified);
  EXPECT_EQ(station_count(a), station_count(b));
  EXPECT_EQ(a.layers[0].max_deviation_mm, b.layers[0].max_deviation_mm);
}

TEST(BevelOutline, ALayerThatJustMissesTheToleranceIsCutFromEveryCorner) {
  // Spot (a low-poly cow 1.7 units tall, read as mm): its second 1 mm layer from a simplified
  // outline measured 0.259 mm against the 0.2 tolerance; cut from every corner, 0.194.
  const auto path = std::filesystem::path(LAMINA_SHARED_MODELS) / "spot.stl";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "no shared models";
  auto soup = read_mesh_file(path.string());
  ASSERT_TRUE(soup.has_value());
  auto mesh = build_mesh(*soup, MeshParams{});
  ASSERT_TRUE(mesh.has_value());
  const double z0 = mesh->summary.bbox_min_mm.z();
  BevelParams p;
  p.tolerance_mm = 0.2;
  const BevelPlan cut = planned_with(*mesh, {{z0, 1.0, 0.0, true}, {z0 + 1.0, 1.0, 0.0, true}}, p);
  ASSERT_EQ(cut.layers.size(), 2u);
  EXPECT_TRUE(cut.layers[1].within_tolerance) << cut.layers[1].max_deviation_mm;
  p.outline_simplify_mm = 0.0;
  const BevelPlan whole = planned_with(*mesh, {{z0, 1.0, 0.0, true}, {z0 + 1.0, 1.0, 0.0, true}}, p);
  ASSERT_EQ(whole.layers.size(), 2u);
  EXPECT_LE(cut.layers[1].max_deviation_mm, whole.layers[1].max_deviation_mm + 1e-9);
}

}  // namespace
}  // namespace lamina
