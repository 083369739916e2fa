// build_mesh: soup → welded, repaired, oriented mesh with topology, surfaces and a diagnosis.
// Each step lives in its own file (mesh_weld, mesh_topology, mesh_orient, mesh_shells,
// mesh_surfaces); this one builds the facets, writes the defects and the summary.
#include "lamina/core/mesh.hpp"

#include "mesh/mesh_internal.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#if defined(__linux__)
#include <sys/mman.h>
#endif


namespace lamina {

const char* severity_name(Severity s) {
  switch (s) {
    case Severity::info: return "info";
    case Severity::repaired: return "repaired";
    case Severity::warning: return "warning";
    case Severity::error: return "error";
  }
  return "unknown";
}

bool Mesh::usable() const {
  return std::none_of(defects.begin(), defects.end(), [](const Defect& d) { return d.severity == Severity::error; });
}

const Defect* Mesh::find_defect(std::string_view code) const {
  for (const Defect& d : defects)
    if (d.code == code) return &d;
  return nullptr;
}

namespace mesh_detail {

void hint_huge_pages(void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t huge = std::uintptr_t{2} << 20;
  if (bytes < 4 * huge) return;
  const auto b = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t lo = (b + huge - 1) & ~(huge - 1), hi = (b + bytes) & ~(huge - 1);
  if (hi > lo) madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

std::string format_point(const Eigen::Vector3d& p) {
  return fmt::format("({:.6g}, {:.6g}, {:.6g}) mm", p.x(), p.y(), p.z());
}

namespace {

const char* plural(std::size_t n, const char* one, const char* many) { return n == 1 ? one : many; }

Eigen::Vector3d midpoint(const Mesh& m, const Edge& e) {
  return 0.5 * (m.vertices[static_cast<std::size_t>(e.v0)] + m.vertices[static_cast<std::size_t>(e.v1)]);
}

// Boundary edges joined at shared vertices: the number of separate holes/cracks.
std::size_t boundary_places(const Mesh& m) {
  std::vector<std::int32_t> parent(m.vertices.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](std::int32_t x) {
    while (parent[static_cast<std::size_t>(x)] != x) {
      parent[static_cast<std::size_t>(x)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
      x = parent[static_cast<std::size_t>(x)];
    }
    return x;
  };
  for (const Edge& e : m.edges) {
    if (e.face_count != 1) continue;
    const std::int32_t a = find(e.v0), b = find(e.v1);
    if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }
  std::size_t places = 0;
  std::vector<char> counted(m.vertices.size(), 0);
  for (const Edge& e : m.edges) {
    if (e.face_count != 1) continue;
    const auto r = static_cast<std::size_t>(find(e.v0));
    if (!counted[r]) counted[r] = 1, ++places;
  }
  return places;
}

Defect make_defect(std::string code, Severity sev, std::size_t count, std::string message,
                   std::optional<Eigen::Vector3d> where = std::nullopt) {
  Defect d;
  d.code = std::move(code);
  d.severity = sev;
  d.count = count;
  d.message = std::move(message);
  d.where = where;
  return d;
}

std::optional<Error> check_params(const MeshParams& p) {
  auto bad = [](std::string what) { return Error{ErrorCode::invalid_argument, std::move(what)}; };
  if (!(std::isfinite(p.scale_to_mm) && p.scale_to_mm > 0.0))
    return bad(fmt::format("build_mesh: scale_to_mm must be finite and > 0 (got {})", p.scale_to_mm));
  if (!(std::isfinite(p.weld_tolerance_rel) && p.weld_tolerance_rel >= 0.0 && p.weld_tolerance_rel < 0.1))
    return bad(fmt::format("build_mesh: weld_tolerance_rel must be in [0, 0.1) (got {})", p.weld_tolerance_rel));
  if (!(std::isfinite(p.degenerate_area_factor) && p.degenerate_area_factor >= 0.0))
    return bad(fmt::format("build_mesh: degenerate_area_factor must be finite and >= 0 (got {})",
                           p.degenerate_area_factor));
  if (!(std::isfinite(p.sharp_angle_rad) && p.sharp_angle_rad >= 0.0))
    return bad(fmt::format("build_mesh: sharp_angle_rad must be finite and >= 0 (got {})", p.sharp_angle_rad));
  switch (p.axis) {
    case BuildAxis::x:
    case BuildAxis::y:
    case BuildAxis::z: break;
    default: return bad("build_mesh: unknown build axis");
  }
  if (p.direction && !(p.direction->allFinite() && p.direction->norm() > 0.0))
    return bad(fmt::format("build_mesh: the build direction ({}, {}, {}) must be finite and non-zero",
                           p.direction->x(), p.direction->y(), p.direction->z()));
  return std::nullopt;
}

// Step 3: facets on welded vertices; degenerate ones dropped; vertices numbered by first use.
struct FacetStep {
  std::size_t degenerate = 0;
  Eigen::Vector3d first_degenerate = Eigen::Vector3d::Zero();
  double area_min = 0.0;
};

FacetStep collect_facets(const WeldResult& w, std::size_t nf_read, const MeshParams& params, Mesh& m,
                         std::vector<std::int32_t>* source_triangle) {
  FacetStep r;
  r.area_min = w.tolerance * w.tolerance * params.degenerate_area_factor;
  const double cross2_min = 4.0 * r.area_min * r.area_min;  // |(b − a) × (c − a)|² = (2·area)²
  std::vector<std::int32_t> vmap(w.points.size(), -1);
  m.faces.reserve(nf_read - w.nan_facets);
  m.vertices.reserve(w.points.size());
  for (std::size_t f = 0; f < nf_read; ++f) {
    if (w.corner_point[3 * f] < 0) continue;
    Tri t;
    for (int k = 0; k < 3; ++k)
      t[static_cast<std::size_t>(k)] = w.rep[static_cast<std::size_t>(w.corner_point[3 * f + static_cast<std::size_t>(k)])];
    const Eigen::Vector3d& a = w.points[static_cast<std::size_t>(t[0])];
    const Eigen::Vector3d& b = w.points[static_cast<std::size_t>(t[1])];
    const Eigen::Vector3d& c = w.points[static_cast<std::size_t>(t[2])];
    bool bad = t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
    if (!bad) {
      const double cross2 = (b - a).cross(c - a).squaredNorm();
      bad = !(cross2 > 0.0) || cross2 < cross2_min;
    }
    if (bad) {
      if (r.degenerate == 0) r.first_degenerate = (a + b + c) / 3.0;
      ++r.degenerate;
      continue;
    }
    for (auto& v : t) {
      auto& slot = vmap[static_cast<std::size_t>(v)];
      if (slot < 0) {
        slot = static_cast<std::int32_t>(m.vertices.size());
        m.vertices.push_back(w.points[static_cast<std::size_t>(v)]);
      }
      v = slot;
    }
    m.faces.push_back(t);
    if (source_triangle) source_triangle->push_back(static_cast<std::int32_t>(f));
  }
  return r;
}

// What the steps found, for the defect lines (step 10), located in the build frame.
struct BuildFacts {
  std::size_t nf_read = 0, nan_facets = 0, first_nan = 0, merged = 0;
  double tolerance = 0.0;
  Eigen::Vector3d first_merged = Eigen::Vector3d::Zero();
  FacetStep facets;
  std::optional<Eigen::Vector3d> first_boundary, first_nonmanifold;
};

// Step 9: the summary's counts, volume and box; the first open and non-manifold edges into `f`.
void summarize(Mesh& m, const Adjacency& adj, const OrientResult& orient, int surfaces, BuildFacts& f) {
  MeshSummary& s = m.summary;
  s.triangles_read = f.nf_read;
  s.triangles = m.faces.size();
  s.vertices = m.vertices.size();
  s.shells = static_cast<int>(m.shell_info.size());
  s.surfaces = surfaces;
  for (const std::int32_t ei : adj.odd_edges) {
    const Edge& e = m.edges[static_cast<std::size_t>(ei)];
    if (e.face_count == 1) {
      if (!f.first_boundary) f.first_boundary = midpoint(m, e);
      ++s.boundary_edges;
    } else if (e.face_count > 2) {
      if (!f.first_nonmanifold) f.first_nonmanifold = midpoint(m, e);
      ++s.nonmanifold_edges;
    }
  }
  s.watertight = s.boundary_edges == 0 && s.nonmanifold_edges == 0 && orient.winding_conflicts == 0;
  s.volume_mm3 = 0.0;
  for (const ShellInfo& sh : m.shell_info) s.volume_mm3 += sh.volume_mm3;
  s.bbox_min_mm = s.bbox_max_mm = m.vertices[0];
  for (const auto& v : m.vertices) {
    s.bbox_min_mm = s.bbox_min_mm.cwiseMin(v);
    s.bbox_max_mm = s.bbox_max_mm.cwiseMax(v);
  }
}

// Step 10, the repairs the weld and the facet step made.
void add_repair_defects(Mesh& m, const BuildFacts& f) {
  auto& d = m.defects;
  if (f.nan_facets > 0)
    d.push_back(make_defect("nan_coordinates", Severity::repaired, f.nan_facets,
                            fmt::format("{} {} with NaN or infinite coordinates dropped (first: facet {})", f.nan_facets,
                                        plural(f.nan_facets, "facet", "facets"), f.first_nan)));
  if (f.merged > 0)
    d.push_back(make_defect(
        "welded_vertices", Severity::repaired, f.merged,
        fmt::format("{} {} welded to a neighbour within {:.3g} mm (cracks an exact weld leaves open), e.g. at {}",
                    f.merged, plural(f.merged, "vertex", "vertices"), f.tolerance, format_point(f.first_merged)),
        f.first_merged));
  const std::size_t degenerate = f.facets.degenerate;
  if (degenerate > 0)
    d.push_back(make_defect("degenerate_facets", Severity::repaired, degenerate,
                            fmt::format("{} degenerate {} dropped (repeated vertex or area below {:.3g} mm²), e.g. at {}",
                                        degenerate, plural(degenerate, "facet", "facets"), f.facets.area_min,
                                        format_point(f.facets.first_degenerate)),
                            f.facets.first_degenerate));
}

// Step 10, what the topology found: open and non-manifold edges, winding.
void add_topology_defects(Mesh& m, const OrientResult& orient, const BuildFacts& f) {
  const MeshSummary& s = m.summary;
  auto& d = m.defects;
  if (s.boundary_edges > 0) {
    const std::size_t places = boundary_places(m);
    d.push_back(make_defect("open_edges", Severity::error, s.boundary_edges,
                            fmt::format("{} open (boundary) {} in {} {}: the mesh is not closed, e.g. at {}",
                                        s.boundary_edges, plural(s.boundary_edges, "edge", "edges"), places,
                                        plural(places, "place", "places"), format_point(*f.first_boundary)),
                            f.first_boundary));
  }
  if (s.nonmanifold_edges > 0)
    d.push_back(make_defect("nonmanifold_edges", Severity::warning, s.nonmanifold_edges,
                            fmt::format("{} non-manifold {} (shared by more than two facets), e.g. at {}",
                                        s.nonmanifold_edges, plural(s.nonmanifold_edges, "edge", "edges"),
                                        format_point(*f.first_nonmanifold)),
                            f.first_nonmanifold));
  if (orient.facets_flipped > 0)
    d.push_back(make_defect("inconsistent_winding", Severity::repaired, orient.facets_flipped,
                            fmt::format("{} {} wound against {} neighbours turned over, e.g. at {}",
                                        orient.facets_flipped, plural(orient.facets_flipped, "facet", "facets"),
                                        plural(orient.facets_flipped, "its", "their"), format_point(orient.first_flipped)),
                            orient.first_flipped));
  if (orient.winding_conflicts > 0)
    d.push_back(make_defect("winding_conflicts", Severity::warning, orient.winding_conflicts,
                            fmt::format("{} {} cannot be wound consistently (non-orientable shell), e.g. at {}",
                                        orient.winding_conflicts, plural(orient.winding_conflicts, "edge", "edges"),
                                        format_point(orient.first_conflict)),
                            orient.first_conflict));
  if (orient.shells_inverted > 0)
    d.push_back(make_defect("inside_out", Severity::repaired, orient.shells_inverted,
                            fmt::format("{} {} inside out, turned over, e.g. at {}", orient.shells_inverted,
                                        plural(orient.shells_inverted, "shell was", "shells were"),
                                        format_point(orient.first_inverted)),
                            orient.first_inverted));
}

// Step 10, several shells: how many solids, cavities and open ones.
void add_shell_defects(Mesh& m) {
  const MeshSummary& s = m.summary;
  if (s.shells <= 1) return;
  std::size_t solids = 0, cavities = 0, open = 0;
  for (const ShellInfo& sh : m.shell_info) {
    if (!sh.closed)
      ++open;
    else if (sh.volume_mm3 < 0.0)
      ++cavities;
    else
      ++solids;
  }
  std::string kinds;
  auto add = [&](std::size_t n, const char* one, const char* many) {
    if (n == 0) return;
    kinds += fmt::format("{}{} {}", kinds.empty() ? "" : ", ", n, plural(n, one, many));
  };
  add(solids, "solid", "solids");
  add(cavities, "cavity", "cavities");
  add(open, "open", "open");
  m.defects.push_back(make_defect("multiple_shells", Severity::info, static_cast<std::size_t>(s.shells),
                                  fmt::format("{} separate shells ({})", s.shells, kinds)));
}

Error no_usable_facet(const BuildFacts& f) {
  std::string why;
  if (f.nan_facets == f.nf_read)
    why = fmt::format("all {} facets have NaN or infinite coordinates", f.nf_read);
  else
    why = fmt::format("of {} facets, {} have NaN or infinite coordinates and {} are degenerate", f.nf_read,
                      f.nan_facets, f.facets.degenerate);
  return Error{ErrorCode::empty_mesh, "build_mesh: no usable facet: " + why};
}

}  // namespace
}  // namespace mesh_detail

std::expected<Mesh, Error> build_mesh(const TriangleSoup& soup, const MeshParams& params) {
  using namespace mesh_detail;
  if (auto err = check_params(params)) return std::unexpected(std::move(*err));

  const std::size_t nf_read = soup.triangle_count();
  if (nf_read == 0) return std::unexpected(Error{ErrorCode::empty_mesh, "build_mesh: the input has no facets"});
  if (nf_read > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max() / 3))
    return std::unexpected(Error{ErrorCode::unsupported,
                                 fmt::format("build_mesh: {} facets is more than this build supports", nf_read)});

  if (soup.brep) {
    const BrepData& b = *soup.brep;
    const bool faces_ok = std::all_of(b.triangle_face.begin(), b.triangle_face.end(), [&](std::int32_t i) {
      return i >= 0 && static_cast<std::size_t>(i) < b.faces.size();
    });
    if (b.triangle_face.size() != nf_read || b.corner_normals.size() != 3 * nf_read || !faces_ok)
      return std::unexpected(Error{ErrorCode::invalid_argument,
                                   fmt::format("build_mesh: the B-rep data does not match the {} triangles", nf_read)});
  }
  LAMINA_TIMER();
  // Steps 1–2: build frame, non-finite facets, weld.
  WeldResult w = weld_soup(soup, params);
  LAMINA_TICK("weld");
  Mesh m;
  BuildFacts f;
  BrepCarry brep;
  f.facets = collect_facets(w, nf_read, params, m, soup.brep ? &brep.source_triangle : nullptr);
  f.nf_read = nf_read;
  f.nan_facets = w.nan_facets, f.first_nan = w.first_nan_facet;
  f.merged = w.tolerance_merged;
  f.tolerance = w.tolerance;
  f.first_merged = w.first_merged;
  w = WeldResult{};  // release the weld tables before the topology is built
  LAMINA_TICK("facets");
  if (m.faces.empty()) return std::unexpected(no_usable_facet(f));

  // Lowest point at z = 0 (x and y as they are).
  double zmin = std::numeric_limits<double>::infinity();
  for (const auto& v : m.vertices) zmin = std::min(zmin, v.z());
  for (auto& v : m.vertices) v.z() -= zmin;
  f.facets.first_degenerate.z() -= zmin;
  f.first_merged.z() -= zmin;

  // Steps 4–8.
  if (soup.brep) brep.faces_as_read = m.faces;
  Adjacency adj = build_edges(m.vertices.size(), m.faces, m.edges, m.edge_faces, m.face_edges);
  LAMINA_TICK("edges");
  compute_normals(m);
  LAMINA_TICK("normals");
  const OrientResult orient = orient_shells(m, adj, params.sharp_angle_rad);
  adj.across = {};
  LAMINA_TICK("orient");
  int surfaces = orient.surfaces;
  if (soup.brep) {
    apply_brep(m, *soup.brep, brep, build_frame_rotation(params), params.scale_to_mm, zmin);
    surfaces = static_cast<int>(soup.brep->faces.size());
  } else {
    renumber_surfaces(m, surfaces);
  }
  LAMINA_TICK("surfaces");

  // Steps 9–10: summary and defects, one readable line each.
  summarize(m, adj, orient, surfaces, f);
  m.summary.lowered_mm = zmin;
  add_repair_defects(m, f);
  add_topology_defects(m, orient, f);
  add_shell_defects(m);
  LAMINA_TICK("summary");
  return m;
}

Mesh in_frame_of(Mesh other, const Mesh& frame) {
  const double dz = other.summary.lowered_mm - frame.summary.lowered_mm;
  for (Eigen::Vector3d& v : other.vertices) v.z() += dz;
  other.summary.bbox_min_mm.z() += dz;
  other.summary.bbox_max_mm.z() += dz;
  for (Defect& d : other.defects)
    if (d.where) d.where->z() += dz;
  for (BrepFace& f : other.brep_faces) f.origin.z() += dz;
  other.summary.lowered_mm = frame.summary.lowered_mm;
  return other;
}

}  // namespace lamina
