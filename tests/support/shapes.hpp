#pragma once
// Header-only mesh generators for tests and benchmarks, with the EXACT section areas and
// volumes of the faceted solids they produce.
//
// Every generator returns a closed, watertight, consistently oriented lamina::TriangleSoup
// whose triangles wind counter-clockwise seen from outside (outward normals). Each vertex is
// computed once (in double, then rounded to float) and shared, so neighbouring triangles use
// bit-identical corners and a welder joins them without any tolerance.
//
// Frames (the ORIGINAL frame of each shape; the slicer moves the lowest point to z = 0, so a
// test either shifts the soup with translated()/lowest_z() or shifts its query heights):
//   uv_sphere: centred at the origin, z in [-radius, radius] (the poles are exact vertices).
//   tube:      axis = z, from z = 0 to z = height (already on the build plate).
//   torus:     axis = z, centred at the origin, z in [torus_z_min(), torus_z_max()]
//              (= [-minor_r, minor_r] when minor_segments is a multiple of 4).
// Meridians are at angles 2*pi*j/segments from +x, so every horizontal section of these
// solids is a REGULAR polygon (or polygon annulus) with a vertex on the +x axis.
//
// Why the section areas are exact: the quad between two adjacent meridians and two adjacent
// profile vertices is a planar isosceles trapezoid, so a horizontal plane cuts it along a chord
// whose ends lie on the two meridian edges at the SAME radius, linearly interpolated between the
// radii of the edge's ends. The section is therefore a regular n-gon of circumradius rho(z):
// area = n/2 * rho^2 * sin(2*pi/n) (an annulus: outer minus inner). The *_section_area functions
// compute this in double from the same double vertex positions as the generators; the soup holds
// them rounded to float, so compare with a tolerance, not exactly: 1e-6 * pi * R^2 (R the
// largest radius of the shape) covers the float rounding with margin; measured worst cases are
// 10x-100x below it (e.g. 5e-4 mm^2 for a section of ~7000 mm^2), anywhere in z, tips included.
// At heights where the plane contains a horizontal face (tube caps; the top and bottom faces of
// a torus whose minor_segments is even but not a multiple of 4) the value returned is the limit
// from inside the solid; tests should not slice exactly there.
#include <lamina/core/triangle_soup.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross()

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

namespace lamina::test {

// Area of a regular n-gon of circumradius rho.
inline double regular_polygon_area(int n, double rho) {
  return 0.5 * n * rho * rho * std::sin(2.0 * std::numbers::pi / n);
}

namespace shapes_detail {

inline void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(what);
}

inline Eigen::Vector3f at(double rho, double phi, double z) {
  return {static_cast<float>(rho * std::cos(phi)), static_cast<float>(rho * std::sin(phi)),
          static_cast<float>(z)};
}

inline void tri(TriangleSoup& s, const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                const Eigen::Vector3f& c) {
  s.corners.push_back(a);
  s.corners.push_back(b);
  s.corners.push_back(c);
}

// Profile point i of a UV sphere: polar angle pi*i/rings from +z. Poles are exact.
struct RhoZ {
  double rho;
  double z;
};
inline RhoZ sphere_ring(double radius, int rings, int i) {
  if (i == 0) return {0.0, radius};
  if (i == rings) return {0.0, -radius};
  const double theta = std::numbers::pi * i / rings;
  return {radius * std::sin(theta), radius * std::cos(theta)};
}

// Vertex j of the torus meridian polygon: tube angle 2*pi*j/minor_segments from the outer equator.
inline RhoZ torus_profile(double major_R, double minor_r, int minor_segments, int j) {
  const double theta = 2.0 * std::numbers::pi * (j % minor_segments) / minor_segments;
  return {major_R + minor_r * std::cos(theta), minor_r * std::sin(theta)};
}

// Volume of the solid of revolution of a closed (rho, z) polygon, faceted with n meridians:
// V = n * sin(2 pi / n) * (integral of rho dA over the polygon). Counter-clockwise profile
// (rho to the right, z up) gives a positive value.
inline double faceted_revolution_volume(const std::vector<RhoZ>& profile, int n) {
  double int_rho_dA = 0.0;  // Green: integral of rho dA = closed integral of rho^2/2 dz
  for (std::size_t i = 0; i < profile.size(); ++i) {
    const RhoZ& a = profile[i];
    const RhoZ& b = profile[(i + 1) % profile.size()];
    int_rho_dA += (b.z - a.z) / 6.0 * (a.rho * a.rho + a.rho * b.rho + b.rho * b.rho);
  }
  return n * std::sin(2.0 * std::numbers::pi / n) * int_rho_dA;
}

}  // namespace shapes_detail

