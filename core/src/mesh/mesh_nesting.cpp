// Step 6b of build_mesh, helper: how deep each closed shell is nested in the others.
//
// Shell s is inside closed shell t when t's box holds s's box, t encloses more volume, and three
// points on s (its largest facet's centroid and two more) are all inside t by ray parity. Each
// parity is the majority of three rays in skew directions (a ray through an edge or vertex of an
// axis-aligned CAD mesh is then unlikely, and one such accident is outvoted). The facets of a
// container are binned, per direction, on a grid in the plane across the ray, so a query meets
// only the facets whose shadow covers its cell: a part with thousands of voids stays fast.
#include "mesh/mesh_internal.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <utility>
#include <cmath>
#include <memory>
#include <optional>

namespace lamina::mesh_detail {
namespace {

const Eigen::Vector3d kDirs[3] = {Eigen::Vector3d(0.2113249, 0.3471105, 0.9137).normalized(),
                                  Eigen::Vector3d(-0.5773503, 0.1339746, -0.8053).normalized(),
                                  Eigen::Vector3d(0.7071068, -0.6180340, 0.3435).normalized()};

// Möller–Trumbore: does the ray p + t·d, t > 0, cross triangle abc?
bool ray_hits(const Eigen::Vector3d& p, const Eigen::Vector3d& d, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
              const Eigen::Vector3d& c) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d h = d.cross(e2);
  const double det = e1.dot(h);
  if (det == 0.0) return false;
  const double inv = 1.0 / det;
  const Eigen::Vector3d s = p - a;
  const double u = s.dot(h) * inv;
  if (u < 0.0 || u > 1.0) return false;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = d.dot(q) * inv;
  if (v < 0.0 || u + v > 1.0) return false;
  return e2.dot(q) * inv > 0.0;
}

// A shell's facets binned by their projection on the plane across direction d.
class RayGrid {
 public:
  RayGrid(const Mesh& m, const std::int32_t* facets, std::size_t n, const Eigen::Vector3d& d) : m_(&m), d_(d) {
    const Eigen::Vector3d e = std::abs(d.x()) < 0.5 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    u_ = d.cross(e).normalized();
    v_ = d.cross(u_);
    std::vector<Eigen::Vector4d> shadow(n);  // (u min, u max, v min, v max) per facet
    lo_ = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector2d hi = -lo_;
    for (std::size_t i = 0; i < n; ++i) {
      const Tri& t = m.faces[static_cast<std::size_t>(facets[i])];
      Eigen::Vector4d s(std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity());
      for (const std::int32_t v : t) {
        const Eigen::Vector2d q = project(m.vertices[static_cast<std::size_t>(v)]);
        s = Eigen::Vector4d(std::min(s[0], q.x()), std::max(s[1], q.x()), std::min(s[2], q.y()), std::max(s[3], q.y()));
      }
      shadow[i] = s;
      lo_ = lo_.cwiseMin(Eigen::Vector2d(s[0], s[2]));
      hi = hi.cwiseMax(Eigen::Vector2d(s[1], s[3]));
    }
    cells_ = std::clamp(static_cast<int>(std::sqrt(static_cast<double>(n))), 1, 1024);
    const Eigen::Vector2d ext = (hi - lo_).cwiseMax(1e-300);
    inv_ = Eigen::Vector2d(cells_ / ext.x(), cells_ / ext.y());
    start_.assign(static_cast<std::size_t>(cells_) * static_cast<std::size_t>(cells_) + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
      for (std::size_t i = 0; i < n; ++i) {
        const auto [c0, c1] = cell_of(Eigen::Vector2d(shadow[i][0], shadow[i][2]));
        const auto [d0, d1] = cell_of(Eigen::Vector2d(shadow[i][1], shadow[i][3]));
        for (int a = c0; a <= d0; ++a)
          for (int b = c1; b <= d1; ++b) {
            const std::size_t c = static_cast<std::size_t>(a) * static_cast<std::size_t>(cells_) + static_cast<std::size_t>(b);
            if (pass == 0)
              ++start_[c + 1];
            else
              items_[static_cast<std::size_t>(fill_[c]++)] = facets[i];
          }
      }
      if (pass == 0) {
        for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
        items_.resize(static_cast<std::size_t>(start_.back()));
        fill_.assign(start_.begin(), start_.end() - 1);
      }
    }
    fill_ = {};
  }

