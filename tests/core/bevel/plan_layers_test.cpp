// plan_layers_apart (the layering's verification): layers that overlap, each planned as
// plan_bevels plans it alone, whatever the indexes given and the threads.
#include "bevel/plan_layers.hpp"
#include "lamina/core/bevel.hpp"
#include "lamina/core/mesh.hpp"

#include "mesh_soups.hpp"

#include <gtest/gtest.h>

namespace lamina {
namespace {

Mesh sphere() {
  auto m = build_mesh(mesh_test::uv_sphere(50.0, 96, 48, Eigen::Vector3d(0, 0, 50)), MeshParams{});
  EXPECT_TRUE(m.has_value() && m->usable());
  return std::move(*m);
}

// Every number of the plan that a program or the report is made of.
void expect_same_layer(const LayerPlan& a, const LayerPlan& b) {
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.z_bottom_mm, b.z_bottom_mm);
  EXPECT_EQ(a.thickness_mm, b.thickness_mm);
  EXPECT_EQ(a.sub_slice_z_mm, b.sub_slice_z_mm);
  EXPECT_EQ(a.passes, b.passes);
  EXPECT_EQ(a.max_deviation_mm, b.max_deviation_mm);
  EXPECT_EQ(a.profile_deviation_mm, b.profile_deviation_mm);
  EXPECT_EQ(a.surface_distance_mm, b.surface_distance_mm);
  EXPECT_EQ(a.within_tolerance, b.within_tolerance);
  EXPECT_EQ(a.gouge_shift_mm, b.gouge_shift_mm);
  EXPECT_EQ(a.shape_counts, b.shape_counts);
  ASSERT_EQ(a.outlines.size(), b.outlines.size());
  for (std::size_t o = 0; o < a.outlines.size(); ++o) {
    const LayerOutline &x = a.outlines[o], &y = b.outlines[o];
    ASSERT_EQ(x.stations.size(), y.stations.size());
    for (std::size_t s = 0; s < x.stations.size(); ++s) EXPECT_EQ(x.stations[s].base_mm, y.stations[s].base_mm);
    ASSERT_EQ(x.passes.size(), y.passes.size());
    for (std::size_t p = 0; p < x.passes.size(); ++p)
      for (std::size_t l = 0; l < x.passes[p].lines.size(); ++l) {
        EXPECT_EQ(x.passes[p].lines[l].top_mm, y.passes[p].lines[l].top_mm);
        EXPECT_EQ(x.passes[p].lines[l].bottom_mm, y.passes[p].lines[l].bottom_mm);
      }
  }
}

TEST(PlanLayersApart, OverlappingLayersArePlannedAsEachAlone) {
  const Mesh mesh = sphere();
  // A chosen layer, the thicker sheet at its start, one inside both, and a thin one at the pole.
  const std::vector<LayerSpan> layers = {{20.0, 5.0}, {20.0, 10.0}, {22.0, 2.5}, {97.0, 3.0}};
  BevelParams params;
  params.tolerance_mm = 0.2;
  for (const bool parallel : {true, false}) {
    params.parallel = parallel;
    auto apart = bevel_detail::plan_layers_apart(mesh, {}, layers, params);
    ASSERT_TRUE(apart.has_value()) << apart.error().message;
    ASSERT_EQ(apart->size(), layers.size());
    for (std::size_t i = 0; i < layers.size(); ++i) {
      SCOPED_TRACE(i);
      auto alone = plan_bevels(mesh, std::span(&layers[i], 1), params);
      ASSERT_TRUE(alone.has_value());
      LayerPlan expected = alone->layers.front();
      expected.index = static_cast<int>(i);
      EXPECT_GT(expected.surface_distance_mm, 0.0);
      expect_same_layer((*apart)[i], expected);
    }
  }
}

TEST(PlanLayersApart, IndexesGivenOnceChangeNothing) {
  const Mesh mesh = sphere();
  const std::vector<LayerSpan> layers = {{40.0, 10.0}, {45.0, 5.0}};
  BevelParams params;
  const geometry_detail::TriangleTree tree(mesh.vertices, mesh.faces, geometry_detail::Threads::many);
  const bevel_detail::FacetsByZ facets(mesh, params.sub_slice_mm);
  auto own = bevel_detail::plan_layers_apart(mesh, {}, layers, params);
  auto given = bevel_detail::plan_layers_apart(mesh, {&tree, &facets}, layers, params);
  ASSERT_TRUE(own && given);
  for (std::size_t i = 0; i < layers.size(); ++i) expect_same_layer((*own)[i], (*given)[i]);
}

TEST(PlanLayersApart, ABadLayerIsNamed) {
  const Mesh mesh = sphere();
  const std::vector<LayerSpan> layers = {{10.0, 5.0}, {12.0, 0.0}};
  auto r = bevel_detail::plan_layers_apart(mesh, {}, layers, BevelParams{});
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(r.error().message.find("layer 1"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace lamina
