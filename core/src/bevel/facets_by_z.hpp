#pragma once
// Private: the mesh's facets bucketed by height, built once per bevel plan, so that each layer
// visits the facets of its own slab instead of every facet of the mesh. On the 1M-triangle
// sphere each of the ~30 planned layers scanned all 1M facets twice (its shadows and its slab),
// gathering a few tens of thousands.
#include "lamina/core/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace lamina::bevel_detail {

class FacetsByZ {
 public:
  explicit FacetsByZ(const Mesh& mesh, double bin_mm) : mesh_(&mesh) {
    const std::size_t n = mesh.faces.size();
    std::vector<double> lo(n), hi(n);  // only while bucketing: 16 MB for the 1M sphere
    double z_min = std::numeric_limits<double>::infinity(), z_max = -z_min;
    for (std::size_t f = 0; f < n; ++f) {
      lo[f] = z_lo(f);
      hi[f] = z_hi(f);
      z_min = std::min(z_min, lo[f]);
      z_max = std::max(z_max, hi[f]);
    }
    if (n == 0 || !std::isfinite(z_min) || !std::isfinite(z_max)) return;
    z0_ = z_min;
    // Tall facets are listed in every bin they span: coarser bins until that stays within a few
    // entries per facet (a tessellated cylinder's full-height strips).
    bin_mm_ = std::max({bin_mm, (z_max - z_min) / 65536.0, 1e-6});
    for (;;) {
      bins_ = static_cast<std::int64_t>(std::floor((z_max - z0_) / bin_mm_)) + 1;
      std::int64_t entries = 0;
      for (std::size_t f = 0; f < n; ++f) entries += bin_of(hi[f]) - bin_of(lo[f]) + 1;
      if (entries <= 4 * static_cast<std::int64_t>(n) + bins_) break;
      bin_mm_ *= 2.0;
    }
    first_bin_.resize(n);
    for (std::size_t f = 0; f < n; ++f) first_bin_[f] = static_cast<std::int32_t>(bin_of(lo[f]));
    begin_.assign(static_cast<std::size_t>(bins_) + 1, 0);
    for (std::size_t f = 0; f < n; ++f)
      for (std::int64_t b = bin_of(lo[f]); b <= bin_of(hi[f]); ++b) ++begin_[static_cast<std::size_t>(b) + 1];
    for (std::size_t b = 0; b + 1 < begin_.size(); ++b) begin_[b + 1] += begin_[b];
    items_.resize(begin_.back());
    std::vector<std::uint32_t> fill(begin_.begin(), begin_.end() - 1);
    for (std::size_t f = 0; f < n; ++f)
      for (std::int64_t b = bin_of(lo[f]); b <= bin_of(hi[f]); ++b)
        items_[fill[static_cast<std::size_t>(b)]++] = static_cast<std::uint32_t>(f);
  }

  // The facets whose z range meets [zb, zt] (zb ≤ zt), ascending: the order a scan of the whole
  // mesh would give, so what is built from them does not change.
  void in_slab(double zb, double zt, std::vector<std::uint32_t>& out) const {
    out.clear();
    if (items_.empty() || zt < zb) return;
    const std::int64_t b0 = bin_of(zb), b1 = bin_of(zt);
    for (std::int64_t b = b0; b <= b1; ++b) {
      for (std::uint32_t i = begin_[static_cast<std::size_t>(b)]; i < begin_[static_cast<std::size_t>(b) + 1]; ++i) {
        const std::uint32_t f = items_[i];
        if (std::max<std::int64_t>(first_bin_[f], b0) != b) continue;  // listed in an earlier bin of the range too
        // Only in the range's end bins can a facet lie outside it: its heights are read there
        // from the mesh (the same doubles the scans compared), not kept for every facet.
        if (b == b0 && z_hi(f) < zb) continue;
        if (b == b1 && z_lo(f) > zt) continue;
        out.push_back(f);
      }
    }
    std::sort(out.begin(), out.end());
  }

 private:
  std::int64_t bin_of(double z) const {
    // Clamped as a double first: a height far outside the mesh must not overflow the cast.
    const double b = std::clamp(std::floor((z - z0_) / bin_mm_), 0.0, static_cast<double>(bins_ - 1));
    return static_cast<std::int64_t>(b);
  }
  double corner_z(std::size_t f, int k) const {
    return mesh_->vertices[static_cast<std::size_t>(mesh_->faces[f][static_cast<std::size_t>(k)])].z();
  }
  double z_lo(std::size_t f) const { return std::min({corner_z(f, 0), corner_z(f, 1), corner_z(f, 2)}); }
  double z_hi(std::size_t f) const { return std::max({corner_z(f, 0), corner_z(f, 1), corner_z(f, 2)}); }

  const Mesh* mesh_;  // outlives this (both belong to one plan)
  double z0_ = 0.0, bin_mm_ = 1.0;
  std::int64_t bins_ = 0;
  std::vector<std::int32_t> first_bin_;  // per facet: the bin of its lowest point
  std::vector<std::uint32_t> begin_, items_;
};

}  // namespace lamina::bevel_detail
