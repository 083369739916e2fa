// sheet_svg on a hand-built plan: one layer, a bevelled square outer with a square hole, placed
// twice (0° and 90°) on a sheet, with a small toolpath. The document is parsed back with a strict
// little XML reader and the geometry compared with R·p + offset.
#include "lamina/core/sheet_svg.hpp"

#include "xml_mini.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <regex>
#include <sstream>

namespace lamina {
namespace {

using Vec2 = Eigen::Vector2d;

constexpr double kZBottom = 10.0, kSvgThickness = 6.0;

CutLine line(const Vec2& top, const Vec2& bottom) {
  CutLine l;
  l.top_mm = Eigen::Vector3d(top.x(), top.y(), kZBottom + kSvgThickness);
  l.bottom_mm = Eigen::Vector3d(bottom.x(), bottom.y(), kZBottom);
  l.tool_axis = (l.top_mm - l.bottom_mm).normalized();
  return l;
}

CutPass pass(const Polygon2& top, const Polygon2& bottom) {
  CutPass p;
  for (std::size_t i = 0; i < top.size(); ++i) p.lines.push_back(line(top[i], bottom[i]));
  return p;
}

Polygon2 square(double lo, double hi, bool ccw) {
  Polygon2 r{{lo, lo}, {hi, lo}, {hi, hi}, {lo, hi}};
  if (!ccw) std::reverse(r.begin(), r.end());
  return r;
}

Polygon2 shifted(Polygon2 r, const Vec2& d) {
  for (auto& p : r) p += d;
  return r;
}

// Layer 3: outer 0..40 at the top, 1..39 at the bottom (its freeing pass; a trim pass before it
// is shifted so that drawing the wrong pass shows); hole 15..25 at the top, 14..26 at the bottom.
BevelPlan svg_plan() {
  LayerPlan layer;
  layer.index = 3;
  layer.z_bottom_mm = kZBottom;
  layer.thickness_mm = kSvgThickness;
  LayerOutline outer;
  outer.passes.push_back(pass(shifted(square(0, 40, true), {5, 5}), shifted(square(1, 39, true), {5, 5})));
  outer.passes.push_back(pass(square(0, 40, true), square(1, 39, true)));
  LayerOutline hole;
  hole.is_hole = true;
  hole.parent = 0;
  hole.passes.push_back(pass(square(15, 25, false), square(14, 26, false)));
  layer.outlines = {outer, hole};
  layer.passes = 2;
  BevelPlan plan;
  plan.layers.push_back(layer);
  return plan;
}

std::vector<Part> svg_parts() {
  Part p;
  p.layer_slot = 0;
  p.layer = 3;
  p.island = 1;
  p.outer = 0;
  p.holes = {1};
  p.thickness_mm = kSvgThickness;
  p.z_bottom_mm = kZBottom;
  p.footprint_mm = square(-1.5, 41.5, true);  // its centroid (20, 20) lies in the hole
  p.area_mm2 = 40 * 40 - 10 * 10;
  p.dowels_mm = {{5, 5}};
  Part q = p;
  q.island = 2;
  return {p, q};
}

NestedSheet svg_sheet() {
  NestedSheet s;
  s.index = 2;
  s.thickness_mm = kSvgThickness;
  s.length_mm = 300;
  s.width_mm = 200;
  s.material = "stainless 316L";
  s.placements = {Placement{0, 0.0, {20.1, 30.2}}, Placement{1, M_PI / 2, {150.0, 20.0}}};
  s.utilisation = 0.0533;
  return s;
}

Vec2 place(const Placement& pl, const Vec2& p) {
  const Eigen::Rotation2Dd r(pl.rotation_rad);
  return r * p + pl.offset_mm;
}

ToolMove move(MoveKind kind, const Vec2& xy, double z, int contour) {
  ToolMove m;
  m.kind = kind;
  m.tip_mm = Eigen::Vector3d(xy.x(), xy.y(), z);
  m.contour = contour;
  m.jet_on = kind != MoveKind::rapid;
  return m;
}

// Per placement: the hole, then the outer; each a rapid over and down, pierce, lead-in, two
// cuts, lead-out, rapid up. Microjoints: one on each outer.
SheetToolpath svg_toolpath(const NestedSheet& sheet) {
  SheetToolpath tp;
  tp.sheet = sheet.index;
  tp.thickness_mm = kSvgThickness;
  for (int k = 0; k < static_cast<int>(sheet.placements.size()); ++k) {
    const auto& pl = sheet.placements[static_cast<std::size_t>(k)];
    for (const bool hole : {true, false}) {
      const Vec2 start = place(pl, hole ? Vec2(20, 15) : Vec2(20, 0));
      const Vec2 pierce = place(pl, hole ? Vec2(20, 18) : Vec2(20, -3));
      const int c = static_cast<int>(tp.contours.size());
      ToolContour tc;
      tc.first_move = tp.moves.size();  // the contour's moves include its rapids (toolpath.hpp)
      tp.moves.push_back(move(MoveKind::rapid, pierce, 10.0, c));
      tp.moves.push_back(move(MoveKind::rapid, pierce, 0.0, c));
      tc.placement = k;
      tc.part = pl.part;
      tc.outline = hole ? 1 : 0;
      tc.pass = hole ? 0 : 1;
      tc.is_hole = hole;
      tc.frees = tc.closed = true;
      tc.pierce_mm = pierce;
      tp.moves.push_back(move(MoveKind::pierce, pierce, 0.0, c));
      tp.moves.push_back(move(MoveKind::lead_in, start, 0.0, c));
      tp.moves.push_back(move(MoveKind::cut, place(pl, hole ? Vec2(25, 15) : Vec2(40, 0)), 0.0, c));
      tp.moves.push_back(move(MoveKind::cut, start, 0.0, c));
      tp.moves.push_back(move(MoveKind::lead_out, place(pl, hole ? Vec2(21, 16.5) : Vec2(21, -1.5)), 0.0, c));
      tp.moves.push_back(move(MoveKind::rapid, tp.moves.back().tip_mm.head<2>(), 10.0, c));
      tc.end_move = tp.moves.size();
      tp.contours.push_back(tc);
    }
    tp.microjoints.push_back(Microjoint{k, place(pl, {40, 20}), place(pl, {40, 20.6})});
  }
  tp.moves.push_back(move(MoveKind::rapid, Vec2::Zero(), 10.0, -1));
  tp.time.total_s = 754.0;
  return tp;
}

struct SvgFixture {
  BevelPlan plan = svg_plan();
  std::vector<Part> parts = svg_parts();
  NestedSheet sheet = svg_sheet();
  SheetToolpath tp = svg_toolpath(sheet);
  SheetSvgParams params{"A&B <x>.stl", 0.0, 6.0, true};

