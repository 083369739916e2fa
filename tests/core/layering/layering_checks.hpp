#pragma once
// Helpers shared by the layering tests: building meshes and the structural checks every
// layering must pass whatever the model.
#include <lamina/core/layering.hpp>
#include <lamina/core/mesh.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

namespace lamina::layering_test {

inline Mesh build(const TriangleSoup& soup) {
  auto m = build_mesh(soup, MeshParams{});
  EXPECT_TRUE(m.has_value()) << (m ? "" : m.error().message);
  return m ? std::move(*m) : Mesh{};
}

inline LayeringParams stock_params(LayeringMethod method = LayeringMethod::optimal) {
  LayeringParams p;
  p.thicknesses_mm = {1.0, 2.5, 5.0, 10.0};
  p.sub_slice_mm = 0.5;
  p.method = method;
  return p;
}

// Where a stack may end (issue 17, item 3): outside keeps the whole model (the top at or above
// the model's), inside never leaves material beyond it (at or below, and no thinnest sheet fits
// above it), mixed within half the thinnest sheet either way.
inline void expect_ends_at_the_top(const Layering& l, const LayeringParams& p, double z_bottom) {
  const double h = l.model_height_mm;
  const double thinnest = *std::min_element(p.thicknesses_mm.begin(), p.thicknesses_mm.end());
  const double top = l.layers.back().z_top_mm() - z_bottom;
  switch (p.fit.side) {
    case CutSide::outside: EXPECT_GE(top, h - 1e-6); break;
    case CutSide::inside:
      EXPECT_LE(top, h + 1e-6);
      EXPECT_GT(top + p.bond_mm + thinnest, h - 1e-6) << "a thinnest sheet still fitted above the stack";
      break;
    case CutSide::mixed: EXPECT_GE(top, h - 0.5 * thinnest - 1e-6); break;
  }
  const double off = std::abs(top - h);
  EXPECT_GE(l.layers.back().estimated_deviation_mm, off - 1e-6) << "the last layer's estimate includes where it ends";
}

// Bottom at the model's bottom, each layer one bond above the previous top, thicknesses from the
// stock, only the last layer ends the stack (expect_ends_at_the_top), stack height = last top,
// shortfalls exactly over the shortfall layers (thinnest sheet), unflagged optimal layers within
// tolerance, a layer out of tolerance that is no shortfall only at the top.
inline void expect_well_formed(const Layering& l, const LayeringParams& p, double z_bottom = 0.0) {
  ASSERT_FALSE(l.layers.empty());
  const double h = l.model_height_mm;
  const double thinnest = *std::min_element(p.thicknesses_mm.begin(), p.thicknesses_mm.end());
  EXPECT_NEAR(l.layers.front().z_bottom_mm, z_bottom, 1e-9);
  for (std::size_t i = 0; i < l.layers.size(); ++i) {
    const LayerSpan& s = l.layers[i];
    SCOPED_TRACE(::testing::Message() << "layer " << i << " at z " << s.z_bottom_mm);
    EXPECT_NE(std::find(p.thicknesses_mm.begin(), p.thicknesses_mm.end(), s.thickness_mm), p.thicknesses_mm.end());
    EXPECT_TRUE(std::isfinite(s.estimated_deviation_mm));
    EXPECT_GE(s.estimated_deviation_mm, 0.0);
    const bool last = i + 1 == l.layers.size();
    if (!last) {
      EXPECT_NEAR(l.layers[i + 1].z_bottom_mm, s.z_top_mm() + p.bond_mm, 1e-9);
      const double top = s.z_top_mm() - z_bottom;
      const double ends_from = p.fit.side == CutSide::outside ? h
                               : p.fit.side == CutSide::mixed ? h - 0.5 * thinnest
                                                              : h - p.bond_mm - thinnest;
      EXPECT_LT(top, ends_from + 1e-6) << "the stack went on after it could end";
    }
    if (p.method == LayeringMethod::optimal) {
      EXPECT_EQ(s.within_tolerance, s.estimated_deviation_mm <= p.tolerance_mm);
    }
    if (s.shortfall) {
      EXPECT_FALSE(s.within_tolerance);
      // (with a rack that limits sheets: the thinnest the rack still allows there)
      if (p.supply.empty()) {
        EXPECT_EQ(s.thickness_mm, thinnest) << "a shortfall layer uses the thinnest sheet";
      }
    } else if (!s.within_tolerance && p.method == LayeringMethod::optimal) {
      EXPECT_TRUE(last) << "only the last layer is out of tolerance without a shortfall (where it ends)";
    }
  }
  expect_ends_at_the_top(l, p, z_bottom);
  EXPECT_NEAR(l.stack_height_mm, l.layers.back().z_top_mm() - z_bottom, 1e-9);

  // Shortfalls cover exactly the runs of flagged layers.
  std::vector<Shortfall> expected;
  for (std::size_t i = 0; i < l.layers.size(); ++i) {
    const LayerSpan& s = l.layers[i];
    if (!s.shortfall) continue;
    if (i > 0 && l.layers[i - 1].shortfall) {
      expected.back().z_to_mm = s.z_top_mm();
      expected.back().deviation_mm = std::max(expected.back().deviation_mm, s.estimated_deviation_mm);
    } else {
      expected.push_back({s.z_bottom_mm, s.z_top_mm(), s.estimated_deviation_mm});
    }
  }
  ASSERT_EQ(l.shortfalls.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_NEAR(l.shortfalls[i].z_from_mm, expected[i].z_from_mm, 1e-9);
    EXPECT_NEAR(l.shortfalls[i].z_to_mm, expected[i].z_to_mm, 1e-9);
    EXPECT_NEAR(l.shortfalls[i].deviation_mm, expected[i].deviation_mm, 1e-12);
    if (p.method == LayeringMethod::optimal) {
      EXPECT_GT(l.shortfalls[i].deviation_mm, p.tolerance_mm);
    }
  }
}

inline bool has_warning(const Layering& l, const std::string& word) {
  return std::any_of(l.warnings.begin(), l.warnings.end(),
                     [&](const std::string& w) { return w.find(word) != std::string::npos; });
}

inline double max_estimate(const Layering& l) {
  double m = 0.0;
  for (const auto& s : l.layers) m = std::max(m, s.estimated_deviation_mm);
  return m;
}

}  // namespace lamina::layering_test
