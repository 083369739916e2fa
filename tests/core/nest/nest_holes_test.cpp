// Hole filling: smaller parts inside the free holes of larger ones (both methods). The geometry
// (inner-fit and no-fit regions) is checked against brute force; the nests against check_nest,
// which lets a footprint overlap another only inside that part's free holes, and before it.
#include "nest_checks.hpp"

// Private headers of lamina_core: the hole filler and its polygon algebra alone.
#include "cam/nest_fit.hpp"
#include "cam/nest_internal.hpp"

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <numbers>
#include <random>

namespace lamina {
namespace {

using namespace nest_test;
using ClipperLib::Path;
using ClipperLib::Paths;

// A ring as make_parts gives it: footprint the outer disc, one free hole inside.
Part ring_part(double r_out, double r_free, int layer, double thickness = 3.0, int n = 96, double cx = 0, double cy = 0) {
  Part p = make_part(circle(r_out, n, cx, cy), thickness, layer, 1, std::numbers::pi * r_free * r_free);
  p.free_holes_mm.push_back(circle(r_free, n, cx, cy));
  return p;
}

NestParams with(NestMethod m, bool fill = true, double spacing = 6.0, double margin = 10.0) {
  NestParams p;
  p.method = m;
  p.spacing_mm = spacing;
  p.margin_mm = margin;
  p.fill_holes = fill;
  p.parallel = false;
  return p;
}

bool point_in(const Paths& region, ClipperLib::IntPoint q) {
  int winding = 0;  // non-zero rule over the region's rings (outer CCW, holes CW)
  for (const Path& p : region) {
    const int in = ClipperLib::PointInPolygon(q, p);
    if (in == -1) return true;
    if (in == 1) winding += ClipperLib::Orientation(p) ? 1 : -1;
  }
  return winding != 0;
}

double area_of(const Paths& a) { return nest_test::area_mm2(a); }

Paths clip(ClipperLib::ClipType op, const Paths& a, const Paths& b) { return cam_detail::boolean(op, a, b); }

// Random t: C + t inside the room exactly when t is in inner_fit (away from the region's edge,
// where rounding to nm decides); C + t overlaps G exactly when t is in G ⊕ (−C).
void brute_force(const Paths& room, const Path& c, const Path& g, std::mt19937& rng, const char* what) {
  SCOPED_TRACE(what);
  const Paths fit = cam_detail::inner_fit(room, c);
  const Paths nfp = cam_detail::minkowski_sum(g, cam_detail::negated(c));
  const Paths fit_edge = cam_detail::offset_mitre(fit, 1e-3);
  const Paths fit_core = cam_detail::offset_mitre(fit, -1e-3);
  const Paths nfp_edge = cam_detail::offset_mitre(nfp, 1e-3);
  const Paths nfp_core = cam_detail::offset_mitre(nfp, -1e-3);
  std::uniform_real_distribution<double> u(-150.0, 150.0);
  int inside = 0, overlapping = 0;
  for (int k = 0; k < 400; ++k) {
    const ClipperLib::IntPoint t{std::llround(u(rng) * kNm), std::llround(u(rng) * kNm)};
    const Paths moved{cam_detail::translated(c, t)};
    const bool in_room = area_of(clip(ClipperLib::ctDifference, moved, room)) == 0.0;
    if (point_in(fit_core, t) || !point_in(fit_edge, t)) {
      EXPECT_EQ(in_room, point_in(fit, t)) << "t = " << t.X * 1e-6 << ", " << t.Y * 1e-6;
      inside += in_room;
    }
    const bool overlaps = area_of(clip(ClipperLib::ctIntersection, moved, {g})) > 0.0;
    if (point_in(nfp_core, t) || !point_in(nfp_edge, t)) {
      EXPECT_EQ(overlaps, point_in(nfp, t)) << "t = " << t.X * 1e-6 << ", " << t.Y * 1e-6;
      overlapping += overlaps;
    }
  }
  EXPECT_GT(inside, 0) << "the samples should hit the inner-fit region";
  EXPECT_GT(overlapping, 0) << "the samples should hit the no-fit region";
}

TEST(NestFit, InnerFitAndNoFitRegionsMatchBruteForce) {
  std::mt19937 rng(5);
  const Path disc = to_path(circle(120, 40));
  const Path square = to_path(rect(60, 60, -30, -30));
  const Path l_shape = to_path(ell(70, 50, 20, -10, -10));
  // A concave room: a U (the L's mirror images joined), and a convex one.
  const Path u_room = to_path({{-140, -140}, {140, -140}, {140, 140}, {60, 140}, {60, -40}, {-60, -40}, {-60, 140}, {-140, 140}});
  brute_force({disc}, square, l_shape, rng, "convex room, convex C");
  brute_force({disc}, l_shape, square, rng, "convex room, concave C");
  brute_force({u_room}, l_shape, l_shape, rng, "concave room, concave C and G");
  brute_force({u_room}, square, to_path(triangle(50, 40)), rng, "concave room, convex C");
}

TEST(NestFit, ConvexShortcutEqualsTheGeneralFormula) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> r(20.0, 60.0);
  for (int k = 0; k < 20; ++k) {
    const Path room = to_path(circle(100.0 + r(rng), 7 + k));
    const Path c = ClipperLib::Path(cam_detail::convex_hull(to_path(circle(r(rng), 3 + k % 9, r(rng) - 40, 3.0))));
    const Paths a = cam_detail::inner_fit({room}, c);
    const Paths b = cam_detail::inner_fit_general({room}, c);
    ASSERT_FALSE(a.empty());
    const double xor_area = area_of(clip(ClipperLib::ctXor, a, b));
    EXPECT_LT(xor_area, 1e-4) << "case " << k << ": areas " << area_of(a) << " vs " << area_of(b);
  }
}

TEST(NestFit, InnerProxyOfANearlyConvexHoleIsInsideItAndSmall) {
  // A 400-gon hole (R 80) with corners pushed in by up to 20 µm (nearly convex, as faceted holes
  // come out of slicing and Clipper), and one with a real 5 mm notch.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> dent(0.0, 0.02);
  Polygon2 noisy = circle(80, 400);
  for (auto& p : noisy) p *= 1.0 - dent(rng) / 80.0;
  const Path ring = to_path(noisy);
  ASSERT_FALSE(cam_detail::is_convex(ring));
  const Path proxy = cam_detail::inner_proxy(ring);
  EXPECT_LE(proxy.size(), 64u);
  EXPECT_EQ(area_of(clip(ClipperLib::ctDifference, {proxy}, {ring})), 0.0) << "the proxy must lie inside the hole";
  // It gives up little: a 64-gon in the R 80 circle, less the 20 µm pockets.
  EXPECT_GT(area_of({proxy}), 0.99 * area_of({ring}));

  // A square hole with 400 corners along its edges, dented in by up to 20 µm: its hull is the
  // square itself, which the dents cut into — only the erosion keeps the proxy inside.
  Polygon2 dented;
  for (int side = 0; side < 4; ++side)
    for (int k = 0; k < 100; ++k) {
      const double t = k / 100.0;
      const Eigen::Vector2d a[4] = {{0, 0}, {100, 0}, {100, 100}, {0, 100}};
      const Eigen::Vector2d p = a[side] + t * (a[(side + 1) % 4] - a[side]);
      const Eigen::Vector2d inward = Eigen::Vector2d(50, 50) - p;
      dented.push_back(k == 0 ? p : Eigen::Vector2d(p + dent(rng) * inward.normalized()));
    }
  const Path square_ring = to_path(dented);
  const Path square_proxy = cam_detail::inner_proxy(square_ring);
  EXPECT_EQ(area_of(clip(ClipperLib::ctDifference, {square_proxy}, {square_ring})), 0.0);
  EXPECT_GT(area_of({square_proxy}), 0.999 * 100 * 100);

  Polygon2 notched = circle(80, 400);
  for (int i = 0; i < 5; ++i) notched[static_cast<std::size_t>(i)] *= 75.0 / 80.0;
  const Path deep = to_path(notched);
  // A real pocket: not convex, so the ring simplified inwards (a room's corners multiply the
  // inner fit's cost): inside it, within 75 µm of it, fewer corners.
  const Path deep_proxy = cam_detail::inner_proxy(deep);
  EXPECT_LT(deep_proxy.size(), deep.size() / 2);
  EXPECT_EQ(area_of(clip(ClipperLib::ctDifference, {deep_proxy}, {deep})), 0.0) << "the proxy must lie inside the hole";
  EXPECT_EQ(area_of(clip(ClipperLib::ctDifference, cam_detail::offset_mitre({deep}, -0.075), {deep_proxy})), 0.0)
      << "nowhere more than 75 µm inside";
}

// Before a ring of 2·10¹⁶ nm² could be simplified at all, is_simple compared the areas in nm²
// to 1, below a double's step there (4): a Ø160 mm hole was never simplified inwards.
TEST(NestFit, SimplifiedInsideOfALargeRoundRoomHasFewerCorners) {
  const Path ring = to_path(circle(80, 400));
  const Path s = cam_detail::simplified_inside(ring);
  EXPECT_LT(s.size(), ring.size() / 2);
  EXPECT_EQ(area_of(clip(ClipperLib::ctDifference, {s}, {ring})), 0.0);
  EXPECT_EQ(cam_detail::simplified_outside(ring).size() < ring.size() / 2, true);
}

// A U of many corners, as a layer of a vase cut along its axis comes out: two round-ended walls
// joined by a curved floor (concave, far from its hull).
Path vase_u(int n, double scale = 1.0) {
  Polygon2 u;
  for (int k = 0; k <= n; ++k) {  // outer arc, then the inner arc back
    const double a = std::numbers::pi * (1.0 + static_cast<double>(k) / n);
    u.emplace_back(60.0 * scale * std::cos(a), 60.0 * scale * std::sin(a));
  }
  for (int k = n; k >= 0; --k) {
    const double a = std::numbers::pi * (1.0 + static_cast<double>(k) / n);
    u.emplace_back(45.0 * scale * std::cos(a), 45.0 * scale * std::sin(a) + 5.0 * scale);
  }
  return to_path(u);
}

TEST(NestFit, SimplifiedOutsideHoldsTheRingCloselyWithFewerCorners) {
  const Path u = vase_u(300);
  ASSERT_FALSE(cam_detail::is_convex(u));
  const Path s = cam_detail::simplified_outside(u);
  EXPECT_LT(s.size(), u.size() / 2) << "the many corners of the arcs should go";
  EXPECT_EQ(area_of(clip(ClipperLib::ctDifference, {u}, {s})), 0.0) << "the proxy must hold the ring";
  // No farther out than 75 µm anywhere: inside the ring grown by that much.
  EXPECT_EQ(area_of(clip(ClipperLib::ctDifference, {s}, cam_detail::offset_mitre({u}, 0.075))), 0.0);
  EXPECT_EQ(cam_detail::outer_proxy(u), s);  // the U is far from its hull: outer_proxy simplifies it
}

TEST(NestFit, WithoutNoFitEqualsSubtractingEachNoFitRegion) {
  // Concave and convex children and candidates, the fit region small and large: the windowed,
  // un-united pieces take exactly what the whole no-fit regions take.
  const Path big = cam_detail::convex_hull(to_path(circle(140, 64)));
  const Path u = vase_u(40, 0.5);
  const Path l_shape = to_path(ell(30, 20, 8, -10, -10));
  const std::vector<Path> children{cam_detail::translated(u, {-60'000'000, 20'000'000}),
                                   cam_detail::translated(l_shape, {50'000'000, -40'000'000}),
                                   to_path(triangle(20, 15, 10, 60))};
  for (const Path& c : {u, l_shape, to_path(rect(12, 8, -6, -4))}) {
    const Paths fit = cam_detail::inner_fit({big}, c);
    ASSERT_FALSE(fit.empty());
    const Paths small = clip(ClipperLib::ctIntersection, fit, {to_path(rect(40, 30, -50, -10))});
    for (const Paths& f : {fit, small}) {
      Paths want = f;
      for (const Path& g : children) want = clip(ClipperLib::ctDifference, want, cam_detail::minkowski_sum(g, cam_detail::negated(c)));
      const Paths got = cam_detail::without_no_fit(f, children, c);
      EXPECT_GT(area_of(got), 0.0);
      EXPECT_LT(area_of(clip(ClipperLib::ctXor, got, want)), 1e-6) << area_of(got) << " vs " << area_of(want);
    }
  }
}

// The general inner fit as its formula states it: (room − c0) less every room ring's whole band
// ∂r ⊕ ∂(−C) (Clipper's MinkowskiSum, which unites all its parallelograms) and r0 − C. What
// inner_fit_general must equal, however it gets there.
Paths whole_inner_fit(const Paths& room, const Path& c) {
  const Path neg = cam_detail::negated(c);
  ClipperLib::Clipper clipper;
  for (const Path& r : room) {
    clipper.AddPath(cam_detail::translated(r, {-c.front().X, -c.front().Y}), ClipperLib::ptSubject, true);
    Paths band;
    ClipperLib::MinkowskiSum(neg, r, band, true);
    clipper.AddPaths(band, ClipperLib::ptClip, true);
    clipper.AddPath(cam_detail::translated(neg, r.front()), ClipperLib::ptClip, true);
  }
  Paths out;
  clipper.Execute(ClipperLib::ctDifference, out, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  return out;
}

// A ring of n corners at radius r (1 + a sin(k θ)): not convex, like the sponge's rooms.
Path wavy(double r, double a, int k, int n, double cx = 0, double cy = 0) {
  Polygon2 ring;
  for (int i = 0; i < n; ++i) {
    const double th = 2 * std::numbers::pi * i / n;
    const double rr = r * (1 + a * std::sin(k * th));
    ring.emplace_back(cx + rr * std::cos(th), cy + rr * std::sin(th));
  }
  return to_path(ring);
}

Path rotated_path(const Path& ring, double deg) {
  const double a = deg * std::numbers::pi / 180, co = std::cos(a), si = std::sin(a);
  Path out;
  for (const auto& q : ring)
    out.push_back({std::llround(co * static_cast<double>(q.X) - si * static_cast<double>(q.Y)),
                   std::llround(si * static_cast<double>(q.X) + co * static_cast<double>(q.Y))});
  return out;
}

// Non-convex rooms (one ring, and one with an island a child left), candidates small, nearly
// filling the room (its own ring eroded 0.3 mm: hundreds of corners), turned a little so that they
// no longer fit, and a little larger than the room: the region the corners' patch bounds is the
// whole formula's region, and empty exactly when that is.
TEST(NestFit, GeneralInnerFitOfNonConvexRoomsEqualsTheWholeFormula) {
  const Path outer = wavy(60, 0.2, 5, 136);
  const Path island = [] {
    Path p = wavy(8, 0.3, 3, 24, 25, 0);
    ClipperLib::ReversePath(p);  // a hole in the room: clockwise
    return p;
  }();
  const Path snug = cam_detail::offset_mitre({outer}, -0.3).front();
  const Path too_big = cam_detail::offset_mitre({outer}, 0.05).front();
  int fitting = 0, empty = 0;
  for (const Paths& room : {Paths{outer}, Paths{outer, island}}) {
    for (const Path& c : {snug, rotated_path(snug, 0.2), rotated_path(snug, 2.0), too_big,
                          to_path(ell(30, 20, 8, -10, -10)), to_path(circle(12, 40, 5, 5)), wavy(20, 0.25, 4, 90)}) {
      SCOPED_TRACE(::testing::Message() << c.size() << " corners in a room of " << room.size() << " ring(s)");
      const Paths want = whole_inner_fit(room, c);
      const Paths got = cam_detail::inner_fit_general(room, c);
      // Both regions are rounded to nm along boundaries hundreds of mm long: 1e-5 mm² is that
      // rounding (1.1e-6 was seen), a wrong piece is square millimetres.
      EXPECT_LT(area_of(clip(ClipperLib::ctXor, got, want)), 1e-5) << area_of(got) << " vs " << area_of(want);
      EXPECT_EQ(area_of(got) > 0.0, area_of(want) > 0.0);
      (area_of(want) > 0.0 ? fitting : empty) += 1;
    }
  }
  EXPECT_GE(fitting, 6) << "the cases must include fits";
  EXPECT_GE(empty, 4) << "and candidates that do not fit";
}

TEST(NestFit, ConvexRoomHoldsAConcaveRingExactlyWhenItHoldsItsHull) {
  const Path room = to_path(circle(120, 40));
  const Path u = vase_u(60, 0.8);
  const Paths a = cam_detail::inner_fit({room}, u);
  const Paths b = cam_detail::inner_fit_general({room}, u);
  ASSERT_FALSE(a.empty());
  EXPECT_LT(area_of(clip(ClipperLib::ctXor, a, b)), 1e-4) << area_of(a) << " vs " << area_of(b);
}

TEST(NestHoles, ComposedPlacementIsHostAfterChild) {
  const Placement host{0, 1.1, {300.0, -20.0}};
  const Placement child{1, 0.7, {12.0, 5.5}};
  const Placement sheet = cam_detail::compose(host, child);
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(3, 4), Eigen::Vector2d(-50, 8)}) {
    const Eigen::Vector2d want = place_point(host, place_point(child, p));
    EXPECT_LT((place_point(sheet, p) - want).norm(), 1e-12);
  }
  EXPECT_EQ(sheet.part, 1);
}