// ---------------------------------------------------------------------------------------------
// UV sphere. `segments` meridians (>= 3), `rings` latitude bands (>= 2): the polar angle of
// latitude circle i is pi*i/rings, i = 1..rings-1; the poles are single vertices joined to the
// first/last circle by triangle fans; every other band is quads split in two.
// Triangles: 2 * segments * (rings - 1). Centred at the origin.
inline TriangleSoup uv_sphere(double radius, int segments, int rings) {
  using namespace shapes_detail;
  require(radius > 0, "uv_sphere: radius must be > 0");
  require(segments >= 3, "uv_sphere: segments must be >= 3");
  require(rings >= 2, "uv_sphere: rings must be >= 2");
  // grid[i][j]: latitude circle i (1..rings-1), meridian j.
  const auto n = static_cast<std::size_t>(segments), r = static_cast<std::size_t>(rings);
  std::vector<std::vector<Eigen::Vector3f>> grid(r + 1);
  for (std::size_t i = 1; i < r; ++i) {
    const RhoZ p = sphere_ring(radius, rings, static_cast<int>(i));
    grid[i].reserve(n);
    for (std::size_t j = 0; j < n; ++j)
      grid[i].push_back(at(p.rho, 2.0 * std::numbers::pi * static_cast<double>(j) / segments, p.z));
  }
  const Eigen::Vector3f north(0.0f, 0.0f, static_cast<float>(radius));
  const Eigen::Vector3f south(0.0f, 0.0f, static_cast<float>(-radius));

  TriangleSoup s;
  s.format = "generated:uv_sphere";
  s.corners.reserve(6 * n * (r - 1));
  for (std::size_t j = 0; j < n; ++j) {
    const std::size_t k = (j + 1) % n;
    tri(s, north, grid[1][j], grid[1][k]);
    for (std::size_t i = 1; i + 1 < r; ++i) {
      tri(s, grid[i][j], grid[i + 1][j], grid[i + 1][k]);
      tri(s, grid[i][j], grid[i + 1][k], grid[i][k]);
    }
    tri(s, grid[r - 1][j], south, grid[r - 1][k]);
  }
  return s;
}

// Exact area of the horizontal section at height z (original frame, centre at the origin) of
// the faceted solid uv_sphere(radius, segments, rings). 0 for |z| >= radius.
inline double uv_sphere_section_area(double radius, int segments, int rings, double z) {
  using namespace shapes_detail;
  if (!(z > -radius && z < radius)) return 0.0;
  // Band i spans z_{i+1} <= z <= z_i (z decreases with i).
  for (int i = 0; i < rings; ++i) {
    const RhoZ a = sphere_ring(radius, rings, i);
    const RhoZ b = sphere_ring(radius, rings, i + 1);
    if (z <= a.z && z >= b.z) {
      const double t = (a.z - z) / (a.z - b.z);
      return regular_polygon_area(segments, a.rho + t * (b.rho - a.rho));
    }
  }
  return 0.0;
}

// Exact volume of the faceted uv_sphere (a stack of regular-polygon frusta).
inline double uv_sphere_volume(double radius, int segments, int rings) {
  using namespace shapes_detail;
  std::vector<RhoZ> profile;  // counter-clockwise: down the axis, then up the outside
  profile.push_back({0.0, radius});
  profile.push_back({0.0, -radius});
  for (int i = rings - 1; i >= 1; --i) profile.push_back(sphere_ring(radius, rings, i));
  return faceted_revolution_volume(profile, segments);
}

