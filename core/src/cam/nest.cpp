// Nesting driver: parts grouped by thickness, thin sheets first; within a thickness smaller parts
// first go into the free holes of larger ones (nest_holes.cpp), then the stock entries in rack
// order, each up to its count, take the rest; the packing itself is nest_matrix.cpp or
// nest_shape.cpp. A host carries its children onto whatever sheet it lands on.
#include "lamina/core/nest.hpp"

#include "cam/nest_internal.hpp"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <functional>
#include <optional>
#include <set>
#include <unordered_map>

namespace lamina {

const ChoiceTable<NestMethod>& nest_methods() {
  static constexpr Choice<NestMethod> rows[] = {
      {NestMethod::shape, "shape", "true-shape nesting (libnest2d), parts in the holes of others"},
      {NestMethod::matrix, "matrix", "the paper's rows of bounding boxes"}};
  static constexpr ChoiceTable<NestMethod> table{"nesting method", rows};
  return table;
}

const char* nest_method_name(NestMethod method) { return nest_methods().name_of(method); }

Eigen::Vector2d place_point(const Placement& placement, const Eigen::Vector2d& layer_xy) {
  return cam_detail::rotation_matrix(placement.rotation_rad) * layer_xy + placement.offset_mm;
}

Polygon2 placed_footprint(const Part& part, const Placement& placement) {
  Polygon2 out;
  out.reserve(part.footprint_mm.size());
  for (const auto& p : part.footprint_mm) out.push_back(place_point(placement, p));
  return out;
}

namespace cam_detail {

Eigen::Matrix2d rotation_matrix(double angle_rad) {
  double c = std::cos(angle_rad);
  double s = std::sin(angle_rad);
  const double quarter = angle_rad / (0.5 * std::numbers::pi);
  const double k = std::round(quarter);
  if (std::abs(quarter - k) < 1e-12) {
    const long q = ((static_cast<long>(k) % 4) + 4) % 4;
    static constexpr double cs[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
    c = cs[q][0];
    s = cs[q][1];
  }
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

Bounds rotated_bounds(const Polygon2& ring, double angle_rad) {
  const Eigen::Matrix2d r = rotation_matrix(angle_rad);
  Bounds b;
  bool first = true;
  for (const auto& p : ring) {
    const Eigen::Vector2d q = r * p;
    if (first) {
      b.min = b.max = q;
      first = false;
    } else {
      b.min = b.min.cwiseMin(q);
      b.max = b.max.cwiseMax(q);
    }
  }
  return b;
}

std::vector<double> method_rotations(const NestParams& params) {
  if (params.method == NestMethod::matrix) return {0.0, 0.5 * std::numbers::pi};
  return params.rotations_rad;
}

bool fits_on_sheet(const Part& part, SheetSize size, const NestParams& params) {
  const double ux = size.length_mm - 2.0 * params.margin_mm;
  const double uy = size.width_mm - 2.0 * params.margin_mm;
  constexpr double tol = 1e-9;
  for (double a : method_rotations(params)) {
    const Bounds b = rotated_bounds(part.footprint_mm, a);
    if (b.dx() <= ux + tol && b.dy() <= uy + tol) return true;
  }
  return false;
}

}  // namespace detail

namespace {

constexpr double kSameThicknessMm = 1e-9;  // as stock_thicknesses()

std::string label(const Part& p) { return fmt::format("L{}-{}", p.layer, p.island); }

std::string sheet_size_text(const SheetStock& s) { return fmt::format("{:g} x {:g} mm", s.length_mm, s.width_mm); }

std::optional<Error> check_params(std::span<const Part> parts, const NestParams& params) {
  auto bad = [](std::string m) { return Error{ErrorCode::invalid_argument, std::move(m)}; };
  if (!std::isfinite(params.spacing_mm) || params.spacing_mm < 0.0)
    return bad(fmt::format("nest: spacing must be finite and >= 0 mm (got {:g})", params.spacing_mm));
  if (!std::isfinite(params.margin_mm) || params.margin_mm < 0.0)
    return bad(fmt::format("nest: margin must be finite and >= 0 mm (got {:g})", params.margin_mm));
  if (params.method == NestMethod::shape) {
    if (params.rotations_rad.empty()) return bad("nest: shape nesting needs at least one rotation");
    for (double a : params.rotations_rad)
      if (!std::isfinite(a)) return bad("nest: a rotation is not finite");
  }
  for (const Part& p : parts) {
    if (p.footprint_mm.size() < 3 || !(signed_area_mm2(p.footprint_mm) > 0.0))
      return bad(fmt::format("nest: part {} has no counter-clockwise footprint ({} points)", label(p),
                             p.footprint_mm.size()));
    for (const auto& v : p.footprint_mm)
      if (!v.allFinite()) return bad(fmt::format("nest: part {} has a footprint point that is not finite", label(p)));
    if (params.fill_holes)
      for (const Polygon2& h : p.free_holes_mm) {
        const bool finite = std::all_of(h.begin(), h.end(), [](const Eigen::Vector2d& v) { return v.allFinite(); });
        if (h.size() < 3 || !finite || !(signed_area_mm2(h) > 0.0))
          return bad(fmt::format("nest: part {} has a free hole that is not a finite counter-clockwise ring", label(p)));
      }
    if (!std::isfinite(p.thickness_mm) || p.thickness_mm <= 0.0)
      return bad(fmt::format("nest: part {} has thickness {:g} mm", label(p), p.thickness_mm));
  }
  return std::nullopt;
}

std::vector<cam_detail::PackedSheet> pack(std::span<const Part> parts, std::span<const int> which, cam_detail::SheetSize size,
                                      const NestParams& params, std::vector<int>& unplaced) {
  if (which.empty()) return {};
  if (params.method == NestMethod::shape) return cam_detail::pack_shape(parts, which, size, params, unplaced);
  return cam_detail::pack_matrix(parts, which, size, params, unplaced);
}

// How many layers of a group lost no part: `unplaced` are packed parts left over, and the parts
// in their holes go with them.
SheetShortage count_placed_layers(std::span<const Part> parts, std::span<const int> group, std::span<const int> unplaced,
                                  const std::unordered_map<int, std::vector<const cam_detail::HostedPart*>>& children) {
  std::set<int> layers, lost;
  for (int p : group) layers.insert(parts[p].layer_slot);
  std::vector<int> todo(unplaced.begin(), unplaced.end());
  while (!todo.empty()) {
    const int p = todo.back();
    todo.pop_back();
    lost.insert(parts[p].layer_slot);
    if (auto it = children.find(p); it != children.end())
      for (const cam_detail::HostedPart* h : it->second) todo.push_back(h->in_host.part);
  }
  SheetShortage s;
  s.layers = static_cast<int>(layers.size());
  s.layers_placed = s.layers - static_cast<int>(lost.size());
  return s;
}

std::unexpected<Error> nest_error(std::string m) { return std::unexpected(Error{ErrorCode::invalid_argument, std::move(m)}); }

cam_detail::SheetSize size_of(const SheetStock& s) { return cam_detail::SheetSize{s.length_mm, s.width_mm}; }

// The stock entries of this thickness, checked: known sizes, counts, and every part fits one.
std::expected<std::vector<int>, Error> thickness_entries(std::span<const Part> parts, std::span<const int> group,
                                                         double thickness, const Stock& stock, const NestParams& params) {
  std::vector<int> entries;
  for (int i = 0; i < static_cast<int>(stock.sheets.size()); ++i)
    if (std::abs(stock.sheets[i].thickness_mm - thickness) <= kSameThicknessMm) entries.push_back(i);
  if (entries.empty())
    return nest_error(fmt::format("nest: no sheet of thickness {:g} mm in stock for {} part(s) (first {})", thickness,
                                  group.size(), label(parts[group.front()])));
  for (int e : entries) {
    const SheetStock& s = stock.sheets[e];
    if (!(s.width_mm > 0.0) || !(s.length_mm > 0.0) || !std::isfinite(s.width_mm) || !std::isfinite(s.length_mm))
      return nest_error(fmt::format("nest: the {:g} mm sheet (stock entry {}) has no known size (length {:g}, width {:g} "
                                    "mm); nesting needs width_mm and length_mm",
                                    thickness, e + 1, s.length_mm, s.width_mm));
    if (s.count < 0)
      return nest_error(fmt::format("nest: the {:g} mm sheet (stock entry {}) has count {}", thickness, e + 1, s.count));
  }
  for (int p : group) {
    const bool fits = std::any_of(entries.begin(), entries.end(), [&](int e) {
      return cam_detail::fits_on_sheet(parts[p], size_of(stock.sheets[e]), params);
    });
    if (fits) continue;
    const cam_detail::Bounds b = cam_detail::rotated_bounds(parts[p].footprint_mm, 0.0);
    std::string sizes;
    for (int e : entries) sizes += (sizes.empty() ? "" : ", ") + sheet_size_text(stock.sheets[e]);
    return nest_error(fmt::format("nest: part {} ({:.1f} x {:.1f} mm) is larger than every {:g} mm sheet ({}) less the "
                                  "{:g} mm margin",
                                  label(parts[p]), b.dx(), b.dy(), thickness, sizes, params.margin_mm));
  }
  return entries;
}

// Children in holes travel with their hosts: only the rest is packed.
struct HostedTree {
  std::unordered_map<int, std::vector<const cam_detail::HostedPart*>> children;

  explicit HostedTree(const cam_detail::HoleFilling& filling) {
    for (const cam_detail::HostedPart& h : filling.hosted) children[h.host].push_back(&h);
  }
  // A packed placement with its children (composed, recursively) before it; each child's `host`
  // is the index of the placement whose hole holds it.
  void emit(const Placement& pl, std::vector<Placement>& list) const {
    std::vector<std::size_t> direct;
    if (auto it = children.find(pl.part); it != children.end())
      for (const cam_detail::HostedPart* h : it->second) {
        emit(cam_detail::compose(pl, h->in_host), list);
        direct.push_back(list.size() - 1);
      }
    list.push_back(pl);
    for (std::size_t i : direct) list[i].host = static_cast<int>(list.size() - 1);
  }
  // The part and every part it carries.
  int carried(int part) const {
    int n = 1;
    if (auto it = children.find(part); it != children.end())
      for (const cam_detail::HostedPart* h : it->second) n += carried(h->in_host.part);
    return n;
  }
};

NestedSheet nested_sheet(std::span<const Part> parts, const cam_detail::PackedSheet& packed, int entry,
                         const SheetStock& s, const HostedTree& tree) {
  NestedSheet ns;
  ns.stock_index = entry;
  ns.thickness_mm = s.thickness_mm;
  ns.width_mm = s.width_mm;
  ns.length_mm = s.length_mm;
  ns.material = s.material;
  ns.slot = s.slot;
  for (const Placement& pl : packed.placements) tree.emit(pl, ns.placements);
  double area = 0.0;
  for (const Placement& pl : ns.placements) area += parts[pl.part].area_mm2;
  ns.utilisation = area / (s.width_mm * s.length_mm);
  return ns;
}

// What the sheets of one thickness took, and what they could not.
struct ThicknessFill {
  std::vector<NestedSheet> sheets;
  std::vector<int> remaining;  // parts left over
  int in_stock = 0;
  int short_by = 0;            // sheets needed beyond the last kind's count
  std::string short_kind;
};

// Packs the stock entries in order; each takes what fits it, up to its count.
ThicknessFill fill_entries(std::span<const Part> parts, const std::vector<int>& entries, const Stock& stock,
                           const NestParams& params, const HostedTree& tree, std::vector<int> remaining) {
  ThicknessFill f;
  for (std::size_t k = 0; k < entries.size() && !remaining.empty(); ++k) {
    const int e = entries[k];
    const SheetStock& s = stock.sheets[e];
    f.in_stock += s.count;
    std::vector<int> here, later;
    for (int p : remaining) (cam_detail::fits_on_sheet(parts[p], size_of(s), params) ? here : later).push_back(p);
    std::vector<int> unplaced;
    std::vector<cam_detail::PackedSheet> sheets = pack(parts, here, size_of(s), params, unplaced);
    later.insert(later.end(), unplaced.begin(), unplaced.end());
    const std::size_t take = s.count == 0 ? sheets.size() : std::min<std::size_t>(s.count, sheets.size());
    for (std::size_t i = 0; i < sheets.size(); ++i) {
      if (i < take) {
        f.sheets.push_back(nested_sheet(parts, sheets[i], e, s, tree));
        continue;
      }
      for (const Placement& pl : sheets[i].placements) later.push_back(pl.part);
    }
    if (k + 1 == entries.size() && sheets.size() > take) {
      f.short_by = static_cast<int>(sheets.size() - take);
      f.short_kind = sheet_size_text(s);
    }
    std::sort(later.begin(), later.end());
    remaining = std::move(later);
  }
  f.remaining = std::move(remaining);
  return f;
}

// Parts left over: those the last kind of sheet would take are counted as `short_by`; any
// others only fit an earlier (exhausted) kind.
Error shortage_error(double thickness, const std::vector<int>& entries, const Stock& stock, const ThicknessFill& f,
                     const HostedTree& tree) {
  std::string stock_text;
  for (int e : entries)
    stock_text += fmt::format("{}{} of {}", stock_text.empty() ? "" : ", ", stock.sheets[e].count,
                              sheet_size_text(stock.sheets[e]));
  const std::string needed =
      f.short_by > 0 ? fmt::format("at least {} sheets needed ({} more of {})", f.in_stock + f.short_by, f.short_by,
                                   f.short_kind)
                     : std::string("more sheets of an earlier size needed");
  int left = 0;
  for (int p : f.remaining) left += tree.carried(p);
  return Error{ErrorCode::stock_exhausted,
               fmt::format("nest: not enough {:g} mm sheets: {} in stock ({}), {} part(s) left over; {}", thickness,
                           f.in_stock, stock_text, left, needed)};
}

// The sheets of one thickness (numbered later), or the error naming the thickness.
std::expected<std::vector<NestedSheet>, Error> nest_thickness(std::span<const Part> parts, std::span<const int> group,
                                                              double thickness, const Stock& stock,
                                                              const NestParams& params, SheetShortage& shortage) {
  auto entries = thickness_entries(parts, group, thickness, stock, params);
  if (!entries) return std::unexpected(entries.error());
  cam_detail::HoleFilling filling;
  if (params.fill_holes)
    filling = cam_detail::fill_holes(parts, group, params);
  else
    filling.free.assign(group.begin(), group.end());
  const HostedTree tree(filling);
  ThicknessFill f = fill_entries(parts, *entries, stock, params, tree, filling.free);
  if (!f.remaining.empty()) {
    shortage = count_placed_layers(parts, group, f.remaining, tree.children);
    shortage.thickness_mm = thickness;
    return std::unexpected(shortage_error(thickness, *entries, stock, f, tree));
  }
  return std::move(f.sheets);
}

}  // namespace

std::expected<Nest, Error> nest_parts(std::span<const Part> parts, const Stock& stock, const NestParams& params,
                                      std::vector<SheetShortage>* shortages) {
  if (auto err = check_params(parts, params)) return std::unexpected(*err);
  // Thickness groups, ascending (thin sheets are cut first); parts keep input order in a group.
  std::vector<int> order(parts.size());
  for (std::size_t i = 0; i < parts.size(); ++i) order[i] = static_cast<int>(i);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return parts[a].thickness_mm < parts[b].thickness_mm; });
  std::vector<std::vector<int>> groups;
  std::vector<double> thickness;
  for (int i : order) {
    if (groups.empty() || parts[i].thickness_mm - thickness.back() > kSameThicknessMm) {
      groups.emplace_back();
      thickness.push_back(parts[i].thickness_mm);
    }
    groups.back().push_back(i);
  }
  std::vector<std::expected<std::vector<NestedSheet>, Error>> results(
      groups.size(), std::unexpected(Error{ErrorCode::invalid_argument, ""}));
  std::vector<SheetShortage> shortage(groups.size());
  auto run = [&](std::size_t g) {
    results[g] = nest_thickness(parts, groups[g], thickness[g], stock, params, shortage[g]);
  };
  if (params.parallel && groups.size() > 1) {
    tbb::parallel_for(std::size_t{0}, groups.size(), run);
  } else {
    for (std::size_t g = 0; g < groups.size(); ++g) run(g);
  }
  if (shortages)
    for (std::size_t g = 0; g < groups.size(); ++g)
      if (!results[g] && results[g].error().code == ErrorCode::stock_exhausted) shortages->push_back(shortage[g]);
  Nest nest;
  for (auto& r : results) {
    if (!r) return std::unexpected(r.error());  // the thinnest failing thickness
    for (NestedSheet& s : *r) {
      s.index = static_cast<int>(nest.sheets.size()) + 1;
      nest.sheets.push_back(std::move(s));
    }
  }
  return nest;
}

}  // namespace lamina
