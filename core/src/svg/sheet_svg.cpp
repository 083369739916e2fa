// The sheet drawing (sheet_svg.hpp): one SVG group in the sheet frame, flipped so y points up
// (origin bottom-left, as on the machine table), with the parts, the toolpath marks and the part
// numbers; the legend beside it in plain SVG coordinates. docs/sheet-svg.md describes it.
#include "lamina/core/sheet_svg.hpp"

#include "svg/sheet_svg_internal.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <optional>
#include <vector>

namespace lamina {
namespace {

using namespace svg_detail;
using Vec2 = Eigen::Vector2d;

// sheet_xy = R(rotation) · layer_xy + offset (nest.hpp). Local on purpose: the drawing needs
// nothing else from the nesting code.
Vec2 to_sheet(const Placement& pl, const Vec2& p) {
  const double c = std::cos(pl.rotation_rad), s = std::sin(pl.rotation_rad);
  return {c * p.x() - s * p.y() + pl.offset_mm.x(), s * p.x() + c * p.y() + pl.offset_mm.y()};
}

Polygon2 to_sheet(const Placement& pl, const Polygon2& ring) {
  Polygon2 out;
  out.reserve(ring.size());
  for (const auto& p : ring) out.push_back(to_sheet(pl, p));
  return out;
}

// The top (or bottom) points of an outline's freeing pass — its last — in layer XY.
Polygon2 freeing_ring(const LayerOutline& o, bool top) {
  Polygon2 ring;
  if (o.passes.empty()) return ring;
  for (const auto& l : o.passes.back().lines) ring.push_back(top ? l.top_mm.head<2>() : l.bottom_mm.head<2>());
  return ring;
}

struct PartRings {
  Polygon2 outer_top, outer_bottom;
  std::vector<Polygon2> holes_top, holes_bottom;
};

std::optional<PartRings> part_rings(const BevelPlan& plan, const Part& part) {
  if (part.layer_slot < 0 || part.layer_slot >= static_cast<int>(plan.layers.size())) return std::nullopt;
  const auto& outlines = plan.layers[static_cast<std::size_t>(part.layer_slot)].outlines;
  const auto valid = [&](int i) { return i >= 0 && i < static_cast<int>(outlines.size()); };
  if (!valid(part.outer)) return std::nullopt;
  PartRings r;
  r.outer_top = freeing_ring(outlines[static_cast<std::size_t>(part.outer)], true);
  r.outer_bottom = freeing_ring(outlines[static_cast<std::size_t>(part.outer)], false);
  for (const int h : part.holes) {
    if (!valid(h)) continue;
    r.holes_top.push_back(freeing_ring(outlines[static_cast<std::size_t>(h)], true));
    r.holes_bottom.push_back(freeing_ring(outlines[static_cast<std::size_t>(h)], false));
  }
  return r;
}

// Crossings of the rings with the line {coord[axis] = v}, as the other coordinate, sorted.
std::vector<double> crossings(const std::vector<const Polygon2*>& rings, int axis, double v) {
  const int other = 1 - axis;
  std::vector<double> xs;
  for (const Polygon2* ring : rings) {
    for (std::size_t i = 0, n = ring->size(); i < n; ++i) {
      const Vec2& a = (*ring)[i];
      const Vec2& b = (*ring)[(i + 1) % n];
      if ((a[axis] > v) == (b[axis] > v)) continue;
      const double t = (v - a[axis]) / (b[axis] - a[axis]);
      xs.push_back(a[other] + t * (b[other] - a[other]));
    }
  }
  std::sort(xs.begin(), xs.end());
  return xs;
}

// The interval of material (even-odd inside the rings) along the axis through p that contains p.
std::optional<std::pair<double, double>> span_at(const std::vector<const Polygon2*>& rings, const Vec2& p, int axis) {
  const auto xs = crossings(rings, 1 - axis, p[1 - axis]);
  for (std::size_t i = 0; i + 1 < xs.size(); i += 2) {
    if (xs[i] <= p[axis] && p[axis] <= xs[i + 1]) return std::pair{xs[i], xs[i + 1]};
  }
  return std::nullopt;
}

Vec2 centroid(const Polygon2& ring) {
  double a = 0.0;
  Vec2 c = Vec2::Zero();
  for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
    const Vec2& p = ring[i];
    const Vec2& q = ring[(i + 1) % n];
    const double cross = p.x() * q.y() - q.x() * p.y();
    a += cross;
    c += (p + q) * cross;
  }
  if (std::abs(a) > 1e-12) return c / (3.0 * a);
  Vec2 mean = Vec2::Zero();
  for (const auto& p : ring) mean += p;
  return ring.empty() ? mean : Vec2(mean / static_cast<double>(ring.size()));
}

struct LabelSpot {
  Vec2 at = Vec2::Zero();
  double room_x = 0.0, room_y = 0.0;  // material around it, along x and y
};

// Where a part's number goes, in the frame of its arguments (the sheet's: the text is horizontal
// there): the footprint's centroid when it lies in the part's material (top contour minus holes);
// otherwise the middle of the widest horizontal run of material (nearest the centroid's height),
// centred vertically there.
LabelSpot label_spot(const Polygon2& footprint, const PartRings& r) {
  const Polygon2& outer = r.outer_top.size() >= 3 ? r.outer_top : footprint;
  if (outer.empty()) return {};
  std::vector<const Polygon2*> rings{&outer};
  for (const auto& h : r.holes_top) {
    if (h.size() >= 3) rings.push_back(&h);
  }
  const Vec2 c = centroid(footprint.size() >= 3 ? footprint : outer);
  const auto hx = span_at(rings, c, 0);
  const auto hy = span_at(rings, c, 1);
  if (hx && hy) return {c, hx->second - hx->first, hy->second - hy->first};

  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& p : outer) lo = std::min(lo, p.y()), hi = std::max(hi, p.y());
  constexpr int kLines = 32;
  double best_w = -1.0, best_dy = 0.0;
  Vec2 best = outer.front();
  for (int k = 0; k < kLines; ++k) {
    const double y = lo + (hi - lo) * (k + 0.5) / kLines;
    const auto xs = crossings(rings, 1, y);
    for (std::size_t i = 0; i + 1 < xs.size(); i += 2) {
      const double w = xs[i + 1] - xs[i], dy = std::abs(y - c.y());
      if (w > best_w * (1 + 1e-9) || (w >= best_w * (1 - 1e-9) && dy < best_dy)) {
        best_w = w, best_dy = dy, best = Vec2(0.5 * (xs[i] + xs[i + 1]), y);
      }
    }
  }
  LabelSpot spot{best, std::max(best_w, 0.0), 0.0};
  if (const auto vy = span_at(rings, best, 1)) {
    spot.at.y() = 0.5 * (vy->first + vy->second);
    spot.room_y = vy->second - vy->first;
    if (const auto vx = span_at(rings, spot.at, 0)) spot.room_x = vx->second - vx->first;
  }
  return spot;
}