// ---------------------------------------------------------------------------------------------
// Tube: a cylinder of radius outer_r from z = 0 to z = height with a coaxial through hole of
// radius inner_r, `segments` (>= 3) meridians on both walls, flat annular caps triangulated as
// quads (outer_j, outer_j+1, inner_j+1, inner_j) split in two. Triangles: 8 * segments.
// inner_r == 0 gives a solid cylinder whose caps are triangle fans (4 * segments triangles).
inline TriangleSoup tube(double outer_r, double inner_r, double height, int segments) {
  using namespace shapes_detail;
  require(outer_r > 0 && height > 0, "tube: outer_r and height must be > 0");
  require(inner_r >= 0 && inner_r < outer_r, "tube: need 0 <= inner_r < outer_r");
  require(segments >= 3, "tube: segments must be >= 3");
  const bool solid = inner_r == 0;
  const auto n = static_cast<std::size_t>(segments);
  std::vector<Eigen::Vector3f> ob, ot, ib, it;  // outer/inner, bottom/top
  for (std::size_t j = 0; j < n; ++j) {
    const double phi = 2.0 * std::numbers::pi * static_cast<double>(j) / segments;
    ob.push_back(at(outer_r, phi, 0.0));
    ot.push_back(at(outer_r, phi, height));
    if (!solid) {
      ib.push_back(at(inner_r, phi, 0.0));
      it.push_back(at(inner_r, phi, height));
    }
  }
  const Eigen::Vector3f cb(0.0f, 0.0f, 0.0f), ct(0.0f, 0.0f, static_cast<float>(height));

  TriangleSoup s;
  s.format = solid ? "generated:cylinder" : "generated:tube";
  s.corners.reserve((solid ? 12 : 24) * n);
  for (std::size_t j = 0; j < n; ++j) {
    const std::size_t k = (j + 1) % n;
    // outer wall, normal away from the axis
    tri(s, ob[j], ob[k], ot[k]);
    tri(s, ob[j], ot[k], ot[j]);
    if (solid) {
      tri(s, ct, ot[j], ot[k]);  // top fan, +z
      tri(s, cb, ob[k], ob[j]);  // bottom fan, -z
      continue;
    }
    // inner wall, normal towards the axis
    tri(s, ib[j], it[k], ib[k]);
    tri(s, ib[j], it[j], it[k]);
    // top annulus, +z
    tri(s, ot[j], ot[k], it[k]);
    tri(s, ot[j], it[k], it[j]);
    // bottom annulus, -z
    tri(s, ob[j], ib[k], ob[k]);
    tri(s, ob[j], ib[j], ib[k]);
  }
  return s;
}

// Exact section area of the faceted tube at height z (original frame: 0 <= z <= height);
// 0 outside [0, height]; at z = 0 or z = height, the area just inside.
inline double tube_section_area(double outer_r, double inner_r, double height, int segments,
                                double z) {
  if (z < 0 || z > height) return 0.0;
  return regular_polygon_area(segments, outer_r) - regular_polygon_area(segments, inner_r);
}

inline double tube_volume(double outer_r, double inner_r, double height, int segments) {
  return tube_section_area(outer_r, inner_r, height, segments, 0.5 * height) * height;
}

// ---------------------------------------------------------------------------------------------
// Torus about the z axis, centred at the origin: `major_segments` (>= 3) meridians around the
// axis, each a regular `minor_segments`-gon (>= 3) of circumradius minor_r centred at
// (rho = major_R, z = 0), its vertex j at tube angle 2*pi*j/minor_segments from the outer
// equator (vertex 0 at rho = major_R + minor_r, z = 0). Needs 0 < minor_r < major_R.
// Triangles: 2 * major_segments * minor_segments.
inline TriangleSoup torus(double major_R, double minor_r, int major_segments,
                          int minor_segments) {
  using namespace shapes_detail;
  require(minor_r > 0 && minor_r < major_R, "torus: need 0 < minor_r < major_R");
  require(major_segments >= 3 && minor_segments >= 3, "torus: segments must be >= 3");
  // grid[i * m + j]: meridian i, profile vertex j
  const auto M = static_cast<std::size_t>(major_segments);
  const auto m = static_cast<std::size_t>(minor_segments);
  std::vector<Eigen::Vector3f> grid;
  grid.reserve(M * m);
  for (std::size_t i = 0; i < M; ++i)
    for (std::size_t j = 0; j < m; ++j) {
      const RhoZ p = torus_profile(major_R, minor_r, minor_segments, static_cast<int>(j));
      grid.push_back(at(p.rho, 2.0 * std::numbers::pi * static_cast<double>(i) / major_segments, p.z));
    }
  auto g = [&](std::size_t i, std::size_t j) -> const Eigen::Vector3f& {
    return grid[(i % M) * m + (j % m)];
  };

  TriangleSoup s;
  s.format = "generated:torus";
  s.corners.reserve(6 * M * m);
  for (std::size_t i = 0; i < M; ++i)
    for (std::size_t j = 0; j < m; ++j) {
      // d/dphi x d/dtheta points outward: (i,j) -> (i+1,j) -> (i+1,j+1)
      tri(s, g(i, j), g(i + 1, j), g(i + 1, j + 1));
      tri(s, g(i, j), g(i + 1, j + 1), g(i, j + 1));
    }
  return s;
}

// Lowest / highest z of the faceted torus (the meridian polygon's extreme vertices).
inline double torus_z_min(double minor_r, int minor_segments) {
  double zmin = 0.0;
  for (int j = 0; j < minor_segments; ++j)
    zmin = std::min(zmin, shapes_detail::torus_profile(0.0, minor_r, minor_segments, j).z);
  return zmin;
}
inline double torus_z_max(double minor_r, int minor_segments) {
  double zmax = 0.0;
  for (int j = 0; j < minor_segments; ++j)
    zmax = std::max(zmax, shapes_detail::torus_profile(0.0, minor_r, minor_segments, j).z);
  return zmax;
}