  std::string svg() const { return sheet_svg(plan, parts, sheet, tp, params); }
};

xml_mini::Element parse_ok(const std::string& svg) {
  auto r = xml_mini::parse(svg);
  EXPECT_TRUE(r.root.has_value()) << r.error;
  return r.root ? *r.root : xml_mini::Element{};
}

std::vector<double> numbers(const std::string& s) {
  std::vector<double> out;
  std::string t = s;
  for (char& c : t) {
    if (c == ',' || c == '(' || c == ')') c = ' ';
  }
  std::istringstream in(t);
  std::string word;
  while (in >> word) {
    try {
      std::size_t used = 0;
      const double v = std::stod(word, &used);
      if (used == word.size()) out.push_back(v);
    } catch (...) {
    }
  }
  return out;
}

Polygon2 polygon_points(const xml_mini::Element& e) {
  const auto v = numbers(e.attr("points"));
  Polygon2 out;
  for (std::size_t i = 0; i + 1 < v.size(); i += 2) out.emplace_back(v[i], v[i + 1]);
  return out;
}

bool inside(const Polygon2& ring, const Vec2& p) {
  bool in = false;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    const Vec2 &a = ring[i], &b = ring[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y())) in = !in;
  }
  return in;
}

const xml_mini::Element* by_id(const xml_mini::Element& root, const std::string& id) {
  std::vector<const xml_mini::Element*> out;
  root.collect([&](const xml_mini::Element& e) { return e.attr("id") == id; }, out);
  return out.size() == 1 ? out[0] : nullptr;
}