// Runs of consecutive moves of one kind in [first, end): each from the previous move's end.
std::vector<Polygon2> runs(const SheetToolpath& tp, std::size_t first, std::size_t end, MoveKind kind,
                           const Vec2& start_if_first) {
  std::vector<Polygon2> out;
  Polygon2 run;
  end = std::min(end, tp.moves.size());
  for (std::size_t i = first; i < end; ++i) {
    const ToolMove& m = tp.moves[i];
    if (m.kind != kind) {
      if (run.size() >= 2) out.push_back(std::move(run));
      run.clear();
      continue;
    }
    if (run.empty()) run.push_back(i > 0 ? Vec2(tp.moves[i - 1].tip_mm.head<2>()) : start_if_first);
    const Vec2 p = m.tip_mm.head<2>();
    if ((p - run.back()).norm() > 1e-9) run.push_back(p);  // vertical moves add nothing in plan view
  }
  if (run.size() >= 2) out.push_back(std::move(run));
  return out;
}

void polygon(std::string& svg, const char* cls, const Polygon2& ring) {
  if (ring.size() < 2) return;
  fmt::format_to(std::back_inserter(svg), "<polygon class=\"{}\" points=\"{}\"/>\n", cls, points(ring));
}

void polyline(std::string& svg, const char* cls, const Polygon2& line) {
  if (line.size() < 2) return;
  fmt::format_to(std::back_inserter(svg), "<polyline class=\"{}\" points=\"{}\"/>\n", cls, points(line));
}