// Exact section area of the faceted torus at height z (original frame, centred at the origin):
// the plane cuts the (convex) meridian polygon in [rho_in(z), rho_out(z)], and the section is
// the annulus between two regular major_segments-gons. 0 outside [torus_z_min, torus_z_max]
// and where the plane only touches a single top/bottom vertex.
inline double torus_section_area(double major_R, double minor_r, int major_segments,
                                 int minor_segments, double z) {
  using namespace shapes_detail;
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  for (int j = 0; j < minor_segments; ++j) {
    const RhoZ a = torus_profile(major_R, minor_r, minor_segments, j);
    const RhoZ b = torus_profile(major_R, minor_r, minor_segments, j + 1);
    if (a.z == b.z) {  // horizontal edge: its ends are reached through the neighbouring edges
      continue;
    }
    if (z < std::min(a.z, b.z) || z > std::max(a.z, b.z)) continue;
    const double t = (z - a.z) / (b.z - a.z);
    const double rho = a.rho + t * (b.rho - a.rho);
    lo = std::min(lo, rho);
    hi = std::max(hi, rho);
  }
  if (!(hi > lo)) return 0.0;
  return regular_polygon_area(major_segments, hi) - regular_polygon_area(major_segments, lo);
}

// Exact volume of the faceted torus: n sin(2pi/n) * R * (area of the meridian polygon).
inline double torus_volume(double major_R, double minor_r, int major_segments,
                           int minor_segments) {
  return major_segments * std::sin(2.0 * std::numbers::pi / major_segments) * major_R *
         regular_polygon_area(minor_segments, minor_r);
}

// ---------------------------------------------------------------------------------------------
// Helpers on soups.

// Signed volume by the divergence theorem (sum of det(a, b, c) / 6, accumulated in double);
// positive for a closed soup with outward winding.
inline double soup_volume(const TriangleSoup& s) {
  double v = 0.0;
  for (std::size_t t = 0; t + 2 < s.corners.size(); t += 3) {
    const Eigen::Vector3d a = s.corners[t].cast<double>();
    const Eigen::Vector3d b = s.corners[t + 1].cast<double>();
    const Eigen::Vector3d c = s.corners[t + 2].cast<double>();
    v += a.dot(b.cross(c));
  }
  return v / 6.0;
}

inline float lowest_z(const TriangleSoup& s) {
  float z = std::numeric_limits<float>::infinity();
  for (const auto& p : s.corners) z = std::min(z, p.z());
  return z;
}

// A copy moved by `offset` (e.g. {0, 0, -lowest_z(s)} to sit it on z = 0 as the slicer does).
inline TriangleSoup translated(TriangleSoup s, const Eigen::Vector3f& offset) {
  for (auto& p : s.corners) p += offset;
  return s;
}

// Writes a binary STL (little-endian, facet normals computed from the winding, attribute 0).
// Throws std::runtime_error when the file cannot be written.
inline void write_binary_stl(const TriangleSoup& s, const std::filesystem::path& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("write_binary_stl: cannot open " + path.string());
  std::array<char, 80> header{};
  const std::string title = "lamina test shape " + s.format;
  std::memcpy(header.data(), title.data(), std::min(title.size(), header.size()));
  out.write(header.data(), header.size());

  auto put_u32 = [&](std::uint32_t v) {
    const char b[4] = {static_cast<char>(v & 0xff), static_cast<char>((v >> 8) & 0xff),
                       static_cast<char>((v >> 16) & 0xff), static_cast<char>((v >> 24) & 0xff)};
    out.write(b, 4);
  };
  auto put_f32 = [&](float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    put_u32(u);
  };
  const std::size_t n = s.corners.size() / 3;
  if (n > std::numeric_limits<std::uint32_t>::max())
    throw std::runtime_error("write_binary_stl: too many triangles");
  put_u32(static_cast<std::uint32_t>(n));
  for (std::size_t t = 0; t < n; ++t) {
    const Eigen::Vector3f& a = s.corners[3 * t];
    const Eigen::Vector3f& b = s.corners[3 * t + 1];
    const Eigen::Vector3f& c = s.corners[3 * t + 2];
    Eigen::Vector3d nrm = (b - a).cast<double>().cross((c - a).cast<double>());
    const double len = nrm.norm();
    if (len > 0) nrm /= len;
    for (int k = 0; k < 3; ++k) put_f32(static_cast<float>(nrm[k]));
    for (const Eigen::Vector3f* p : {&a, &b, &c})
      for (int k = 0; k < 3; ++k) put_f32((*p)[k]);
    out.put(0);
    out.put(0);
  }
  out.flush();
  if (!out) throw std::runtime_error("write_binary_stl: write failed for " + path.string());
}

}  // namespace lamina::test
