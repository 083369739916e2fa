// Which facets does each plane cut? A facet crosses z iff zmin < z <= zmax (the on-plane-is-above
// rule), i.e. it is in the buckets of planes (upper_bound(zmin), upper_bound(zmax)]. Built as a
// CSR in two parallel passes over fixed facet chunks (histogram, then fill), so the result is
// deterministic: facets ascend within each plane's bucket.
#include "slice/slice_internal.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace lamina::slice_detail {
namespace {

// upper_bound over sorted heights through a bin table: O(1) for evenly spread planes (the usual
// --step case) and a short binary search inside one bin otherwise.
class PlaneIndex {
 public:
  explicit PlaneIndex(std::span<const double> sorted) : z_(sorted) {
    if (z_.empty()) return;
    lo_ = z_.front();
    const double span = z_.back() - lo_;
    const std::size_t bins = std::max<std::size_t>(1, 4 * z_.size());
    inv_ = span > 0 ? static_cast<double>(bins) / span : 0.0;
    // Evenly spread planes (--step): the count is a rounding away, checked against the neighbours.
    if (z_.size() > 1) {
      step_ = span / static_cast<double>(z_.size() - 1);
      for (std::size_t i = 0; i < z_.size() && uniform_; ++i)
        uniform_ = std::abs(z_[i] - (lo_ + static_cast<double>(i) * step_)) <= 1e-9 * step_;
    }
    first_.resize(bins + 2);
    // first_[b] = index of the first plane with z >= lo_ + b / inv_.
    std::size_t i = 0;
    for (std::size_t b = 0; b < first_.size(); ++b) {
      while (i < z_.size() && bin_of(z_[i]) < b) ++i;
      first_[b] = i;
    }
  }
  // Number of planes with z <= v.
  std::uint32_t upper_bound(double v) const {
    if (z_.empty() || v < lo_) return 0;
    if (v >= z_.back()) return static_cast<std::uint32_t>(z_.size());
    if (uniform_) {
      auto i = static_cast<std::size_t>((v - lo_) / step_);  // z_[i] is about v or just below it
      while (i > 0 && z_[i] > v) --i;
      while (i < z_.size() && z_[i] <= v) ++i;
      return static_cast<std::uint32_t>(i);
    }
    const std::size_t b = bin_of(v);
    const auto begin = z_.begin() + static_cast<std::ptrdiff_t>(first_[b]);
    const auto end = z_.begin() + static_cast<std::ptrdiff_t>(first_[std::min(b + 1, first_.size() - 1)]);
    return static_cast<std::uint32_t>(std::upper_bound(begin, end, v) - z_.begin());
  }

 private:
  std::size_t bin_of(double v) const {
    const double b = std::floor((v - lo_) * inv_);
    return b <= 0 ? 0 : std::min(static_cast<std::size_t>(b), first_.size() - 2);
  }
  std::span<const double> z_;
  double lo_ = 0.0, inv_ = 0.0, step_ = 0.0;
  bool uniform_ = true;
  std::vector<std::size_t> first_;
};

}  // namespace

FacetBuckets bucket_facets(const Mesh& mesh, std::span<const double> sorted_z) {
  const PlaneIndex index(sorted_z);
  const std::size_t nf = mesh.faces.size(), np = sorted_z.size();
  constexpr std::size_t kChunk = 1 << 15;
  const std::size_t chunks = (nf + kChunk - 1) / kChunk;
  auto range_of = [&](std::size_t f) {
    const auto& t = mesh.faces[f];
    const double z0 = mesh.vertices[static_cast<std::size_t>(t[0])].z();
    const double z1 = mesh.vertices[static_cast<std::size_t>(t[1])].z();
    const double z2 = mesh.vertices[static_cast<std::size_t>(t[2])].z();
    return std::pair(index.upper_bound(std::min({z0, z1, z2})), index.upper_bound(std::max({z0, z1, z2})));
  };

  // Pass 1: per-chunk histograms of planes cut.
  std::vector<std::vector<std::int64_t>> hist(chunks, std::vector<std::int64_t>(np, 0));
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    auto& h = hist[c];
    for (std::size_t f = c * kChunk; f < std::min(nf, (c + 1) * kChunk); ++f) {
      const auto [a, b] = range_of(f);
      for (std::uint32_t k = a; k < b; ++k) ++h[k];
    }
  });
  // Offsets: plane-major, chunk-minor, so every chunk writes its own disjoint slots.
  FacetBuckets out;
  out.offsets.assign(np + 1, 0);
  std::int64_t total = 0;
  for (std::size_t p = 0; p < np; ++p) {
    out.offsets[p] = total;
    for (std::size_t c = 0; c < chunks; ++c) {
      const std::int64_t n = hist[c][p];
      hist[c][p] = total;  // becomes the chunk's cursor for plane p
      total += n;
    }
  }
  out.offsets[np] = total;
  out.faces.resize(static_cast<std::size_t>(total));
  // Pass 2: fill.
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    auto& cursor = hist[c];
    for (std::size_t f = c * kChunk; f < std::min(nf, (c + 1) * kChunk); ++f) {
      const auto [a, b] = range_of(f);
      for (std::uint32_t k = a; k < b; ++k) out.faces[static_cast<std::size_t>(cursor[k]++)] = static_cast<std::int32_t>(f);
    }
  });
  return out;
}

}  // namespace lamina::slice_detail
