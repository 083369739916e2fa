// The part as cut against the model, beside the plan (as_cut.hpp, issue 20). A 20 × 20 × 10 box
// planned as one vertical-walled layer, placed on a sheet turned by 90° and moved; the "cut"
// sections are built by hand in the sheet frame, so every answer is known: the plan's own
// sections give the planned figures back; a part cut 0.1 mm small gives its lost volume and a
// 0.1 mm distance; a piece of scrap is not taken for the part; a part missing at one depth is
// said; a sheet the record does not match is refused.
#include "hand_plans.hpp"
#include "lamina/core/as_cut.hpp"
#include "lamina/core/deviation.hpp"
#include "lamina/core/parts.hpp"
#include "mesh_checks.hpp"
#include "mesh_soups.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace lamina {
namespace {

struct BoxSheet {
  Mesh mesh;
  BevelPlan plan;
  std::vector<Part> parts;
  NestedSheet sheet;
};

BoxSheet box_on_a_sheet() {
  BoxSheet s;
  s.mesh = mesh_test::build_checked(mesh_test::box({0, 0, 0}, {20, 20, 10}));
  s.plan.layers.push_back(dev_test::make_layer(0, 0.0, 10.0, {dev_test::square_outline({10, 10}, 10, 0.0, 10.0)}));
  auto parts = make_parts(s.plan, PartParams{.kerf_mm = 1.0, .dowels = {}});
  EXPECT_TRUE(parts) << parts.error().message;
  s.parts = *parts;
  s.sheet.index = 1;
  s.sheet.thickness_mm = 10.0;
  s.sheet.width_mm = s.sheet.length_mm = 500.0;
  s.sheet.placements.push_back({0, std::numbers::pi / 2, {200.0, 100.0}});
  return s;
}

// The layer's square 0..20 shrunk by `inset` mm, in the sheet frame of placement `pl`.
Polygon2 placed_square(const Placement& pl, double inset) {
  Polygon2 ring;
  for (const Eigen::Vector2d& c : {Eigen::Vector2d(inset, inset), Eigen::Vector2d(20 - inset, inset),
                                  Eigen::Vector2d(20 - inset, 20 - inset), Eigen::Vector2d(inset, 20 - inset)})
    ring.push_back(Eigen::Rotation2Dd(pl.rotation_rad) * c + pl.offset_mm);
  return ring;
}

CutSheet cut_sheet(const BoxSheet& s, double inset, int sections = 4) {
  CutSheet c{1, 10.0, {}};
  for (int k = 0; k < sections; ++k) {
    CutSection section{(k + 0.5) * 10.0 / sections, {}};
    section.pieces.push_back({{placed_square(s.sheet.placements[0], inset)}});
    // A slug from somewhere in the scrap, and nothing of the skeleton: it is not a piece.
    section.pieces.push_back({{{{400, 400}, {410, 400}, {410, 410}, {400, 410}}}});
    c.sections.push_back(std::move(section));
  }
  return c;
}

TEST(AsCutDeviation, ThePlansOwnSectionsMeasureAsThePlan) {
  const BoxSheet s = box_on_a_sheet();
  const CutSheet cut = cut_sheet(s, 0.0);
  auto d = measure_as_cut(s.mesh, s.plan, s.parts, {&s.sheet, 1}, {&cut, 1}, AsCutParams{});
  ASSERT_TRUE(d) << d.error().message;
  ASSERT_EQ(d->layers.size(), 1u);
  EXPECT_NEAR(d->model_volume_mm3, 4000.0, 1e-3);
  EXPECT_NEAR(d->as_cut.volume_mm3, d->planned.volume_mm3, 1e-6);
  EXPECT_NEAR(d->as_cut.volume_mm3, 0.0, 1e-3);
  EXPECT_NEAR(d->as_cut.max_mm, 0.0, 1e-4);
  EXPECT_EQ(d->parts, 1);
  EXPECT_EQ(d->parts_freed, 1);
  EXPECT_TRUE(d->not_freed.empty());
}

TEST(AsCutDeviation, APartCutSmallLosesItsVolumeAndItsDistance) {
  const BoxSheet s = box_on_a_sheet();
  const CutSheet cut = cut_sheet(s, 0.1);
  auto d = measure_as_cut(s.mesh, s.plan, s.parts, {&s.sheet, 1}, {&cut, 1}, AsCutParams{});
  ASSERT_TRUE(d) << d.error().message;
  const double lost = (400.0 - 19.8 * 19.8) * 10.0;
  EXPECT_NEAR(d->as_cut.volume_mm3, lost, 1e-3);
  EXPECT_NEAR(d->as_cut.volume_pct, 100.0 * lost / 4000.0, 1e-6);
  EXPECT_NEAR(d->as_cut.max_mm, 0.1, 1e-4);
  EXPECT_NEAR(d->planned.volume_mm3, 0.0, 1e-3) << "the plan is the box";
  EXPECT_NEAR(d->layers[0].as_cut.volume_mm3, lost, 1e-3);
}

TEST(AsCutDeviation, APartMissingAtADepthIsSaidAndTheSheetMustMatch) {
  const BoxSheet s = box_on_a_sheet();
  CutSheet cut = cut_sheet(s, 0.0);
  cut.sections[3].pieces.erase(cut.sections[3].pieces.begin());  // not cut through at the bottom
  auto d = measure_as_cut(s.mesh, s.plan, s.parts, {&s.sheet, 1}, {&cut, 1}, AsCutParams{});
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_EQ(d->parts_freed, 0);
  ASSERT_EQ(d->not_freed.size(), 1u);
  EXPECT_EQ(d->not_freed[0], "L0-1 on sheet 1 at 8.75 mm");
  EXPECT_NEAR(d->as_cut.volume_mm3, 400.0 * 2.5, 1e-3) << "the bottom slab counts as missing";

  CutSheet thick = cut_sheet(s, 0.0);
  thick.thickness_mm = 12.0;
  auto refused = measure_as_cut(s.mesh, s.plan, s.parts, {&s.sheet, 1}, {&thick, 1}, AsCutParams{});
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("sheet 1 was cut 12 mm thick"), std::string::npos) << refused.error().message;
  CutSheet other = cut_sheet(s, 0.0);
  other.sheet = 2;
  refused = measure_as_cut(s.mesh, s.plan, s.parts, {&s.sheet, 1}, {&other, 1}, AsCutParams{});
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("sheet 1 is not measured"), std::string::npos) << refused.error().message;
  CutSheet deep = cut_sheet(s, 0.0);
  deep.sections.back().depth_mm = 10.5;
  refused = measure_as_cut(s.mesh, s.plan, s.parts, {&s.sheet, 1}, {&deep, 1}, AsCutParams{});
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("depth 10.5 mm"), std::string::npos) << refused.error().message;
}

}  // namespace
}  // namespace lamina