// The failures check_nest reports for a nest, intercepted (not failing this test).
std::vector<std::string> checker_failures(std::span<const Part> parts, const Stock& stock, const NestParams& params,
                                          const Nest& nest) {
  ::testing::TestPartResultArray results;
  {
    ::testing::ScopedFakeTestPartResultReporter reporter(
        ::testing::ScopedFakeTestPartResultReporter::INTERCEPT_ONLY_CURRENT_THREAD, &results);
    check_nest(parts, stock, params, nest);
  }
  std::vector<std::string> out;
  for (int i = 0; i < results.size(); ++i) out.emplace_back(results.GetTestPartResult(i).message());
  return out;
}

bool any_contains(const std::vector<std::string>& messages, const std::string& what) {
  return std::any_of(messages.begin(), messages.end(), [&](const std::string& m) { return m.find(what) != std::string::npos; });
}

// The checker itself: a child too close to the hole's ring, or listed after its host, fails.
TEST(NestHoles, CheckNestRefusesBadChildren) {
  const std::vector<Part> parts{ring_part(100, 90, 1), make_part(rect(30, 30), 3.0, 2, 1)};
  const Stock stock = one_sheet_kind(3.0, 230, 230);
  const NestParams params = with(NestMethod::matrix);
  auto sheet_with = [&](Eigen::Vector2d child_at, bool child_first) {
    Nest n;
    NestedSheet s;
    s.index = 1;
    s.stock_index = 0;
    s.thickness_mm = 3.0;
    s.width_mm = s.length_mm = 230;
    s.material = "aluminium";
    const Placement host{0, 0.0, {115, 115}};
    const Placement child{1, 0.0, child_at, child_first ? 1 : -1};
    s.placements = child_first ? std::vector<Placement>{child, host} : std::vector<Placement>{host, child};
    s.utilisation = (parts[0].area_mm2 + parts[1].area_mm2) / (230.0 * 230.0);
    n.sheets.push_back(s);
    return n;
  };
  const Summary ok = check_nest(parts, stock, params, sheet_with({100, 100}, true));
  EXPECT_EQ(ok.nested_pairs, 1);
  // The square's right edge 88 mm from the centre: 2 mm from the Ø180 free ring.
  EXPECT_TRUE(any_contains(checker_failures(parts, stock, params, sheet_with({115 + 58, 100}, true)),
                           "closer than the spacing"));
  EXPECT_TRUE(any_contains(checker_failures(parts, stock, params, sheet_with({100, 100}, false)), "comes after it"));
}

