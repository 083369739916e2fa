// The edge a bevel plan's cuts leave (declared in stack_geometry.hpp): per station its pass lines
// and their lower envelope, rings of edge points at a height, and outline groups.
#include "geometry/stack_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace lamina::geometry_detail {

namespace {
bool finite2(const Eigen::Vector2d& v) { return std::isfinite(v.x()) && std::isfinite(v.y()); }
bool finite3(const Eigen::Vector3d& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }
}  // namespace

bool outline_usable(const LayerOutline& outline) {
  const std::size_t n = outline.stations.size();
  if (n < 3) return false;
  for (const auto& st : outline.stations)
    if (!finite2(st.base_mm) || !finite2(st.normal)) return false;
  for (const auto& pass : outline.passes) {
    if (pass.lines.size() != n) return false;
    for (const auto& line : pass.lines)
      if (!finite3(line.top_mm) || !finite3(line.bottom_mm)) return false;
  }
  return true;
}

void station_lines(const LayerOutline& outline, std::size_t s, std::vector<OffsetLine>& out) {
  out.clear();
  const CutStation& st = outline.stations[s];
  for (const auto& pass : outline.passes) {
    const CutLine& line = pass.lines[s];
    out.push_back({(line.bottom_mm.head<2>() - st.base_mm).dot(st.normal),
                   (line.top_mm.head<2>() - st.base_mm).dot(st.normal)});
  }
}

double station_offset(const LayerOutline& outline, std::size_t s, double t) {
  if (outline.passes.empty()) return 0.0;
  const CutStation& st = outline.stations[s];
  double u = std::numeric_limits<double>::infinity();
  for (const auto& pass : outline.passes) {
    const CutLine& line = pass.lines[s];
    const double ub = (line.bottom_mm.head<2>() - st.base_mm).dot(st.normal);
    const double ut = (line.top_mm.head<2>() - st.base_mm).dot(st.normal);
    u = std::min(u, ub + t * (ut - ub));
  }
  return u;
}

void envelope_kinks(const std::vector<OffsetLine>& lines, std::vector<double>& ts) {
  ts.clear();
  if (lines.size() < 2) return;
  auto slope = [&](std::size_t i) { return lines[i].top - lines[i].bottom; };
  // Active line at t = 0: the lowest, ties to the one that falls fastest.
  std::size_t active = 0;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    if (lines[i].bottom < lines[active].bottom ||
        (lines[i].bottom == lines[active].bottom && slope(i) < slope(active)))
      active = i;
  }
  double t = 0.0;
  for (std::size_t guard = 0; guard < lines.size(); ++guard) {
    // The next line to undercut the active one: only lines falling faster can.
    double best_t = 1.0;
    std::size_t next = active;
    for (std::size_t i = 0; i < lines.size(); ++i) {
      const double ds = slope(active) - slope(i);
      if (!(ds > 0.0)) continue;
      const double ti = (lines[i].bottom - lines[active].bottom) / ds;
      if (ti < t) continue;
      if (ti < best_t || (ti == best_t && next != active && slope(i) < slope(next))) {
        best_t = ti;
        next = i;
      }
    }
    if (next == active || !(best_t < 1.0)) break;
    if (best_t > 0.0) ts.push_back(best_t);
    t = best_t;
    active = next;
  }
  ts.erase(std::unique(ts.begin(), ts.end()), ts.end());
}

double layer_t(const LayerPlan& layer, double z_mm) {
  return layer.thickness_mm > 0.0 ? (z_mm - layer.z_bottom_mm) / layer.thickness_mm : 0.0;
}

Polygon2 base_ring(const LayerOutline& outline) {
  Polygon2 ring;
  ring.reserve(outline.stations.size());
  for (const auto& st : outline.stations) ring.push_back(st.base_mm);
  return ring;
}

Polygon2 edge_ring(const LayerOutline& outline, double t) {
  Polygon2 ring;
  ring.reserve(outline.stations.size());
  for (std::size_t s = 0; s < outline.stations.size(); ++s) {
    const CutStation& st = outline.stations[s];
    ring.push_back(st.base_mm + station_offset(outline, s, t) * st.normal);
  }
  return ring;
}

double reversed_share(const Polygon2& ring, const Polygon2& base) {
  const std::size_t n = base.size();
  double total = 0.0, reversed = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    const Eigen::Vector2d b = base[j] - base[i];
    const double len = b.norm();
    total += len;
    if ((ring[j] - ring[i]).dot(b) < 0.0) reversed += len;
  }
  return total > 0.0 ? reversed / total : 0.0;
}

std::vector<OutlineGroup> outline_groups(const LayerPlan& layer) {
  std::vector<OutlineGroup> groups;
  std::vector<int> group_of(layer.outlines.size(), -1);
  for (std::size_t i = 0; i < layer.outlines.size(); ++i) {
    const LayerOutline& o = layer.outlines[i];
    if (o.is_hole || !outline_usable(o)) continue;
    group_of[i] = static_cast<int>(groups.size());
    groups.push_back({static_cast<int>(i), {}});
  }
  for (std::size_t i = 0; i < layer.outlines.size(); ++i) {
    const LayerOutline& o = layer.outlines[i];
    if (!o.is_hole || !outline_usable(o)) continue;
    if (o.parent < 0 || static_cast<std::size_t>(o.parent) >= layer.outlines.size()) continue;
    const int g = group_of[static_cast<std::size_t>(o.parent)];
    if (g >= 0) groups[static_cast<std::size_t>(g)].holes.push_back(static_cast<int>(i));
  }
  return groups;
}

}  // namespace lamina::geometry_detail