void circle(std::string& svg, const char* cls, const Vec2& c, double r) {
  fmt::format_to(std::back_inserter(svg), "<circle class=\"{}\" cx=\"{}\" cy=\"{}\" r=\"{}\"/>\n", cls, num(c.x()), num(c.y()), num(r));
}

// One placement: footprint, bottom then top contours, dowel holes. Its label goes to labels.
void draw_part(std::string& svg, std::string& labels, int k, const BevelPlan& plan, const Part& part,
               const Placement& pl, const Scale& s, const SheetSvgParams& params) {
  auto rings = part_rings(plan, part);
  if (rings) {
    rings->outer_top = to_sheet(pl, rings->outer_top);
    rings->outer_bottom = to_sheet(pl, rings->outer_bottom);
    for (auto& h : rings->holes_top) h = to_sheet(pl, h);
    for (auto& h : rings->holes_bottom) h = to_sheet(pl, h);
  }
  const Polygon2 footprint = to_sheet(pl, part.footprint_mm);
  auto out = std::back_inserter(svg);
  fmt::format_to(out, "<g class=\"part\" id=\"part-{}\">\n", k + 1);
  polygon(svg, "footprint", footprint);
  if (rings) {
    polygon(svg, "bottom-outer", rings->outer_bottom);
    for (const auto& h : rings->holes_bottom) polygon(svg, "bottom-hole", h);
    polygon(svg, "top-outer", rings->outer_top);
    for (const auto& h : rings->holes_top) polygon(svg, "top-hole", h);
  }
  if (params.dowel_diameter_mm > 0.0) {
    for (const auto& d : part.dowels_mm) circle(svg, "dowel", to_sheet(pl, d), 0.5 * params.dowel_diameter_mm);
  }
  svg += "</g>\n";

  const std::string text = fmt::format("L{}-{}", part.layer, part.island);
  const LabelSpot spot = rings ? label_spot(footprint, *rings) : LabelSpot{centroid(footprint), s.font, s.font};
  // As large as the legend's text, but fitting the material around the spot.
  const double fit_x = spot.room_x / (0.65 * static_cast<double>(text.size()) + 0.5);
  const double fit_y = 0.7 * spot.room_y;
  const double font = std::max(0.5, std::min({s.font, fit_x, fit_y}));
  const Vec2& at = spot.at;
  // The drawing's group flips y; the label flips back about its own anchor to stay upright.
  fmt::format_to(std::back_inserter(labels),
                 "<text class=\"label\" id=\"label-{}\" transform=\"translate({} {}) scale(1 -1)\" font-size=\"{}\" dy=\"0.35em\">{}</text>\n",
                 k + 1, num(at.x()), num(at.y()), num(font), xml_escape(text));
}

// Where jet compensation met the head's tilt limit: each run of such cuts, over the toolpath.
void draw_tilt_limited(std::string& svg, const SheetToolpath& tp) {
  std::vector<Vec2> run;
  for (std::size_t i = 1; i <= tp.moves.size(); ++i) {
    const bool held = i < tp.moves.size() && tp.moves[i].tilt_limited;
    if (held && run.empty()) run.push_back(tp.moves[i - 1].tip_mm.head<2>());
    if (held) run.push_back(tp.moves[i].tip_mm.head<2>());
    if (!held && !run.empty()) {
      polyline(svg, "tilt-limited", run);
      run.clear();
    }
  }
}