// A Ø200 ring with a Ø180 free hole and small parts: they all go in, each at least the spacing
// from the hole's ring and from each other; on a sheet just big enough for the ring, one sheet.
class NestHoles : public ::testing::TestWithParam<NestMethod> {};

std::vector<Part> ring_and_small_parts() {
  std::vector<Part> parts{ring_part(100, 90, 1)};
  for (int i = 0; i < 3; ++i) parts.push_back(make_part(circle(18, 32), 3.0, 2, i + 1));
  for (int i = 0; i < 3; ++i) parts.push_back(make_part(rect(30, 25), 3.0, 3, i + 1));
  for (int i = 0; i < 3; ++i) parts.push_back(make_part(ell(45, 40, 15), 3.0, 4, i + 1));
  return parts;
}

TEST_P(NestHoles, SmallPartsGoInsideTheBigRing) {
  const std::vector<Part> parts = ring_and_small_parts();
  const NestParams params = with(GetParam());
  std::vector<int> group(parts.size());
  for (std::size_t i = 0; i < parts.size(); ++i) group[i] = static_cast<int>(i);
  const cam_detail::HoleFilling fill = cam_detail::fill_holes(parts, group, params);
  EXPECT_EQ(fill.rejected_by_check, 0);
  ASSERT_EQ(fill.hosted.size(), parts.size() - 1) << "every small part fits the Ø180 hole";
  ASSERT_EQ(fill.free, std::vector<int>{0});
  const Path hole = to_path(parts[0].free_holes_mm[0]);
  std::vector<Polygon2> in_hole;
  for (const auto& h : fill.hosted) {
    EXPECT_EQ(h.host, 0);
    in_hole.push_back(placed_footprint(parts[h.in_host.part], h.in_host));
    // Grown by the spacing (less 0.1 µm) the child stays inside the free hole.
    const Paths out = clip(ClipperLib::ctDifference, grow(in_hole.back(), params.spacing_mm - 1e-4), {hole});
    EXPECT_EQ(area_of(out), 0.0) << "part " << h.in_host.part << " too close to the hole's edge";
  }
  for (std::size_t i = 0; i < in_hole.size(); ++i)
    for (std::size_t j = i + 1; j < in_hole.size(); ++j) {
      const Paths both = clip(ClipperLib::ctIntersection, grow(in_hole[i], 0.5 * params.spacing_mm - 1e-4),
                              grow(in_hole[j], 0.5 * params.spacing_mm - 1e-4));
      EXPECT_EQ(area_of(both), 0.0) << "children " << i << " and " << j << " closer than the spacing";
    }

  // On a 230 x 230 sheet only the ring fits beside nothing: one sheet with, 2 or more without.
  const Stock stock = one_sheet_kind(3.0, 230, 230);
  auto filled = nest_parts(parts, stock, params);
  ASSERT_TRUE(filled) << filled.error().message;
  const Summary a = check_nest(parts, stock, params, *filled);
  EXPECT_EQ(a.sheets, 1);
  EXPECT_EQ(a.hosted, static_cast<int>(parts.size()) - 1);
  EXPECT_EQ(a.nested_pairs, static_cast<int>(parts.size()) - 1);
  ASSERT_EQ(filled->sheets[0].placements.back().part, 0) << "the host is listed after its children";
  auto plain = nest_parts(parts, stock, with(GetParam(), false));
  ASSERT_TRUE(plain) << plain.error().message;
  const Summary b = check_nest(parts, stock, with(GetParam(), false), *plain);
  EXPECT_EQ(b.hosted, 0);
  EXPECT_GT(b.sheets, a.sheets);
  std::printf("[%s] ring + 9 small parts on 230 x 230: %d sheet(s), utilisation %.3f with hole filling; %d, %.3f without\n",
              nest_method_name(GetParam()), a.sheets, a.mean_utilisation, b.sheets, b.mean_utilisation);
}

