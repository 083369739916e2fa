// surface_normal_at: the exact normal a B-rep gives, where the facet normal is a chord's.
#include "lamina/core/surface_normal.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <optional>

namespace lamina {
namespace {

constexpr double kTiny = 1e-9;

std::optional<Eigen::Vector3d> unit(const Eigen::Vector3d& v) {
  const double n = v.norm();
  if (!(n > kTiny)) return std::nullopt;
  return v / n;
}

// The unit vector from the axis to `p`, square to the axis (none on the axis itself).
std::optional<Eigen::Vector3d> radial(const BrepFace& s, const Eigen::Vector3d& p) {
  const Eigen::Vector3d d = p - s.origin;
  return unit(d - d.dot(s.axis) * s.axis);
}

// The analytic surface's normal at p, either sign; none for the other kinds or at a singularity.
std::optional<Eigen::Vector3d> analytic_normal(const BrepFace& s, const Eigen::Vector3d& p) {
  switch (s.kind) {
    case SurfaceKind::plane: return s.axis;
    case SurfaceKind::cylinder: return radial(s, p);
    case SurfaceKind::cone: {
      const auto r = radial(s, p);
      if (!r) return std::nullopt;
      return Eigen::Vector3d(std::cos(s.semi_angle_rad) * *r - std::sin(s.semi_angle_rad) * s.axis);
    }
    case SurfaceKind::sphere: return unit(p - s.origin);
    case SurfaceKind::torus: {
      const auto r = radial(s, p);
      if (!r) return std::nullopt;
      return unit(p - (s.origin + s.radius_mm * *r));
    }
    default: return std::nullopt;
  }
}

// The corners' normals, weighted by p's barycentric coordinates in the facet.
std::optional<Eigen::Vector3d> interpolated_normal(const Mesh& m, std::size_t f, const Eigen::Vector3d& p) {
  const auto& t = m.faces[f];
  const Eigen::Vector3d a = m.vertices[static_cast<std::size_t>(t[0])], b = m.vertices[static_cast<std::size_t>(t[1])],
                        c = m.vertices[static_cast<std::size_t>(t[2])];
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  if (!(n2 > 0)) return std::nullopt;
  double wb = (p - a).cross(c - a).dot(n) / n2, wc = (b - a).cross(p - a).dot(n) / n2;
  wb = std::clamp(wb, 0.0, 1.0), wc = std::clamp(wc, 0.0, 1.0 - wb);
  const double wa = 1.0 - wb - wc;
  const auto& cn = m.corner_normals[f];
  for (const auto& v : cn)
    if (!(v.squaredNorm() > 0.5f)) return std::nullopt;  // a corner without a normal: the facet's
  return unit(wa * cn[0].cast<double>() + wb * cn[1].cast<double>() + wc * cn[2].cast<double>());
}

}  // namespace

Eigen::Vector3d surface_normal_at(const Mesh& mesh, std::int32_t facet, const Eigen::Vector3d& point) {
  const auto f = static_cast<std::size_t>(facet);
  const Eigen::Vector3d& facet_normal = mesh.normals[f];
  if (mesh.corner_normals.empty()) return facet_normal;
  const auto sid = static_cast<std::size_t>(mesh.surface_id[f]);
  std::optional<Eigen::Vector3d> n;
  if (sid < mesh.brep_faces.size()) n = analytic_normal(mesh.brep_faces[sid], point);
  if (!n) n = interpolated_normal(mesh, f, point);
  if (!n) return facet_normal;
  return n->dot(facet_normal) < 0 ? Eigen::Vector3d(-*n) : *n;
}

}  // namespace lamina