namespace lamina {
namespace {

double signed_volume_mm3(const TriangleSoup& soup) {
  double v = 0.0;
  for (std::size_t i = 0; i + 2 < soup.corners.size(); i += 3)
    v += soup.corners[i].cast<double>().dot(soup.corners[i + 1].cast<double>().cross(soup.corners[i + 2].cast<double>())) / 6.0;
  return v;
}

// `lamina plan --as-cut` writes the parts as cut as as-cut.stl: a stack of closed prisms, one per
// slab, in the build frame, holes and all, the volume the sections enclose.
TEST(AsCutMesh, EverySlabIsAClosedPrismOfItsSectionInTheBuildFrame) {
  const BoxSheet s = box_on_a_sheet();
  CutSheet cut = cut_sheet(s, 0.1);
  Polygon2 hole;  // a 3 mm square hole at 5..8 in the layer's frame, clockwise
  for (const Eigen::Vector2d& c : {Eigen::Vector2d(5, 5), Eigen::Vector2d(5, 8), Eigen::Vector2d(8, 8), Eigen::Vector2d(8, 5)})
    hole.push_back(Eigen::Rotation2Dd(s.sheet.placements[0].rotation_rad) * c + s.sheet.placements[0].offset_mm);
  for (CutSection& section : cut.sections) section.pieces[0].rings.push_back(hole);
  auto d = measure_as_cut(s.mesh, s.plan, s.parts, {&s.sheet, 1}, {&cut, 1}, AsCutParams{});
  ASSERT_TRUE(d) << d.error().message;
  ASSERT_EQ(d->slabs.size(), 4u);
  const TriangleSoup all = as_cut_mesh(d->slabs);
  EXPECT_NEAR(signed_volume_mm3(all), (19.8 * 19.8 - 9.0) * 10.0, 1e-2);
  for (const AsCutSlab& slab : d->slabs) {
    EXPECT_NEAR(slab.z_top_mm - slab.z_bottom_mm, 2.5, 1e-9);
    const TriangleSoup one = as_cut_mesh({&slab, 1});
    const Mesh m = mesh_test::build_checked(one);
    EXPECT_TRUE(m.summary.watertight) << "every edge twice, consistently wound";
    EXPECT_NEAR(signed_volume_mm3(one), (19.8 * 19.8 - 9.0) * 2.5, 1e-2) << "facing outward as written";
    for (const Eigen::Vector3d& v : m.vertices) {
      EXPECT_GE(v.x(), 0.1 - 1e-4);  // the build frame: the box's 0..20, not the sheet's 200..
      EXPECT_LE(v.x(), 19.9 + 1e-4);
    }
  }
}

}  // namespace
}  // namespace lamina