// The nest says as it goes how many parts it has placed: once for each, whether in a hole or on
// a sheet (a plan's progress bar stood still through a minute of nesting, issue 22).
TEST_P(NestHoles, EveryPartPlacedIsCountedOnceAsItIsPlaced) {
  const std::vector<Part> parts = ring_and_small_parts();
  for (const bool fill : {true, false}) {
    SCOPED_TRACE(fill ? "hole filling" : "no hole filling");
    NestParams params = with(GetParam(), fill);
    params.parallel = true;
    std::atomic<int> placed{0};
    params.on_placed = [&] { ++placed; };
    auto nest = nest_parts(parts, one_sheet_kind(3.0, 230, 230), params);
    ASSERT_TRUE(nest) << nest.error().message;
    std::size_t on_sheets = 0;
    for (const NestedSheet& sheet : nest->sheets) on_sheets += sheet.placements.size();
    ASSERT_EQ(on_sheets, parts.size());
    EXPECT_EQ(placed.load(), static_cast<int>(parts.size()));
  }
}

// Four rings with L-shapes: the children follow their hosts onto both sheets (the packer may turn a ring).
TEST_P(NestHoles, ChildrenFollowTheirHostOntoEverySheet) {
  std::vector<Part> parts;
  for (int k = 0; k < 4; ++k) {
    parts.push_back(ring_part(100, 90, 1 + k, 3.0, 96, 37.0 * k, -12.0 * k));
    for (int i = 0; i < 3; ++i) parts.push_back(make_part(ell(45, 40, 15, 500, 200), 3.0, 10 + k, i + 1));
  }
  const Stock stock = one_sheet_kind(3.0, 460, 240);
  const NestParams params = with(GetParam());
  auto nest = nest_parts(parts, stock, params);
  ASSERT_TRUE(nest) << nest.error().message;
  const Summary s = check_nest(parts, stock, params, *nest);
  EXPECT_EQ(s.hosted, 12);
  EXPECT_EQ(s.sheets, 2);
}