void expect_ring(const xml_mini::Element& e, const Polygon2& expected, const std::string& what) {
  const Polygon2 got = polygon_points(e);
  ASSERT_EQ(got.size(), expected.size()) << what;
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_NEAR(got[i].x(), expected[i].x(), 1e-3) << what << " point " << i;
    EXPECT_NEAR(got[i].y(), expected[i].y(), 1e-3) << what << " point " << i;
  }
}

TEST(SheetSvg, IsWellFormedSvgInMillimetres) {
  const SvgFixture f;
  const std::string svg = f.svg();
  ASSERT_EQ(svg.rfind("<?xml", 0), 0u);
  const auto root = parse_ok(svg);
  EXPECT_EQ(root.name, "svg");
  EXPECT_EQ(root.attr("xmlns"), "http://www.w3.org/2000/svg");
  EXPECT_EQ(root.attr("version"), "1.1");
  // width/height in mm equal the viewBox's size: 1 user unit = 1 mm.
  const auto vb = numbers(root.attr("viewBox"));
  ASSERT_EQ(vb.size(), 4u);
  ASSERT_TRUE(root.attr("width").ends_with("mm"));
  ASSERT_TRUE(root.attr("height").ends_with("mm"));
  EXPECT_DOUBLE_EQ(std::stod(root.attr("width")), vb[2]);
  EXPECT_DOUBLE_EQ(std::stod(root.attr("height")), vb[3]);
  EXPECT_GE(vb[2], 300.0);
  EXPECT_GE(vb[3], 200.0);
  // Numbers carry at most 3 decimals (offsets like 20.1 + 0.3 would print long otherwise).
  EXPECT_FALSE(std::regex_search(svg, std::regex(R"(\d\.\d{4,})"))) << "long decimals in the output";
}

TEST(SheetSvg, TheCheckerRejectsBrokenDocuments) {
  EXPECT_FALSE(xml_mini::parse("<svg><g></svg></g>").root);
  EXPECT_FALSE(xml_mini::parse("<svg><g></svg>").root);
  EXPECT_FALSE(xml_mini::parse("<svg><text>A&B</text></svg>").root);
  EXPECT_FALSE(xml_mini::parse("<svg><text>a < b</text></svg>").root);
  EXPECT_FALSE(xml_mini::parse("<svg a=\"<\"/>").root);
  EXPECT_FALSE(xml_mini::parse("<svg/><svg/>").root);
  EXPECT_TRUE(xml_mini::parse("<?xml version=\"1.0\"?>\n<svg a='1'><!-- c --><t>A&amp;B &lt;x&gt;</t></svg>\n").root);
}

TEST(SheetSvg, SheetRectangleInAYUpFrame) {
  const SvgFixture f;
  const auto root = parse_ok(f.svg());
  const auto* g = by_id(root, "sheet");
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(g->attr("transform"), "translate(0 200) scale(1 -1)");
  const auto rects = g->find("rect", "sheet");
  ASSERT_EQ(rects.size(), 1u);
  EXPECT_EQ(rects[0]->attr("x"), "0");
  EXPECT_EQ(rects[0]->attr("y"), "0");
  EXPECT_EQ(rects[0]->attr("width"), "300");
  EXPECT_EQ(rects[0]->attr("height"), "200");
}

