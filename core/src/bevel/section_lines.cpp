// Line queries against one slice through a uniform grid of its contour vectors. The paper finds
// corresponding points by intersecting a line with "a short list of line segments"; the grid is
// that short list.
#include "lamina/core/section_lines.hpp"
#include "lamina/core/surface_normal.hpp"

#include <algorithm>
#include <iterator>
#include <cmath>
#include <limits>
#include <span>

namespace lamina {

namespace {
double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Whether the path a → b crosses the contour vector c → d. An end of c → d on the path's line
// counts as lying on its right, and an end of the path on the vector's line as lying on its
// right: the parity along a path made of such pieces is that of the path moved off those
// coincidences by an infinitesimal amount (a vertex of a loop on the path is crossed once or
// not at all, never twice).
bool path_crosses(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c, const Eigen::Vector2d& d) {
  const Eigen::Vector2d ab = b - a, cd = d - c;
  if ((cross(ab, c - a) > 0.0) == (cross(ab, d - a) > 0.0)) return false;
  return (cross(cd, a - c) > 0.0) != (cross(cd, b - c) > 0.0);
}

// p on the vector a → b, to rounding (1e-9 of the vector's length).
bool on_segment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a, ap = p - a;
  const double len2 = ab.squaredNorm();
  if (std::abs(cross(ab, ap)) > 1e-9 * len2) return false;
  const double t = ab.dot(ap);
  return t >= 0.0 && t <= len2;
}
}  // namespace

double profile_slope(const Eigen::Vector3d& normal, const Eigen::Vector2d& direction) {
  // The facet plane n·x = 0 traced in the plane spanned by (direction, z): n_h·d·u + n_z·z = 0.
  constexpr double kSteep = 1e6;
  const double nd = normal.x() * direction.x() + normal.y() * direction.y();
  const double nz = normal.z();
  if (std::abs(nz) < 1e-15) return 0.0;
  if (std::abs(nd) * kSteep <= std::abs(nz)) return nd * nz > 0 ? -kSteep : kSteep;
  return -nz / nd;
}

SectionLines::SectionLines(const Mesh& mesh, const Slice& slice, SectionQueries queries)
    : mesh_(&mesh), z_mm_(slice.z_mm) {
  std::size_t n = 0;
  for (const auto& l : slice.loops) n += l.size();
  segments_.reserve(n);
  Eigen::Vector2d lo(std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (const auto& l : slice.loops) {
    const std::size_t m = l.size();
    for (std::size_t i = 0; i < m; ++i) {
      Segment s;
      s.a = l.points[i];
      s.b = l.points[(i + 1) % m];
      s.facet = l.facets[i];
      lo = lo.cwiseMin(s.a).cwiseMin(s.b);
      hi = hi.cwiseMax(s.a).cwiseMax(s.b);
      segments_.push_back(s);
    }
  }
  if (segments_.empty()) return;
  std::vector<Box2> boxes;
  boxes.reserve(segments_.size());
  for (const auto& s : segments_) boxes.push_back({s.a.cwiseMin(s.b), s.a.cwiseMax(s.b)});
  // About one segment per cell on average: contours are long thin sets, so use the extent.
  grid_ = BoxGrid(boxes, [](const Eigen::Vector2d& size, std::size_t count) {
    const double cells_wanted = std::max<double>(1.0, static_cast<double>(count));
    const double cell = std::max(std::sqrt(size.x() * size.y() / cells_wanted), std::max(size.x(), size.y()) / 4096.0);
    return std::max(cell, 1e-6);
  });
  if (queries == SectionQueries::crossings_and_contains) build_inside_grid(boxes);
}

// Cells about two vectors long (at most 16 cells per vector over the extent), and whether each
// cell's centre is material: along each row of cells, from left of the grid (outside every loop)
// through the centres of its cells, each step crossing only vectors listed in the two cells it
// joins.
void SectionLines::build_inside_grid(const std::vector<Box2>& boxes) {
  double length = 0.0;
  for (const Segment& s : segments_) length += (s.b - s.a).norm();
  const double mean = length / static_cast<double>(segments_.size());
  inside_grid_ = BoxGrid(boxes, [mean](const Eigen::Vector2d& size, std::size_t count) {
    const double most_cells = 16.0 * static_cast<double>(count);
    return std::max({2.0 * mean, std::sqrt(size.x() * size.y() / most_cells), std::max(size.x(), size.y()) / 4096.0, 1e-6});
  });
  const BoxGrid& grid = inside_grid_;
  const int nx = grid.nx(), ny = grid.ny();
  centre_inside_.assign(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny), 0);
  std::vector<std::uint32_t> both;
  for (int cy = 0; cy < ny; ++cy) {
    const double y = grid.origin().y() + (cy + 0.5) * grid.cell_mm();
    Eigen::Vector2d from(grid.origin().x() - grid.cell_mm(), y);  // left of every vector
    bool inside = false;
    std::span<const std::uint32_t> previous;
    for (int cx = 0; cx < nx; ++cx) {
      const std::size_t cell = grid.cell(cx, cy);
      const Eigen::Vector2d to(grid.origin().x() + (cx + 0.5) * grid.cell_mm(), y);
      const std::span<const std::uint32_t> here = grid.items(cell);
      both.clear();
      std::set_union(previous.begin(), previous.end(), here.begin(), here.end(), std::back_inserter(both));
      for (const std::uint32_t idx : both)
        if (path_crosses(from, to, segments_[idx].a, segments_[idx].b)) inside = !inside;
      centre_inside_[cell] = inside ? 1 : 0;
      from = to;
      previous = here;
    }
  }
}