// Rings of decreasing radius (a vase's layers): with hole filling they nest like Russian dolls.
std::vector<Part> vase(int n, double thickness = 3.0) {
  std::vector<Part> parts;
  for (int k = 0; k < n; ++k) {
    const double r = 140.0 - 110.0 * k / std::max(1, n - 1);  // Ø280 down to Ø60
    parts.push_back(ring_part(r, r - 3.5, k + 1, thickness, 120));
  }
  return parts;
}

TEST_P(NestHoles, VaseUsesFewerSheetsWithHoleFilling) {
  for (int n : {20, 60}) {
    const std::vector<Part> parts = vase(n);
    const Stock stock = one_sheet_kind(3.0, 1000, 600);
    Summary res[2];
    double ms[2];
    for (int fill = 0; fill < 2; ++fill) {
      const NestParams params = with(GetParam(), fill == 1);
      const auto t0 = std::chrono::steady_clock::now();
      auto nest = nest_parts(parts, stock, params);
      ms[fill] = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      ASSERT_TRUE(nest) << nest.error().message;
      res[fill] = check_nest(parts, stock, params, *nest);
    }
    EXPECT_LT(res[1].sheets, res[0].sheets);
    EXPECT_GT(res[1].hosted, 0);
    std::printf("[%s] vase of %d rings on 1000 x 600: without hole filling %d sheets, utilisation %.3f, %.0f ms; "
                "with %d sheets, utilisation %.3f, %.0f ms (%d parts in holes)\n",
                nest_method_name(GetParam()), n, res[0].sheets, res[0].mean_utilisation, ms[0], res[1].sheets,
                res[1].mean_utilisation, ms[1], res[1].hosted);
  }
}

