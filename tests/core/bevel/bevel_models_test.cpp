// The shared models (skipped when ../shared/models is absent): the vase's belly is convex and its
// neck concave, the flange's R8 fillet is concave and gets single cuts, and no cut on any model
// removes part material.
#include "lamina/core/bevel.hpp"
#include "lamina/core/mesh.hpp"
#include "lamina/core/mesh_io.hpp"

#include "bevel_checks.hpp"

#include <gtest/gtest.h>

#include <filesystem>

namespace lamina {
namespace {

std::filesystem::path model_path(const char* name) { return std::filesystem::path(LAMINA_SHARED_MODELS) / name; }

std::optional<Mesh> load(const char* name, double scale_to_mm = 1.0) {
  const auto path = model_path(name);
  if (!std::filesystem::exists(path)) return std::nullopt;
  auto soup = read_mesh_file(path.string());
  EXPECT_TRUE(soup.has_value());
  MeshParams params;
  params.scale_to_mm = scale_to_mm;
  auto mesh = build_mesh(*soup, params);
  EXPECT_TRUE(mesh.has_value());
  return std::move(*mesh);
}

int count(const LayerOutline& o, ProfileShape s) {
  int n = 0;
  for (const auto& st : o.stations) n += st.shape == s;
  return n;
}

const LayerOutline& outer(const LayerPlan& layer) {
  for (const auto& o : layer.outlines) {
    if (!o.is_hole) return o;
  }
  throw std::runtime_error("no outer outline");
}

TEST(BevelModels, VaseBellyConvexNeckConcave) {
  auto mesh = load("vase.stl");
  if (!mesh) GTEST_SKIP() << "no shared models";
  // r(z) = 34 + 13 sin(2πz/110 − 0.9): bulging out for z in (15.8, 70.8), hollow in (70.8, 125.8).
  const std::vector<LayerSpan> layers{{30, 10, 0, true}, {50, 10, 0, true}, {85, 10, 0, true}, {100, 10, 0, true}};
  const auto plan = plan_bevels(*mesh, layers, BevelParams{});
  ASSERT_TRUE(plan.has_value());
  for (int i : {0, 1}) {
    const auto& o = outer(plan->layers[static_cast<std::size_t>(i)]);
    EXPECT_GT(count(o, ProfileShape::convex), static_cast<int>(o.stations.size()) * 9 / 10) << "belly layer " << i;
    EXPECT_EQ(o.passes.size(), plan->layers[static_cast<std::size_t>(i)].sub_slice_z_mm.size());
  }
  for (int i : {2, 3}) {
    const auto& o = outer(plan->layers[static_cast<std::size_t>(i)]);
    EXPECT_GT(count(o, ProfileShape::concave), static_cast<int>(o.stations.size()) * 9 / 10) << "neck layer " << i;
    EXPECT_EQ(o.passes.size(), 1u) << "a concave span is one cut, top point to bottom point";
  }
  const auto removed = bevel_test::material_removed(*mesh, *plan, 1e-3);
  EXPECT_EQ(removed.inside, 0u) << removed.first;
}

TEST(BevelModels, FlangeFilletIsConcaveAndCutOnce) {
  auto mesh = load("flange.stl");
  if (!mesh) GTEST_SKIP() << "no shared models";
  // Disc to z 12, R8 fillet from the disc (r 33) up to the hub wall (r 25) at z 20, hub to 45.
  const std::vector<LayerSpan> layers{{0, 12, 0, true}, {12, 4, 0, true}, {16, 4, 0, true}, {20, 25, 0, true}};
  const auto plan = plan_bevels(*mesh, layers, BevelParams{});
  ASSERT_TRUE(plan.has_value());
  for (int i : {1, 2}) {
    const auto& layer = plan->layers[static_cast<std::size_t>(i)];
    const auto& o = outer(layer);
    EXPECT_GT(count(o, ProfileShape::concave), static_cast<int>(o.stations.size()) * 9 / 10) << "fillet layer " << i;
    EXPECT_EQ(o.passes.size(), 1u);
    for (const auto& l : o.passes[0].lines) {
      EXPECT_GT(l.tilt_rad, 0.1);
      EXPECT_LT(l.tool_axis.head<2>().dot(l.bottom_mm.head<2>().normalized()), 0.0) << "leans towards the hub";
    }
  }
  // The hub and the bore are vertical; the disc's outer rim (R3 round) is convex.
  for (const auto& l : outer(plan->layers[3]).passes[0].lines) EXPECT_LT(l.tilt_rad, 0.02);
  EXPECT_GT(count(outer(plan->layers[0]), ProfileShape::convex), 0);
  const auto removed = bevel_test::material_removed(*mesh, *plan, 1e-3);
  EXPECT_EQ(removed.inside, 0u) << removed.first;
}

struct NoRemovalCase {
  const char* file;
  double scale_to_mm;
};

class NoCutRemovesMaterial : public ::testing::TestWithParam<NoRemovalCase> {};

TEST_P(NoCutRemovesMaterial, SampledAlongEveryCutLine) {
  auto mesh = load(GetParam().file, GetParam().scale_to_mm);
  if (!mesh) GTEST_SKIP() << "no shared models";
  const double height = mesh->summary.bbox_max_mm.z() - mesh->summary.bbox_min_mm.z();
  const double diag = (mesh->summary.bbox_max_mm - mesh->summary.bbox_min_mm).norm();
  BevelParams params;
  params.sub_slice_mm = height / 60.0;
  params.station_spacing_mm = diag / 200.0;
  for (BevelStrategy s : {BevelStrategy::curved, BevelStrategy::sloped}) {
    params.fit.strategy = s;
    const auto plan = plan_bevels(*mesh, bevel_test::uniform_layers(height, height / 7.0), params);
    ASSERT_TRUE(plan.has_value());
    const auto removed = bevel_test::material_removed(*mesh, *plan, 1e-5 * diag + 1e-4);
    EXPECT_GT(removed.points, 1000u);
    EXPECT_EQ(removed.inside, 0u) << bevel_strategy_name(s) << ": " << removed.first << " of " << removed.points;
  }
}

INSTANTIATE_TEST_SUITE_P(SharedModels, NoCutRemovesMaterial,
                         ::testing::Values(NoRemovalCase{"vase.stl", 1}, NoRemovalCase{"flange.stl", 1}, NoRemovalCase{"dome.stl", 1},
                                           NoRemovalCase{"openscad_example001.stl", 1}, NoRemovalCase{"openscad_example006.stl", 1},
                                           NoRemovalCase{"openscad_example024.stl", 1}, NoRemovalCase{"torus.STL", 1},
                                           NoRemovalCase{"quadknot.stl", 1}, NoRemovalCase{"spot.stl", 1},
                                           NoRemovalCase{"featuretype.STL", 25.4}, NoRemovalCase{"plate_holes.STL", 1},
                                           NoRemovalCase{"fixed_top.stl", 1}, NoRemovalCase{"busted.STL", 1},
                                           NoRemovalCase{"HalfDonut_binary.stl", 1}),
                         [](const auto& info) {
                           std::string n = info.param.file;
                           for (char& c : n) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return n;
                         });

}  // namespace
}  // namespace lamina
