// The sphere checks, end to end through the core: layering → bevel plan → deviation.
// Sphere R 50 made here (uv, 256 × 128): ten 10 mm layers with vertical outside edges leave
// 14.0 % of excess volume (analytic: π·10·2·(900+1600+2100+2400+2500) / (4/3·π·50³) − 1);
// the curved form on stock {1, 2.5, 5, 10} with the optimal layering stays within 0.3 % using
// at most 25 layers, and beats the sloped and vertical edges on the same layering.
#include "lamina/core/bevel.hpp"
#include "lamina/core/deviation.hpp"
#include "lamina/core/layering.hpp"
#include "lamina/core/mesh.hpp"

#include "mesh_soups.hpp"

#include <gtest/gtest.h>

namespace lamina {
namespace {

const Mesh& sphere() {
  static const Mesh mesh = [] {
    auto m = build_mesh(mesh_test::uv_sphere(50.0, 256, 128, Eigen::Vector3d(0, 0, 50)), MeshParams{});
    return std::move(*m);
  }();
  return mesh;
}

Deviation deviation_of(const std::vector<LayerSpan>& layers, BevelStrategy strategy) {
  BevelParams params;
  params.fit.strategy = strategy;
  auto plan = plan_bevels(sphere(), layers, params);
  EXPECT_TRUE(plan.has_value());
  auto dev = measure_deviation(sphere(), *plan, DeviationParams{});
  EXPECT_TRUE(dev.has_value());
  return *dev;
}

TEST(SpherePlan, TenVerticalLayersLeaveFourteenPercent) {
  std::vector<LayerSpan> layers;
  for (int i = 0; i < 10; ++i) layers.push_back({10.0 * i, 10.0, 0.0, true});
  const Deviation d = deviation_of(layers, BevelStrategy::vertical);
  const double analytic = 10.0 * 2 * (900 + 1600 + 2100 + 2400 + 2500) / (4.0 / 3.0 * 125000.0) - 1.0;
  EXPECT_NEAR(analytic * 100, 14.0, 0.05);
  EXPECT_NEAR(d.volume_pct, 14.0, 0.2);
  EXPECT_NEAR(d.volume_pct, analytic * 100, 0.2);
  // Outside edges only add material: stack − model = the whole symmetric difference.
  EXPECT_NEAR(d.stack_volume_mm3 - d.model_volume_mm3, d.volume_mm3, 0.01 * d.volume_mm3);
}

TEST(SpherePlan, CurvedOptimalWithinPointThreePercentInTwentyFiveLayers) {
  LayeringParams lp;
  lp.thicknesses_mm = {1, 2.5, 5, 10};
  lp.tolerance_mm = 0.3;
  auto layering = choose_layers(sphere(), lp);
  ASSERT_TRUE(layering.has_value()) << layering.error().message;
  const auto& layers = layering->layers;
  EXPECT_LE(layers.size(), 25u);
  EXPECT_GE(layering->stack_height_mm, 100.0 - 1e-9);
  const Deviation curved = deviation_of(layers, BevelStrategy::curved);
  const Deviation sloped = deviation_of(layers, BevelStrategy::sloped);
  const Deviation vertical = deviation_of(layers, BevelStrategy::vertical);
  RecordProperty("layers", static_cast<int>(layers.size()));
  std::cout << "layers " << layers.size() << ": curved " << curved.volume_pct << " %, sloped " << sloped.volume_pct
            << " %, vertical " << vertical.volume_pct << " %; max " << curved.max_mm << " mm\n";
  EXPECT_LE(curved.volume_pct, 0.3);
  EXPECT_LT(curved.volume_mm3, sloped.volume_mm3);
  EXPECT_LT(sloped.volume_mm3, vertical.volume_mm3);
  EXPECT_LT(curved.max_mm, vertical.max_mm);
}

}  // namespace
}  // namespace lamina