// Seeded random rings and small (often concave) parts in two thicknesses: every invariant holds,
// and the final check on real footprints never has to refuse a position.
TEST_P(NestHoles, SeededRandomRingsAndSmallParts) {
  for (unsigned seed : {3u, 17u, 99u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> radius(40.0, 130.0);
    std::uniform_real_distribution<double> wall(3.0, 12.0);
    std::uniform_real_distribution<double> size(8.0, 45.0);
    std::uniform_real_distribution<double> jitter(0.45, 1.0);
    std::uniform_real_distribution<double> where(-300.0, 300.0);
    std::uniform_int_distribution<int> corners(3, 12);
    std::vector<Part> parts;
    for (int i = 0; i < 10; ++i) {
      const double r = radius(rng);
      parts.push_back(ring_part(r, r - wall(rng), 1 + i, i % 2 ? 1.5 : 3.0, 24 + i * 9, where(rng), where(rng)));
    }
    for (int i = 0; i < 40; ++i) {
      const int k = corners(rng);
      const double rx = size(rng), ry = size(rng), cx = where(rng), cy = where(rng);
      Polygon2 ring;
      for (int c = 0; c < k; ++c) {
        const double a = 2 * std::numbers::pi * (c + 0.3 * jitter(rng)) / k;
        const double rr = jitter(rng);
        ring.emplace_back(cx + rx * rr * std::cos(a), cy + ry * rr * std::sin(a));
      }
      parts.push_back(make_part(ring, i % 3 ? 3.0 : 1.5, 20 + i / 10, 1 + i % 10));
    }
    Stock stock;
    stock.sheets.push_back({3.0, 500, 800, 0, "3 mm", ""});
    stock.sheets.push_back({1.5, 500, 800, 0, "1.5 mm", ""});
    const NestParams params = with(GetParam(), true, 5.0, 12.0);
    for (double t : {1.5, 3.0}) {
      std::vector<int> group;
      for (std::size_t i = 0; i < parts.size(); ++i)
        if (parts[i].thickness_mm == t) group.push_back(static_cast<int>(i));
      EXPECT_EQ(cam_detail::fill_holes(parts, group, params).rejected_by_check, 0);
    }
    auto with_fill = nest_parts(parts, stock, params);
    ASSERT_TRUE(with_fill) << with_fill.error().message;
    const Summary a = check_nest(parts, stock, params, *with_fill);
    auto without = nest_parts(parts, stock, with(GetParam(), false, 5.0, 12.0));
    ASSERT_TRUE(without) << without.error().message;
    const Summary b = check_nest(parts, stock, with(GetParam(), false, 5.0, 12.0), *without);
    EXPECT_GT(a.hosted, 0);
    EXPECT_LE(a.sheets, b.sheets);
    std::printf("[%s] seed %u, 10 rings + 40 parts: %d sheets, utilisation %.3f, %d in holes; without %d, %.3f\n",
                nest_method_name(GetParam()), seed, a.sheets, a.mean_utilisation, a.hosted, b.sheets,
                b.mean_utilisation);
  }
}

INSTANTIATE_TEST_SUITE_P(BothMethods, NestHoles, ::testing::Values(NestMethod::matrix, NestMethod::shape),
                         [](const auto& info) { return std::string(nest_method_name(info.param)); });

}  // namespace
}  // namespace lamina