  // Does the ray from p along d cross the shell an odd number of times?
  bool odd(const Eigen::Vector3d& p) const {
    const Eigen::Vector2d r = (project(p) - lo_).cwiseProduct(inv_);
    if (!(r.x() >= 0.0 && r.y() >= 0.0 && r.x() <= cells_ && r.y() <= cells_)) return false;  // outside every shadow
    const auto [a, b] = cell_of(project(p));
    const std::size_t c = static_cast<std::size_t>(a) * static_cast<std::size_t>(cells_) + static_cast<std::size_t>(b);
    bool parity = false;
    for (auto i = start_[c]; i < start_[c + 1]; ++i) {
      const Tri& t = m_->faces[static_cast<std::size_t>(items_[static_cast<std::size_t>(i)])];
      parity ^= ray_hits(p, d_, m_->vertices[static_cast<std::size_t>(t[0])], m_->vertices[static_cast<std::size_t>(t[1])],
                         m_->vertices[static_cast<std::size_t>(t[2])]);
    }
    return parity;
  }

 private:
  Eigen::Vector2d project(const Eigen::Vector3d& p) const { return Eigen::Vector2d(u_.dot(p), v_.dot(p)); }
  std::pair<int, int> cell_of(const Eigen::Vector2d& q) const {
    const Eigen::Vector2d r = (q - lo_).cwiseProduct(inv_);
    return {std::clamp(static_cast<int>(r.x()), 0, cells_ - 1), std::clamp(static_cast<int>(r.y()), 0, cells_ - 1)};
  }

  const Mesh* m_;
  Eigen::Vector3d d_, u_, v_;
  Eigen::Vector2d lo_, inv_;
  int cells_ = 1;
  std::vector<std::int32_t> start_, fill_, items_;
};

double facet_area2(const Mesh& m, std::int32_t f) {
  const Tri& t = m.faces[static_cast<std::size_t>(f)];
  const Eigen::Vector3d& a = m.vertices[static_cast<std::size_t>(t[0])];
  return (m.vertices[static_cast<std::size_t>(t[1])] - a).cross(m.vertices[static_cast<std::size_t>(t[2])] - a).squaredNorm();
}

}  // namespace

std::vector<int> nesting_depths(const Mesh& m, const ShellFaces& sf, const std::vector<std::size_t>& closed,
                                const std::vector<Box3>& box, const std::vector<double>& vol) {
  std::vector<int> depth(box.size(), 0);
  if (closed.size() < 2) return depth;
  // Ray grids of a container, built the first time it is asked.
  std::vector<std::unique_ptr<RayGrid[]>> grids(box.size());
  auto inside = [&](std::size_t t, const Eigen::Vector3d& p) {
    if (!grids[t]) {
      const std::int32_t* fs = sf.order.data() + sf.begin[t];
      const auto n = static_cast<std::size_t>(sf.begin[t + 1] - sf.begin[t]);
      grids[t].reset(new RayGrid[3]{RayGrid(m, fs, n, kDirs[0]), RayGrid(m, fs, n, kDirs[1]), RayGrid(m, fs, n, kDirs[2])});
    }
    int votes = 0;
    for (int k = 0; k < 3; ++k) votes += grids[t][k].odd(p) ? 1 : 0;
    return votes >= 2;
  };

  for (const std::size_t s : closed) {
    const double slack = 1e-9 * (box[s].hi - box[s].lo).norm();
    const std::int32_t* fs = sf.order.data() + sf.begin[s];
    const auto n = static_cast<std::size_t>(sf.begin[s + 1] - sf.begin[s]);
    std::optional<std::array<Eigen::Vector3d, 3>> probes;
    for (const std::size_t t : closed) {
      if (t == s || std::abs(vol[t]) <= std::abs(vol[s]) || !box[t].contains(box[s], slack)) continue;
      if (!probes) {
        std::size_t big = 0;
        double big_a = -1.0;
        for (std::size_t i = 0; i < n; ++i) {
          const double a = facet_area2(m, fs[i]);
          if (a > big_a) big_a = a, big = i;
        }
        probes = std::array<Eigen::Vector3d, 3>{centroid(m, static_cast<std::size_t>(fs[big])),
                                                centroid(m, static_cast<std::size_t>(fs[n / 3])),
                                                centroid(m, static_cast<std::size_t>(fs[(2 * n) / 3]))};
      }
      bool all_inside = true;
      for (const auto& p : *probes) {
        if (!box[t].contains(p) || !inside(t, p)) {
          all_inside = false;
          break;
        }
      }
      if (all_inside) ++depth[s];
    }
  }
  return depth;
}

}  // namespace lamina::mesh_detail