void draw_toolpath(std::string& svg, const SheetToolpath& tp, const Scale& s, bool rapids) {
  svg += "<g class=\"toolpath\">\n";
  if (rapids) {
    for (const auto& r : runs(tp, 1, tp.moves.size(), MoveKind::rapid, Vec2::Zero())) polyline(svg, "rapid", r);
  }
  for (const auto& c : tp.contours) {
    for (const auto& r : runs(tp, c.first_move, c.end_move, MoveKind::lead_in, c.pierce_mm)) polyline(svg, "lead-in", r);
    for (const auto& r : runs(tp, c.first_move, c.end_move, MoveKind::lead_out, c.pierce_mm)) polyline(svg, "lead-out", r);
  }
  for (const auto& mj : tp.microjoints) {
    fmt::format_to(std::back_inserter(svg), "<line class=\"microjoint\" x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\"/>\n",
                   num(mj.from_mm.x()), num(mj.from_mm.y()), num(mj.to_mm.x()), num(mj.to_mm.y()));
  }
  draw_tilt_limited(svg, tp);
  const double r = std::max(0.5, 2.0 * s.line);
  for (const auto& c : tp.contours) circle(svg, "pierce", c.pierce_mm, r);
  svg += "</g>\n";
}

}  // namespace

std::string sheet_svg(const BevelPlan& plan, std::span<const Part> parts, const NestedSheet& sheet,
                      const SheetToolpath& toolpath, const SheetSvgParams& params) {
  const double L = std::max(sheet.length_mm, 0.0), W = std::max(sheet.width_mm, 0.0);
  const Scale s = scale_for(L, W);
  const double margin = s.font, gap = 2.0 * s.font;

  LegendInfo info;
  info.title = params.title;
  info.sheet = sheet.index;
  info.thickness_mm = sheet.thickness_mm;
  info.material = sheet.material;
  info.length_mm = L;
  info.width_mm = W;
  info.parts = static_cast<int>(sheet.placements.size());
  info.utilisation = sheet.utilisation;
  info.time_s = params.estimated_time_s > 0.0 ? params.estimated_time_s : toolpath.time.total_s;
  info.rapids = params.show_rapids;
  info.tilt_limited = std::any_of(toolpath.moves.begin(), toolpath.moves.end(), [](const ToolMove& m) { return m.tilt_limited; });
  const Fragment leg = legend(info, s, L + gap, 0.0);

  const double doc_w = L + gap + leg.width + 2 * margin, doc_h = std::max(W, leg.height) + 2 * margin;
  std::string svg;
  auto out = std::back_inserter(svg);
  svg += "<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"no\"?>\n";
  fmt::format_to(out,
                 "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"{}mm\" height=\"{}mm\" viewBox=\"{} {} {} {}\">\n",
                 num(doc_w), num(doc_h), num(-margin), num(-margin), num(doc_w), num(doc_h));
  const std::string heading = params.title.empty() ? fmt::format("Sheet {}", sheet.index)
                                                   : fmt::format("{} - sheet {}", params.title, sheet.index);
  fmt::format_to(out, "<title>{}</title>\n", xml_escape(heading));
  svg += style_sheet(s);

  // The sheet frame: SVG y runs down, the table's y up.
  fmt::format_to(out, "<g id=\"sheet\" transform=\"translate(0 {}) scale(1 -1)\">\n", num(W));
  fmt::format_to(out, "<rect class=\"sheet\" x=\"0\" y=\"0\" width=\"{}\" height=\"{}\"/>\n", num(L), num(W));
  std::string labels;
  for (std::size_t k = 0; k < sheet.placements.size(); ++k) {
    const Placement& pl = sheet.placements[k];
    if (pl.part < 0 || pl.part >= static_cast<int>(parts.size())) continue;
    draw_part(svg, labels, static_cast<int>(k), plan, parts[static_cast<std::size_t>(pl.part)], pl, s, params);
  }
  draw_toolpath(svg, toolpath, s, params.show_rapids);
  svg += "<g class=\"labels\">\n" + labels + "</g>\n";
  svg += "</g>\n";
  svg += leg.svg;
  svg += "</svg>\n";
  return svg;
}

}  // namespace lamina
