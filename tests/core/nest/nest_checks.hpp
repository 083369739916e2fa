#pragma once
// Hand-built parts and the checks every nest must pass (Clipper 6 booleans at 1 nm).
#include "lamina/core/nest.hpp"

#include <gtest/gtest.h>
#include <polyclipping/clipper.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <string>
#include <vector>

namespace lamina::nest_test {

inline constexpr double kNm = 1e6;  // Clipper units per mm

inline Polygon2 rect(double w, double h, double x = 0, double y = 0) {
  return {{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}};
}
// L: w x h with the top-right (w - leg) x (h - leg) corner cut away.
inline Polygon2 ell(double w, double h, double leg, double x = 0, double y = 0) {
  return {{x, y}, {x + w, y}, {x + w, y + leg}, {x + leg, y + leg}, {x + leg, y + h}, {x, y + h}};
}
inline Polygon2 triangle(double b, double h, double x = 0, double y = 0) { return {{x, y}, {x + b, y}, {x, y + h}}; }
inline Polygon2 circle(double r, int n = 48, double cx = 0, double cy = 0) {
  Polygon2 p;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * i / n;
    p.emplace_back(cx + r * std::cos(a), cy + r * std::sin(a));
  }
  return p;
}

// A part as make_parts would give it: the footprint already includes half the kerf.
inline Part make_part(Polygon2 footprint, double thickness, int layer, int island, double hole_area = 0.0) {
  Part p;
  p.layer = layer;
  p.island = island;
  p.thickness_mm = thickness;
  p.area_mm2 = signed_area_mm2(footprint) - hole_area;
  p.footprint_mm = std::move(footprint);
  return p;
}

inline ClipperLib::Path to_path(const Polygon2& ring) {
  ClipperLib::Path path;
  for (const auto& p : ring) path.emplace_back(std::llround(p.x() * kNm), std::llround(p.y() * kNm));
  return path;
}
inline double area_mm2(const ClipperLib::Paths& paths) {
  double a = 0;
  for (const auto& p : paths) a += ClipperLib::Area(p);
  return a / (kNm * kNm);
}
inline ClipperLib::Paths grow(const Polygon2& ring, double by_mm) {
  ClipperLib::ClipperOffset off;
  off.ArcTolerance = 1e-3 * kNm;  // chords inside the arc by <= 1 µm
  off.AddPath(to_path(ring), ClipperLib::jtRound, ClipperLib::etClosedPolygon);
  ClipperLib::Paths out;
  off.Execute(out, by_mm * kNm);
  return out;
}

struct Summary {
  int sheets = 0;
  double mean_utilisation = 0.0;
  int hosted = 0;        // placements with a host
  int nested_pairs = 0;  // pairs closer than the spacing because one is in the other's hole
};

