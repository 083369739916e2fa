// plan_bevels: slice every layer's sub-slices in one pass, then plan the layers (bevel.cpp) and
// measure each one's 3-D distance to the model (bevel_distance.cpp), in parallel.
#include "bevel/bevel_distance.hpp"
#include "bevel/plan_layers.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>

namespace lamina {

namespace {

std::unexpected<Error> invalid(std::string message) {
  return std::unexpected(Error{ErrorCode::invalid_argument, std::move(message)});
}

std::expected<void, Error> check_params(const BevelParams& params) {
  if (!(params.sub_slice_mm > 0.0) || !std::isfinite(params.sub_slice_mm))
    return invalid(fmt::format("sub-slice spacing must be > 0 mm (got {})", params.sub_slice_mm));
  if (!(params.fit.tilt_max_rad >= 0.0) || params.fit.tilt_max_rad >= 0.5 * M_PI)
    return invalid(fmt::format("tilt limit must be in [0°, 90°) (got {:.3f}°)", params.fit.tilt_max_rad * 180.0 / M_PI));
  return {};
}

// Every layer's sub-slices, sliced in one pass: layer i's are slices[first[i] .. first[i+1]).
struct SlicedLayers {
  std::vector<std::vector<double>> zs;
  std::vector<std::size_t> first;
  std::vector<Slice> slices;
  std::vector<const Slice*> subs(std::size_t i) const {
    std::vector<const Slice*> out;
    for (std::size_t k = first[i]; k < first[i + 1]; ++k) out.push_back(&slices[k]);
    return out;
  }
};

std::expected<SlicedLayers, Error> slice_layers(const Mesh& mesh, std::span<const LayerSpan> layers,
                                                const BevelParams& params) {
  SlicedLayers out;
  out.zs.resize(layers.size());
  out.first.assign(layers.size() + 1, 0);
  std::vector<double> all_z;
  for (std::size_t i = 0; i < layers.size(); ++i) {
    out.zs[i] = sub_slice_heights(layers[i].z_bottom_mm, layers[i].thickness_mm, params.sub_slice_mm);
    out.first[i] = all_z.size();
    all_z.insert(all_z.end(), out.zs[i].begin(), out.zs[i].end());
  }
  out.first[layers.size()] = all_z.size();
  SliceParams slice_params;
  slice_params.parallel = params.parallel;
  auto slices = slice_mesh(mesh, all_z, slice_params);
  if (!slices) return std::unexpected(slices.error());
  out.slices = std::move(*slices);
  return out;
}

// The indexes the caller did not give, built here.
struct OwnIndexes {
  std::optional<geometry_detail::TriangleTree> tree;
  std::optional<bevel_detail::FacetsByZ> facets_by_z;
  bevel_detail::MeshIndexes complete(const Mesh& mesh, bevel_detail::MeshIndexes given, const BevelParams& params) {
    if (params.measure_surface_distance && !given.model_tree)
      given.model_tree = &tree.emplace(mesh.vertices, mesh.faces, geometry_detail::threads_for(params.parallel));
    if (!params.measure_surface_distance) given.model_tree = nullptr;
    if (!given.facets_by_z) given.facets_by_z = &facets_by_z.emplace(mesh, params.sub_slice_mm);
    return given;
  }
};

// A layer over the tolerance but within this multiple of it is a near miss (plan_each).
constexpr double kNearMiss = 1.5;

// Plans layers[order[k]] for every k (in that order, or as a pool of tasks), each with its index
// in `layers`, into out.
void plan_each(const Mesh& mesh, const bevel_detail::MeshIndexes& indexes, std::span<const LayerSpan> layers,
               const SlicedLayers& sliced, const std::vector<std::size_t>& order, const BevelParams& params,
               std::vector<LayerPlan>& out) {
  double model_z_lo = std::numeric_limits<double>::infinity(), model_z_hi = -model_z_lo;
  if (indexes.model_tree)
    for (const Eigen::Vector3d& v : mesh.vertices) model_z_lo = std::min(model_z_lo, v.z()), model_z_hi = std::max(model_z_hi, v.z());
  out.resize(layers.size());
  auto plan_one = [&](std::size_t i, const std::vector<const Slice*>& subs, const BevelParams& p) {
    LayerPlan layer = bevel_detail::plan_layer(mesh, *indexes.facets_by_z, layers[i], static_cast<int>(i), sliced.zs[i], subs, p);
    layer.profile_deviation_mm = layer.max_deviation_mm;
    if (indexes.model_tree) {
      // What the tolerance checks is the 3-D distance (issue 17, item 4): a station's plane can
      // neither see a corner that slides along the outline nor the true (normal) distance to a
      // sloped surface.
      layer.surface_distance_mm = bevel_detail::layer_surface_distance(*indexes.model_tree, model_z_lo, model_z_hi, layer,
                                                                       subs, p.distance_sample_mm);
      layer.max_deviation_mm = layer.surface_distance_mm;
      layer.within_tolerance = layer.max_deviation_mm <= p.tolerance_mm;
    }
    return layer;
  };
  auto one = [&](std::size_t k) {
    const std::size_t i = order[k];
    const std::vector<const Slice*> subs = sliced.subs(i);
    out[i] = plan_one(i, subs, params);
    // A layer cut from a simplified outline that just misses the tolerance is planned again
    // from every corner: between stations further apart the ruled surface can stray from a
    // surface curved both ways (a low-poly cow's layer measured 0.259 mm instead of 0.194, over
    // the 0.2 tolerance). A layer further over misses it for its surface, not for its stations
    // (the 1M sphere's poles, 0.38-0.67 mm either way: planning those again cost 0.45 s).
    const bool near_miss = out[i].max_deviation_mm <= kNearMiss * params.tolerance_mm;
    if (!out[i].within_tolerance && near_miss && out[i].outline_simplified) {
      BevelParams every_corner = params;
      every_corner.outline_simplify_mm = 0.0;
      LayerPlan full = plan_one(i, subs, every_corner);
      // Kept when it meets the tolerance or is nearer by a twentieth of it (more stations for
      // 2 µm are not worth it).
      if (full.within_tolerance || full.max_deviation_mm < out[i].max_deviation_mm - params.tolerance_mm / 20.0)
        out[i] = std::move(full);
    }
    if (params.on_layer) params.on_layer();
  };
  if (params.parallel)
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t k = r.begin(); k != r.end(); ++k) one(k);
                      },
                      tbb::simple_partitioner());
  else
    for (std::size_t k = 0; k < order.size(); ++k) one(k);
}