namespace {
// Narrows [t0, t1] of the line origin + t·direction to the grid's box (slab test); false when
// the line misses the box there.
bool clip_to_grid(const BoxGrid& grid, const Eigen::Vector2d& origin, const Eigen::Vector2d& direction, double& t0,
                  double& t1) {
  const Eigen::Vector2d& box_lo = grid.origin();
  const Eigen::Vector2d box_hi = grid.origin() + Eigen::Vector2d(grid.nx(), grid.ny()) * grid.cell_mm();
  for (int k = 0; k < 2; ++k) {
    if (std::abs(direction[k]) < 1e-300) {
      if (origin[k] < box_lo[k] || origin[k] > box_hi[k]) return false;
      continue;
    }
    double a = (box_lo[k] - origin[k]) / direction[k];
    double b = (box_hi[k] - origin[k]) / direction[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  return t0 <= t1;
}
}  // namespace

namespace {

// Walks the cells the line origin + t·dir crosses for t in [t0, t1], in order (Amanatides & Woo),
// calling visit(cell, t_entry) with the t at which the line enters the cell; stops when visit
// returns false.
template <class Visit>
void walk_cells(const BoxGrid& grid, const Eigen::Vector2d& origin, const Eigen::Vector2d& dir, double t0, double t1,
                Visit&& visit) {
  if (!(t1 >= t0) || !clip_to_grid(grid, origin, dir, t0, t1)) return;
  const Eigen::Vector2d& grid_origin = grid.origin();
  const double cell_mm = grid.cell_mm();
  const int nx = grid.nx(), ny = grid.ny();
  const Eigen::Vector2d start = origin + t0 * dir;
  int cx = grid.column(start.x()), cy = grid.row(start.y());
  const int step_x = dir.x() > 0 ? 1 : -1;
  const int step_y = dir.y() > 0 ? 1 : -1;
  const double inf = std::numeric_limits<double>::infinity();
  const double dt_x = std::abs(dir.x()) > 1e-300 ? cell_mm / std::abs(dir.x()) : inf;
  const double dt_y = std::abs(dir.y()) > 1e-300 ? cell_mm / std::abs(dir.y()) : inf;
  auto boundary_t = [&](int c, int step, int k) {
    if (std::abs(dir[k]) < 1e-300) return inf;
    const double edge = grid_origin[k] + (c + (step > 0 ? 1 : 0)) * cell_mm;
    return (edge - origin[k]) / dir[k];
  };
  double next_x = boundary_t(cx, step_x, 0);
  double next_y = boundary_t(cy, step_y, 1);
  double t_entry = t0;
  while (visit(grid.cell(cx, cy), t_entry)) {
    t_entry = std::min(next_x, next_y);
    if (t_entry > t1) break;
    if (next_x < next_y) {
      cx += step_x;
      next_x += dt_x;
      if (cx < 0 || cx >= nx) break;
    } else {
      cy += step_y;
      next_y += dt_y;
      if (cy < 0 || cy >= ny) break;
    }
  }
}

}  // namespace

std::optional<LineCrossing> SectionLines::exit_crossing(const Eigen::Vector2d& origin, const Eigen::Vector2d& direction,
                                                        double u_min, double u_max, CrossingPick pick) const {
  if (segments_.empty() || !(u_max >= u_min)) return std::nullopt;
  const double inf = std::numeric_limits<double>::infinity();
  std::optional<LineCrossing> best;
  double best_key = inf;  // |u| (nearest_zero) or −u (largest): smaller is better
  std::uint32_t seen[64];
  int seen_count = 0;
  auto consider = [&](std::uint32_t idx) {
    for (int i = 0; i < seen_count; ++i) {
      if (seen[i] == idx) return;
    }
    if (seen_count < 64) seen[seen_count++] = idx;
    const Segment& s = segments_[idx];
    const Eigen::Vector2d e = s.b - s.a;
    const double denom = cross(direction, e);
    if (std::abs(denom) < 1e-300) return;
    const Eigen::Vector2d w = s.a - origin;
    const double u = cross(w, e) / denom;
    const double t = cross(w, direction) / denom;
    if (t < 0.0 || t >= 1.0 || u < u_min || u > u_max) return;
    // Material is on the left of e; leaving it towards +u means the left side faces −direction.
    const Eigen::Vector2d left(-e.y(), e.x());
    if (left.dot(direction) >= 0.0) return;
    const double key = pick == CrossingPick::largest ? -u : std::abs(u);
    // Equal keys (u = ±a from the middle of a slot) go to the smaller u, whatever the walk's order.
    if (key < best_key || (key == best_key && best && u < best->u_mm)) {
      best_key = key;
      best = LineCrossing{u, Eigen::Vector3d::Zero(), -1, static_cast<std::int32_t>(idx)};  // completed below
    }
  };
  // Each walk runs where its t is the key (|u| outwards from u = 0, or −u inwards from u_max):
  // a crossing not yet found lies in a cell not yet entered, so at a key of at least that cell's
  // entry, and the walk stops once the entry is past the best key found.
  auto visit = [&](std::span<const std::uint32_t> items, double t_entry) {
    if (t_entry > best_key) return false;
    for (const std::uint32_t idx : items) consider(idx);
    if (seen_count >= 64) seen_count = 0;  // long walks: forget old ones (re-testing is harmless)
    return true;
  };
  auto walk = [&](const Eigen::Vector2d& dir, double t0, double t1) {
    walk_cells(grid_, origin, dir, t0, t1, [&](std::size_t cell, double t) { return visit(grid_.items(cell), t); });
  };
  if (pick == CrossingPick::largest) {
    walk(-direction, -u_max, -u_min);
  } else {
    walk(direction, std::max(0.0, u_min), u_max);
    walk(-direction, std::max(0.0, -u_max), -u_min);
  }
  if (best) *best = crossing_at(static_cast<std::size_t>(best->facet), best->u_mm);
  return best;
}

LineCrossing SectionLines::crossing_at(std::size_t index, double u_mm) const {
  const Segment& s = segments_[index];
  LineCrossing c{u_mm, Eigen::Vector3d::Zero(), -1, s.facet};
  if (s.facet >= 0) {
    // A B-rep's surface normal half-way along the crossing (the facet's own for a mesh).
    const Eigen::Vector2d mid = 0.5 * (s.a + s.b);
    c.normal = surface_normal_at(*mesh_, s.facet, Eigen::Vector3d(mid.x(), mid.y(), z_mm_));
    c.surface_id = mesh_->surface_id[static_cast<std::size_t>(s.facet)];
  } else {
    const Eigen::Vector2d d = (s.b - s.a).normalized();
    c.normal = Eigen::Vector3d(d.y(), -d.x(), 0.0);
  }
  return c;
}

bool SectionLines::contains(const Eigen::Vector2d& p) const {
  if (segments_.empty()) return false;
  if (inside_grid_.empty()) {  // not built for it: every vector, by a ray to the left of the extent
    const Eigen::Vector2d far(grid_.origin().x() - grid_.cell_mm(), p.y());
    bool inside = false;
    for (const Segment& s : segments_) {
      if (on_segment(p, s.a, s.b)) return true;
      if (path_crosses(far, p, s.a, s.b)) inside = !inside;
    }
    return inside;
  }
  const BoxGrid& grid = inside_grid_;
  const Eigen::Vector2d g = (p - grid.origin()) / grid.cell_mm();
  if (!(g.x() >= 0.0 && g.x() < grid.nx() && g.y() >= 0.0 && g.y() < grid.ny())) return false;
  const int cx = static_cast<int>(g.x()), cy = static_cast<int>(g.y());
  const std::size_t cell = grid.cell(cx, cy);
  const Eigen::Vector2d centre = grid.origin() + Eigen::Vector2d(cx + 0.5, cy + 0.5) * grid.cell_mm();
  bool inside = centre_inside_[cell] != 0;
  for (const std::uint32_t idx : grid.items(cell)) {
    const Segment& s = segments_[idx];
    if (on_segment(p, s.a, s.b)) return true;  // the section is closed: its boundary is material
    if (path_crosses(centre, p, s.a, s.b)) inside = !inside;
  }
  return inside;
}

}  // namespace lamina