// Whether `ring` lies inside one of `holes` (placed free holes of another part) at least `spacing`
// (less 0.1 µm and the 1 µm chords of the round growth) from the hole's free ring.
inline bool inside_holes(const Polygon2& ring, const std::vector<Polygon2>& holes, double spacing) {
  if (holes.empty()) return false;
  const double by = spacing - 1e-4;
  ClipperLib::Clipper c;
  c.AddPaths(by > 0 ? grow(ring, by) : ClipperLib::Paths{to_path(ring)}, ClipperLib::ptSubject, true);
  for (const auto& h : holes) c.AddPath(to_path(h), ClipperLib::ptClip, true);
  ClipperLib::Paths outside;
  c.Execute(ClipperLib::ctDifference, outside, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  return area_mm2(outside) == 0.0;
}

inline std::vector<Polygon2> placed_free_holes(const Part& part, const Placement& pl) {
  std::vector<Polygon2> out;
  for (const auto& h : part.free_holes_mm) {
    Polygon2 r;
    for (const auto& p : h) r.push_back(place_point(pl, p));
    out.push_back(std::move(r));
  }
  return out;
}

// Every invariant of a nest; returns the sheet count and the mean utilisation. Two footprints may
// come closer than the spacing (overlap) only when one lies inside a free hole of the other at
// least the spacing from the hole's free ring; it must then come first on the sheet (cut before
// its host), and a placement's `host` must be such a part.
inline Summary check_nest(std::span<const Part> parts, const Stock& stock, const NestParams& params, const Nest& nest) {
  std::vector<int> seen(parts.size(), 0);
  std::map<int, int> used_per_entry;
  double prev_thickness = 0.0;
  double util_sum = 0.0;
  int hosted = 0;
  int nested_pairs = 0;
  for (std::size_t s = 0; s < nest.sheets.size(); ++s) {
    const NestedSheet& sheet = nest.sheets[s];
    SCOPED_TRACE("sheet " + std::to_string(sheet.index));
    EXPECT_EQ(sheet.index, static_cast<int>(s) + 1);
    EXPECT_GE(sheet.thickness_mm, prev_thickness) << "thin sheets come first";
    prev_thickness = sheet.thickness_mm;
    if (sheet.stock_index < 0 || sheet.stock_index >= static_cast<int>(stock.sheets.size())) {
      ADD_FAILURE() << "stock index " << sheet.stock_index;
      return {};
    }
    const SheetStock& st = stock.sheets[sheet.stock_index];
    EXPECT_EQ(sheet.thickness_mm, st.thickness_mm);
    EXPECT_EQ(sheet.width_mm, st.width_mm);
    EXPECT_EQ(sheet.length_mm, st.length_mm);
    ++used_per_entry[sheet.stock_index];
    EXPECT_FALSE(sheet.placements.empty());

    const double m = params.margin_mm;
    const Polygon2 usable = rect(st.length_mm - 2 * m, st.width_mm - 2 * m, m, m);
    std::vector<Polygon2> placed;
    double part_area = 0.0;
    for (const Placement& pl : sheet.placements) {
      if (pl.part < 0 || pl.part >= static_cast<int>(parts.size())) {
        ADD_FAILURE() << "part index " << pl.part;
        return {};
      }
      ++seen[pl.part];
      const Part& part = parts[pl.part];
      EXPECT_NEAR(part.thickness_mm, sheet.thickness_mm, 1e-9);
      part_area += part.area_mm2;
      placed.push_back(placed_footprint(part, pl));
      // Inside the sheet minus the margin: nothing of the footprint outside.
      ClipperLib::Clipper c;
      c.AddPath(to_path(placed.back()), ClipperLib::ptSubject, true);
      c.AddPath(to_path(usable), ClipperLib::ptClip, true);
      ClipperLib::Paths outside;
      c.Execute(ClipperLib::ctDifference, outside, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
      EXPECT_EQ(area_mm2(outside), 0.0) << "part L" << part.layer << "-" << part.island << " outside the margin";
    }
    EXPECT_NEAR(sheet.utilisation, part_area / (st.width_mm * st.length_mm), 1e-12);
    util_sum += sheet.utilisation;
    // Pairwise at least `spacing` apart: the footprints grown by spacing/2 (less 0.1 µm) are disjoint.
    const double half = 0.5 * params.spacing_mm - 1e-4;
    std::vector<ClipperLib::Paths> grown;
    std::vector<ClipperLib::IntRect> boxes;
    for (const auto& f : placed) {
      grown.push_back(half > 0 ? grow(f, half) : ClipperLib::Paths{to_path(f)});
      ClipperLib::IntRect b{INT64_MAX, INT64_MAX, INT64_MIN, INT64_MIN};
      for (const auto& path : grown.back())
        for (const auto& q : path) {
          b.left = std::min(b.left, q.X);
          b.right = std::max(b.right, q.X);
          b.top = std::min(b.top, q.Y);
          b.bottom = std::max(b.bottom, q.Y);
        }
      boxes.push_back(b);
    }
    for (std::size_t i = 0; i < placed.size(); ++i) {
      for (std::size_t j = i + 1; j < placed.size(); ++j) {
        const auto& a = boxes[i];
        const auto& b = boxes[j];
        if (a.right < b.left || b.right < a.left || a.bottom < b.top || b.bottom < a.top) continue;
        ClipperLib::Clipper c;
        c.AddPaths(grown[i], ClipperLib::ptSubject, true);
        c.AddPaths(grown[j], ClipperLib::ptClip, true);
        ClipperLib::Paths both;
        c.Execute(ClipperLib::ctIntersection, both, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
        if (area_mm2(both) == 0.0) continue;
        const Placement& pi = sheet.placements[i];
        const Placement& pj = sheet.placements[j];
        if (inside_holes(placed[i], placed_free_holes(parts[pj.part], pj), params.spacing_mm)) {
          ++nested_pairs;
          continue;  // i (listed first) in a hole of j: cut before j
        }
        if (inside_holes(placed[j], placed_free_holes(parts[pi.part], pi), params.spacing_mm)) {
          ADD_FAILURE() << "placement " << j << " lies in a hole of placement " << i << " but comes after it";
          continue;
        }
        ADD_FAILURE() << "placements " << i << " and " << j << " closer than the spacing";
      }
    }
    for (std::size_t i = 0; i < sheet.placements.size(); ++i) {
      const int h = sheet.placements[i].host;
      if (h < 0) continue;
      ++hosted;
      if (h <= static_cast<int>(i) || h >= static_cast<int>(sheet.placements.size())) {
        ADD_FAILURE() << "placement " << i << " names host " << h << ": hosts come after their children";
        continue;
      }
      const Placement& hp = sheet.placements[static_cast<std::size_t>(h)];
      EXPECT_TRUE(inside_holes(placed[i], placed_free_holes(parts[hp.part], hp), params.spacing_mm))
          << "placement " << i << " is not inside a free hole of its host " << h;
    }
  }
  for (std::size_t i = 0; i < parts.size(); ++i) EXPECT_EQ(seen[i], 1) << "part " << i << " placed once";
  for (auto [entry, used] : used_per_entry) {
    if (stock.sheets[entry].count > 0) {
      EXPECT_LE(used, stock.sheets[entry].count) << "stock entry " << entry;
    }
  }
  Summary s;
  s.sheets = static_cast<int>(nest.sheets.size());
  s.mean_utilisation = nest.sheets.empty() ? 0.0 : util_sum / static_cast<double>(nest.sheets.size());
  s.hosted = hosted;
  s.nested_pairs = nested_pairs;
  return s;
}

inline Stock one_sheet_kind(double thickness, double length, double width, int count = 0) {
  Stock s;
  s.sheets.push_back({thickness, width, length, count, "aluminium", ""});
  return s;
}

}  // namespace lamina::nest_test