// Checks, slices and plans the layers, layers[order[k]] for every k (a pool of tasks takes them
// in that order), each with its index in `layers`.
std::expected<std::vector<LayerPlan>, Error> plan_in_order(const Mesh& mesh, const bevel_detail::MeshIndexes& indexes,
                                                           std::span<const LayerSpan> layers,
                                                           const std::vector<std::size_t>& order,
                                                           const BevelParams& params) {
  if (auto ok = check_params(params); !ok) return std::unexpected(ok.error());
  for (std::size_t i = 0; i < layers.size(); ++i)
    if (!(layers[i].thickness_mm > 0.0) || !std::isfinite(layers[i].z_bottom_mm))
      return invalid(fmt::format("layer {}: thickness must be > 0 mm (got {})", i, layers[i].thickness_mm));
  auto sliced = slice_layers(mesh, layers, params);
  if (!sliced) return std::unexpected(sliced.error());
  OwnIndexes own;
  const bevel_detail::MeshIndexes all = layers.empty() ? indexes : own.complete(mesh, indexes, params);
  std::vector<LayerPlan> out;
  plan_each(mesh, all, layers, *sliced, order, params, out);
  return out;
}

std::vector<std::size_t> in_turn(std::size_t n) {
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  return order;
}

}  // namespace

std::expected<BevelPlan, Error> plan_bevels(const Mesh& mesh, std::span<const LayerSpan> layers,
                                            const BevelParams& params) {
  return bevel_detail::plan_bevels_on(mesh, {}, layers, params);
}

std::expected<BevelPlan, Error> bevel_detail::plan_bevels_on(const Mesh& mesh, const MeshIndexes& indexes,
                                                             std::span<const LayerSpan> layers,
                                                             const BevelParams& params) {
  if (auto ok = check_params(params); !ok) return std::unexpected(ok.error());  // said before the layers
  for (std::size_t i = 1; i < layers.size(); ++i)
    if (layers[i].z_bottom_mm < layers[i - 1].z_top_mm() - 1e-9)
      return invalid(fmt::format("layer {} starts at z = {} mm, below the top of layer {} ({} mm)", i,
                                 layers[i].z_bottom_mm, i - 1, layers[i - 1].z_top_mm()));
  auto planned = plan_in_order(mesh, indexes, layers, in_turn(layers.size()), params);
  if (!planned) return std::unexpected(planned.error());
  BevelPlan plan;
  plan.fit = params.fit;
  plan.layers = std::move(*planned);
  return plan;
}

std::expected<std::vector<LayerPlan>, Error> bevel_detail::plan_layers_apart(const Mesh& mesh,
                                                                             const MeshIndexes& indexes,
                                                                             std::span<const LayerSpan> layers,
                                                                             const BevelParams& params) {
  // The thickest first: the tasks that finish last are short ones.
  std::vector<std::size_t> order = in_turn(layers.size());
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return layers[a].thickness_mm > layers[b].thickness_mm; });
  return plan_in_order(mesh, indexes, layers, order, params);
}

}  // namespace lamina
