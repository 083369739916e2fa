// The issue's check on three shared models (vase: convex belly and concave neck; flange: concave
// fillet, convex round, flat faces and holes; dome: a cap on a plinth): the optimal layering
// never uses more layers than the paper's greedy rule at the same tolerance.
//
// "At the same tolerance": the greedy rule does not take a tolerance, so its layers' own worst
// estimated deviation is the tolerance it achieves; the optimal layering gets exactly that.
#include "layering_checks.hpp"

#include <lamina/core/bevel.hpp>
#include <lamina/core/layering.hpp>
#include <lamina/core/mesh_io.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <optional>
#include <numbers>

namespace lamina {
namespace {

using layering_test::expect_well_formed;
using layering_test::max_estimate;
using layering_test::stock_params;

class LayeringSharedModels : public ::testing::TestWithParam<const char*> {};

// The shared model, built; nullopt when ../shared/models is absent (the caller skips).
std::optional<Mesh> shared_model(const char* name) {
  const std::filesystem::path path = std::filesystem::path(LAMINA_SHARED_MODELS) / name;
  if (!std::filesystem::exists(path)) return std::nullopt;
  auto soup = read_mesh_file(path);
  EXPECT_TRUE(soup.has_value()) << soup.error().message;
  if (!soup) return std::nullopt;
  auto mesh = build_mesh(*soup, MeshParams{});
  EXPECT_TRUE(mesh.has_value()) << mesh.error().message;
  if (!mesh) return std::nullopt;
  return std::move(*mesh);
}

TEST_P(LayeringSharedModels, OptimalNeverUsesMoreLayersThanGreedyAtTheSameTolerance) {
  const auto mesh = shared_model(GetParam());
  if (!mesh) GTEST_SKIP() << "shared model not present: " << GetParam();

  auto pg = stock_params(LayeringMethod::greedy);
  pg.fit.tilt_max_rad = 60.0 * std::numbers::pi / 180.0;
  auto greedy = choose_layers(*mesh, pg);
  ASSERT_TRUE(greedy.has_value()) << greedy.error().message;
  expect_well_formed(*greedy, pg);

  auto po = pg;
  po.method = LayeringMethod::optimal;
  po.tolerance_mm = max_estimate(*greedy);
  ASSERT_GT(po.tolerance_mm, 0.0);
  auto optimal = choose_layers(*mesh, po);
  ASSERT_TRUE(optimal.has_value()) << optimal.error().message;
  expect_well_formed(*optimal, po);

  EXPECT_LE(optimal->layers.size(), greedy->layers.size());
  EXPECT_LE(max_estimate(*optimal), po.tolerance_mm);
  EXPECT_TRUE(optimal->shortfalls.empty()) << "the greedy layering itself meets this tolerance";
  ::testing::Test::RecordProperty("greedy_layers", static_cast<int>(greedy->layers.size()));
  ::testing::Test::RecordProperty("optimal_layers", static_cast<int>(optimal->layers.size()));
  std::printf("%s: greedy %zu layers, optimal %zu layers at tolerance %.3f mm\n", GetParam(), greedy->layers.size(),
              optimal->layers.size(), po.tolerance_mm);
}

// Issue 17, item 4: per layer, the layering's estimate and the plan's measure agree within 20 %
// (the last layer's estimate also holds how far the stack ends from the model's top).
class LayeringEstimateIsMeasure : public ::testing::TestWithParam<const char*> {};

TEST_P(LayeringEstimateIsMeasure, EveryLayersEstimateIsThePlansMeasure) {
  const auto mesh = shared_model(GetParam());
  if (!mesh) GTEST_SKIP() << "shared model not present: " << GetParam();
  auto p = stock_params(LayeringMethod::optimal);
  p.tolerance_mm = 0.2;
  auto layering = choose_layers(*mesh, p);
  ASSERT_TRUE(layering.has_value()) << layering.error().message;
  BevelParams b;
  b.fit = p.fit;
  b.sub_slice_mm = p.sub_slice_mm;
  b.tolerance_mm = p.tolerance_mm;
  auto plan = plan_bevels(*mesh, layering->layers, b);
  ASSERT_TRUE(plan.has_value()) << plan.error().message;
  const double top = layering->model_height_mm;
  for (std::size_t i = 0; i < plan->layers.size(); ++i) {
    const double measure = plan->layers[i].max_deviation_mm;
    double estimate = layering->layers[i].estimated_deviation_mm;
    if (i + 1 == plan->layers.size()) {
      const double off = std::abs(layering->stack_height_mm - top);
      if (estimate <= off + 1e-9 && measure <= off) continue;  // it ends the stack: that is its estimate
    }
    EXPECT_NEAR(estimate, measure, 0.2 * std::max(measure, 0.01)) << GetParam() << " layer " << i;
  }
}

// The flange (concave fillet, convex round, flat faces, holes) and the dome (a cap on a plinth);
// the vase takes as long as both together and adds no kind of surface they lack.
INSTANTIATE_TEST_SUITE_P(Issue, LayeringEstimateIsMeasure, ::testing::Values("flange.stl", "dome.stl"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           std::string n = info.param;
                           return n.substr(0, n.find('.'));
                         });

INSTANTIATE_TEST_SUITE_P(Issue, LayeringSharedModels, ::testing::Values("vase.stl", "flange.stl", "dome.stl"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           std::string n = info.param;
                           return n.substr(0, n.find('.'));
                         });

}  // namespace
}  // namespace lamina
