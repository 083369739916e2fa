// Step 6b of build_mesh: which way is out, per shell.
//
// A closed shell's signed volume says which way its (already consistent) facets face. A shell
// nested inside an odd number of other closed shells is a cavity and must have negative volume;
// every other shell must have positive volume (nesting: mesh_nesting.cpp). Open shells have no
// inside; they are turned so that their volume about their box centre is positive, when that
// volume is clearly non-zero.
#include "mesh/mesh_internal.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

namespace lamina::mesh_detail {
namespace {

struct Acc {
  Box3 box{Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()),
          Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity())};
  double six_v = 0.0;
  Eigen::Vector3d area2 = Eigen::Vector3d::Zero();
  void add(const Acc& o) {
    box.lo = box.lo.cwiseMin(o.box.lo);
    box.hi = box.hi.cwiseMax(o.box.hi);
    six_v += o.six_v;
    area2 += o.area2;
  }
};

void accumulate_range(const Mesh& m, std::size_t b, std::size_t e, const Eigen::Vector3d& ref, std::vector<Acc>& acc) {
  for (std::size_t f = b; f < e; ++f) {
    const Tri& t = m.faces[f];
    const Eigen::Vector3d& p0 = m.vertices[static_cast<std::size_t>(t[0])];
    const Eigen::Vector3d& p1 = m.vertices[static_cast<std::size_t>(t[1])];
    const Eigen::Vector3d& p2 = m.vertices[static_cast<std::size_t>(t[2])];
    Acc& a = acc[static_cast<std::size_t>(m.shell_id[f])];
    a.box.lo = a.box.lo.cwiseMin(p0).cwiseMin(p1).cwiseMin(p2);
    a.box.hi = a.box.hi.cwiseMax(p0).cwiseMax(p1).cwiseMax(p2);
    const Eigen::Vector3d u = p0 - ref, v = p1 - ref, w = p2 - ref;
    a.six_v += u.dot(v.cross(w));
    a.area2 += (v - u).cross(w - u);
  }
}

// Per shell: box, 6·volume and doubled vector area about ref. Deterministic: a fixed split, so
// the sums do not depend on thread timing.
std::vector<Acc> accumulate_shells(const Mesh& m, std::size_t shells, const Eigen::Vector3d& ref) {
  const std::size_t nf = m.faces.size();
  constexpr std::size_t kGrain = 32768;
  if (shells > 16 || nf < 2 * kGrain) {
    std::vector<Acc> acc(shells);
    accumulate_range(m, 0, nf, ref, acc);
    return acc;
  }
  struct Body {
    const Mesh* m;
    const Eigen::Vector3d* ref;
    std::vector<Acc> acc;
    Body(const Mesh& mm, const Eigen::Vector3d& r, std::size_t n) : m(&mm), ref(&r), acc(n) {}
    Body(Body& o, tbb::split) : m(o.m), ref(o.ref), acc(o.acc.size()) {}
    void operator()(const tbb::blocked_range<std::size_t>& r) { accumulate_range(*m, r.begin(), r.end(), *ref, acc); }
    void join(const Body& o) {
      for (std::size_t s = 0; s < acc.size(); ++s) acc[s].add(o.acc[s]);
    }
  };
  Body body(m, ref, shells);
  tbb::parallel_deterministic_reduce(tbb::blocked_range<std::size_t>(0, nf, kGrain), body);
  return std::move(body.acc);
}

}  // namespace

void outward_shells(Mesh& m, const Adjacency& adj, const ShellFaces& sf, const std::vector<char>& shell_conflict,
                    OrientResult& r) {
  const std::size_t shells = sf.begin.size() - 1;
  m.shell_info.assign(shells, ShellInfo{});
  std::vector<char> closed(shells, 1);
  for (std::size_t s = 0; s < shells; ++s) {
    m.shell_info[s].facets = sf.begin[s + 1] - sf.begin[s];
    if (shell_conflict[s]) closed[s] = 0;
  }

  // A shell is open where one of its edges is unbalanced: a boundary edge, or a non-manifold
  // edge its own facets do not cross as many times in each direction.
  for (const std::int32_t e : adj.odd_edges) {
    const Edge& ed = m.edges[static_cast<std::size_t>(e)];
    const std::int32_t* fs = m.edge_faces.data() + ed.face_begin;
    if (ed.face_count == 1) {
      closed[static_cast<std::size_t>(m.shell_id[static_cast<std::size_t>(fs[0])])] = 0;
      continue;
    }
    for (std::int32_t i = 0; i < ed.face_count; ++i) {
      const std::int32_t s = m.shell_id[static_cast<std::size_t>(fs[i])];
      bool seen = false;
      for (std::int32_t j = 0; j < i && !seen; ++j) seen = m.shell_id[static_cast<std::size_t>(fs[j])] == s;
      if (seen) continue;
      int sum = 0;
      for (std::int32_t j = i; j < ed.face_count; ++j) {
        const std::int32_t g = fs[j];
        if (m.shell_id[static_cast<std::size_t>(g)] == s) sum += edge_direction(m, g, local_edge(m, g, e));
      }
      if (sum != 0) closed[static_cast<std::size_t>(s)] = 0;
    }
  }

  // Boxes and volumes in one pass in facet order. Volumes are taken about each shell's box
  // centre c without knowing it beforehand: with 6V(o) = Σ a·(b×c) and the doubled vector area
  // A2 = Σ (b−a)×(c−a), both about a reference point, 6V(c) = 6V(ref) − (c − ref)·A2.
  const Eigen::Vector3d ref = m.vertices[0];
  std::vector<Acc> acc = accumulate_shells(m, shells, ref);
  std::vector<Box3> box(shells);
  std::vector<double> vol(shells);
  for (std::size_t s = 0; s < shells; ++s) {
    box[s] = acc[s].box;
    const Eigen::Vector3d c = 0.5 * (box[s].lo + box[s].hi);
    vol[s] = (acc[s].six_v - (c - ref).dot(acc[s].area2)) / 6.0;
  }

  // Nesting depth of each closed shell among the closed shells.
  std::vector<std::size_t> closed_list;
  for (std::size_t s = 0; s < shells; ++s)
    if (closed[s] && vol[s] != 0.0) closed_list.push_back(s);
  const std::vector<int> depth = nesting_depths(m, sf, closed_list, box, vol);
  for (std::size_t s = 0; s < shells; ++s) m.shell_info[s].depth = depth[s];

  // Turn over the shells that face the wrong way.
  for (std::size_t s = 0; s < shells; ++s) {
    ShellInfo& info = m.shell_info[s];
    info.closed = closed[s] != 0;
    const double want = (info.depth % 2 == 1) ? -1.0 : 1.0;
    const Eigen::Vector3d ext = box[s].hi - box[s].lo;
    const double eps = info.closed ? 0.0 : 1e-9 * std::pow(ext.maxCoeff(), 3);
    if (vol[s] * want < 0.0 && std::abs(vol[s]) > eps) {
      for (auto i = sf.begin[s]; i < sf.begin[s + 1]; ++i) flip_face(m, static_cast<std::size_t>(sf.order[static_cast<std::size_t>(i)]));
      vol[s] = -vol[s];
      if (r.shells_inverted == 0) r.first_inverted = centroid(m, static_cast<std::size_t>(sf.order[static_cast<std::size_t>(sf.begin[s])]));
      ++r.shells_inverted;
    }
    info.volume_mm3 = vol[s];
  }
}

}  // namespace lamina::mesh_detail