TEST(SheetSvg, TopAndBottomContoursOfTheFreeingPassArePlaced) {
  const SvgFixture f;
  const auto root = parse_ok(f.svg());
  for (std::size_t k = 0; k < f.sheet.placements.size(); ++k) {
    const auto& pl = f.sheet.placements[k];
    const auto* g = by_id(root, "part-" + std::to_string(k + 1));
    ASSERT_NE(g, nullptr) << k;
    const auto placed = [&](const Polygon2& r) {
      Polygon2 out;
      for (const auto& p : r) out.push_back(place(pl, p));
      return out;
    };
    const std::string at = " of placement " + std::to_string(k);
    const auto top_outer = g->find("polygon", "top-outer");
    const auto bottom_outer = g->find("polygon", "bottom-outer");
    const auto top_hole = g->find("polygon", "top-hole");
    const auto bottom_hole = g->find("polygon", "bottom-hole");
    const auto footprint = g->find("polygon", "footprint");
    ASSERT_EQ(top_outer.size(), 1u);
    ASSERT_EQ(bottom_outer.size(), 1u);
    ASSERT_EQ(top_hole.size(), 1u);
    ASSERT_EQ(bottom_hole.size(), 1u);
    ASSERT_EQ(footprint.size(), 1u);
    expect_ring(*top_outer[0], placed(square(0, 40, true)), "top outer" + at);
    expect_ring(*bottom_outer[0], placed(square(1, 39, true)), "bottom outer" + at);
    expect_ring(*top_hole[0], placed(square(15, 25, false)), "top hole" + at);
    expect_ring(*bottom_hole[0], placed(square(14, 26, false)), "bottom hole" + at);
    expect_ring(*footprint[0], placed(square(-1.5, 41.5, true)), "footprint" + at);
    const auto dowels = g->find("circle", "dowel");
    ASSERT_EQ(dowels.size(), 1u);
    EXPECT_NEAR(std::stod(dowels[0]->attr("cx")), place(pl, {5, 5}).x(), 1e-3);
    EXPECT_NEAR(std::stod(dowels[0]->attr("cy")), place(pl, {5, 5}).y(), 1e-3);
    EXPECT_EQ(dowels[0]->attr("r"), "3");
  }
}

TEST(SheetSvg, OneUprightLabelPerPlacementInsideThePart) {
  const SvgFixture f;
  const auto root = parse_ok(f.svg());
  const auto labels = root.find("text", "label");
  ASSERT_EQ(labels.size(), 2u);
  const char* expected[] = {"L3-1", "L3-2"};
  for (std::size_t k = 0; k < 2; ++k) {
    const auto* t = by_id(root, "label-" + std::to_string(k + 1));
    ASSERT_NE(t, nullptr);
    EXPECT_EQ(t->text, expected[k]);
    const std::string tr = t->attr("transform");
    ASSERT_TRUE(tr.ends_with("scale(1 -1)")) << tr << ": the flipped group would mirror the text";
    const auto v = numbers(tr);
    ASSERT_GE(v.size(), 2u);
    const Vec2 at(v[0], v[1]);
    Polygon2 outer, hole;
    for (const auto& p : square(0, 40, true)) outer.push_back(place(f.sheet.placements[k], p));
    for (const auto& p : square(15, 25, true)) hole.push_back(place(f.sheet.placements[k], p));
    EXPECT_TRUE(inside(outer, at)) << expected[k] << " at " << at.transpose();
    EXPECT_FALSE(inside(hole, at)) << expected[k] << " at " << at.transpose() << " is in the hole";
  }
}

