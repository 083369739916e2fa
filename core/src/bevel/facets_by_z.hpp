#pragma once
// Private: the mesh's facets bucketed by height, built once per bevel plan, so that each layer
// visits the facets of its own slab instead of every facet of the mesh. On the 1M-triangle
// sphere each of the ~30 planned layers scanned all 1M facets twice (its shadows and its slab),
// gathering a few tens of thousands.
#include "geometry/outward_float.hpp"
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
    lo_.resize(n);
    hi_.resize(n);
    double z_min = std::numeric_limits<double>::infinity(), z_max = -z_min;
    for (std::size_t f = 0; f < n; ++f) {
      const double lo = z_lo(f), hi = z_hi(f);
      lo_[f] = geometry_detail::float_at_most(lo);
      hi_[f] = geometry_detail::float_at_least(hi);
      z_min = std::min(z_min, lo);
      z_max = std::max(z_max, hi);
    }
    if (n == 0 || !std::isfinite(z_min) || !std::isfinite(z_max)) return;
    z0_ = z_min;
    // Tall facets are listed in every bin they span: coarser bins until that stays within a few
    // entries per facet (a tessellated cylinder's full-height strips).
    bin_mm_ = std::max({bin_mm, (z_max - z_min) / 65536.0, 1e-6});
    for (;;) {
      bins_ = static_cast<std::int64_t>(std::floor((z_max - z0_) / bin_mm_)) + 1;
      std::int64_t entries = 0;
      for (std::size_t f = 0; f < n; ++f) entries += bin_of(hi_[f]) - bin_of(lo_[f]) + 1;
      if (entries <= 4 * static_cast<std::int64_t>(n) + bins_) break;
      bin_mm_ *= 2.0;
    }
    begin_.assign(static_cast<std::size_t>(bins_) + 1, 0);
    for (std::size_t f = 0; f < n; ++f)
      for (std::int64_t b = bin_of(lo_[f]); b <= bin_of(hi_[f]); ++b) ++begin_[static_cast<std::size_t>(b) + 1];
    for (std::size_t b = 0; b + 1 < begin_.size(); ++b) begin_[b + 1] += begin_[b];
    items_.resize(begin_.back());
    std::vector<std::uint32_t> fill(begin_.begin(), begin_.end() - 1);
    for (std::size_t f = 0; f < n; ++f)
      for (std::int64_t b = bin_of(lo_[f]); b <= bin_of(hi_[f]); ++b)
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
        if (std::max(bin_of(lo_[f]), b0) != b) continue;  // listed in an earlier bin of the range too
        // The float bounds hold the facet: outside them is outside it; a bound that reaches past
        // an end of the range by less than its rounding is decided on the mesh's own heights
        // (the doubles the scans compared).
        if (hi_[f] < zb || lo_[f] > zt) continue;
        if (static_cast<double>(hi_[f]) < zb + kFloatSlack * std::abs(zb) + kFloatSlack && z_hi(f) < zb) continue;
        if (static_cast<double>(lo_[f]) > zt - kFloatSlack * std::abs(zt) - kFloatSlack && z_lo(f) > zt) continue;
        out.push_back(f);
      }
    }
    std::sort(out.begin(), out.end());
  }

 private:
  // More than a float's relative rounding (2^-24 ≈ 6e-8): within it of an end, a bound may be the
  // rounding's and not the facet's.
  static constexpr double kFloatSlack = 1e-6;
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
  // Per facet, its lowest and highest point as floats rounded outwards (8 bytes instead of 16;
  // 8 MB less for the 1M sphere, at the layering's peak).
  std::vector<float> lo_, hi_;
  double z0_ = 0.0, bin_mm_ = 1.0;
  std::int64_t bins_ = 0;
  std::vector<std::uint32_t> begin_, items_;
};

}  // namespace lamina::bevel_detail