TEST(SheetSvg, PiercesLeadsMicrojointsAndRapids) {
  SvgFixture f;
  const auto root = parse_ok(f.svg());
  const auto groups = root.find("g", "toolpath");
  ASSERT_EQ(groups.size(), 1u);
  const auto& tp = *groups[0];
  const auto pierces = tp.find("circle", "pierce");
  ASSERT_EQ(pierces.size(), f.tp.contours.size());
  for (std::size_t i = 0; i < pierces.size(); ++i) {
    EXPECT_NEAR(std::stod(pierces[i]->attr("cx")), f.tp.contours[i].pierce_mm.x(), 1e-3);
    EXPECT_NEAR(std::stod(pierces[i]->attr("cy")), f.tp.contours[i].pierce_mm.y(), 1e-3);
  }
  const auto leads_in = tp.find("polyline", "lead-in");
  const auto leads_out = tp.find("polyline", "lead-out");
  ASSERT_EQ(leads_in.size(), f.tp.contours.size());
  ASSERT_EQ(leads_out.size(), f.tp.contours.size());
  for (std::size_t i = 0; i < leads_in.size(); ++i) {
    const auto& c = f.tp.contours[i];
    // Moves of a contour: rapid over, rapid down, pierce, lead-in, cut, cut, lead-out, rapid up.
    ASSERT_EQ(c.end_move - c.first_move, 8u);
    const Vec2 start = f.tp.moves[c.first_move + 3].tip_mm.head<2>();
    expect_ring(*leads_in[i], {c.pierce_mm, start}, "lead-in " + std::to_string(i));
    const Vec2 from = f.tp.moves[c.end_move - 3].tip_mm.head<2>(), to = f.tp.moves[c.end_move - 2].tip_mm.head<2>();
    expect_ring(*leads_out[i], {from, to}, "lead-out " + std::to_string(i));
  }
  EXPECT_EQ(tp.find("line", "microjoint").size(), f.tp.microjoints.size());
  EXPECT_FALSE(tp.find("polyline", "rapid").empty());

  f.params.show_rapids = false;
  const auto without = parse_ok(f.svg());
  EXPECT_TRUE(without.find("polyline", "rapid").empty());
}

TEST(SheetSvg, LegendStatesTheSheetAndEscapesTheTitle) {
  const SvgFixture f;
  const std::string svg = f.svg();
  EXPECT_NE(svg.find("A&amp;B &lt;x&gt;.stl"), std::string::npos);
  EXPECT_EQ(svg.find("A&B"), std::string::npos);
  EXPECT_EQ(svg.find("<x>"), std::string::npos);
  const auto root = parse_ok(svg);
  const auto legends = root.find("g", "legend");
  ASSERT_EQ(legends.size(), 1u);
  std::vector<std::string> lines;
  for (const auto* t : legends[0]->find("text")) lines.push_back(t->text);
  const auto has = [&](const std::string& s) { return std::find(lines.begin(), lines.end(), s) != lines.end(); };
  EXPECT_TRUE(has("A&B <x>.stl"));
  EXPECT_TRUE(has("Sheet 2"));
  EXPECT_TRUE(has("Thickness: 6 mm"));
  EXPECT_TRUE(has("Material: stainless 316L"));
  EXPECT_TRUE(has("Size: 300 x 200 mm"));
  EXPECT_TRUE(has("Parts: 2"));
  EXPECT_TRUE(has("Utilisation: 5.3 %"));
  EXPECT_TRUE(has("Estimated time: 0:12:34 (h:mm:ss)"));
  EXPECT_TRUE(has("Top contour, outer"));
  EXPECT_TRUE(has("Bottom contour, hole"));
  const auto titles = root.find("title");
  ASSERT_EQ(titles.size(), 1u);
  EXPECT_EQ(titles[0]->text, "A&B <x>.stl - sheet 2");
}

TEST(SheetSvg, EscapesMaterialAndDropsControlCharacters) {
  SvgFixture f;
  f.sheet.material = "S235 \"JR\" & 'co'\x01";
  f.params.title.clear();
  f.params.estimated_time_s = 3725.4;
  const auto root = parse_ok(f.svg());
  std::vector<std::string> lines;
  for (const auto* t : root.find("g", "legend")[0]->find("text")) lines.push_back(t->text);
  EXPECT_NE(std::find(lines.begin(), lines.end(), "Material: S235 \"JR\" & 'co'"), lines.end());
  EXPECT_NE(std::find(lines.begin(), lines.end(), "Estimated time: 1:02:05 (h:mm:ss)"), lines.end());
  EXPECT_EQ(root.find("title")[0]->text, "Sheet 2");
}

TEST(SheetSvg, SkipsPlacementsOfUnknownParts) {
  SvgFixture f;
  f.sheet.placements.push_back(Placement{7, 0.0, {0, 0}});
  const auto root = parse_ok(f.svg());
  EXPECT_EQ(root.find("text", "label").size(), 2u);
  EXPECT_EQ(root.find("g", "part").size(), 2u);
}

}  // namespace
}  // namespace lamina
