// choose_layers: validate, build the grid estimator, run the chosen method, report.
#include "lamina/core/layering.hpp"

#include "layering/layering_internal.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace lamina {

const ChoiceTable<LayeringMethod>& layering_methods() {
  static constexpr Choice<LayeringMethod> rows[] = {
      {LayeringMethod::optimal, "optimal", "the fewest layers within tolerance (dynamic programme, verified by plans)"},
      {LayeringMethod::greedy, "greedy", "the paper's rule: thickest sheet while its criteria hold"}};
  static constexpr ChoiceTable<LayeringMethod> table{"layering method", rows};
  return table;
}

const char* layering_method_name(LayeringMethod method) { return layering_methods().name_of(method); }

namespace {

std::unexpected<Error> invalid(std::string message) {
  return std::unexpected(Error{ErrorCode::invalid_argument, "layering: " + std::move(message)});
}

std::expected<std::vector<double>, Error> validate(const LayeringParams& p) {
  if (p.thicknesses_mm.empty()) return invalid("no stock thickness given (thicknesses_mm is empty)");
  for (std::size_t i = 0; i < p.thicknesses_mm.size(); ++i) {
    const double t = p.thicknesses_mm[i];
    if (!std::isfinite(t) || t <= 0.0)
      return invalid(fmt::format("stock thickness #{} is {} mm; thicknesses must be finite and > 0", i + 1, t));
    if (t < layering_detail::kPositionQuantum)
      return invalid(fmt::format("stock thickness #{} is {} mm, below 1 µm", i + 1, t));
  }
  if (!std::isfinite(p.sub_slice_mm) || p.sub_slice_mm <= 0.0)
    return invalid(fmt::format("sub_slice_mm is {}; it must be finite and > 0", p.sub_slice_mm));
  if (!std::isfinite(p.bond_mm) || p.bond_mm < 0.0)
    return invalid(fmt::format("bond_mm is {}; it must be finite and >= 0", p.bond_mm));
  if (!std::isfinite(p.tolerance_mm) || p.tolerance_mm <= 0.0)
    return invalid(fmt::format("tolerance_mm is {}; it must be finite and > 0", p.tolerance_mm));
  if (!std::isfinite(p.greedy_area_deviation) || p.greedy_area_deviation < 0.0)
    return invalid(fmt::format("greedy_area_deviation is {}; it must be finite and >= 0", p.greedy_area_deviation));
  if (!std::isfinite(p.greedy_triangle_area_mm2) || p.greedy_triangle_area_mm2 < 0.0)
    return invalid(fmt::format("greedy_triangle_area_mm2 is {}; it must be finite and >= 0", p.greedy_triangle_area_mm2));
  if (!std::isfinite(p.fit.tilt_max_rad) || p.fit.tilt_max_rad < 0.0 || p.fit.tilt_max_rad > 1.5707963267948966)
    return invalid(fmt::format("fit.tilt_max_rad is {}; it must be in [0, pi/2]", p.fit.tilt_max_rad));
  if (p.method != LayeringMethod::optimal && p.method != LayeringMethod::greedy)
    return invalid("unknown layering method");
  std::vector<double> t = p.thicknesses_mm;
  std::sort(t.begin(), t.end());
  t.erase(std::unique(t.begin(), t.end(), [](double a, double b) { return b - a <= 1e-9; }), t.end());
  return t;
}

// The stock against the model (issue 16, item 11: --stock 1e10 crashed, --stock 0.001 took
// 2.6 GB): a sheet thicker than the whole part is never needed (dropped, said); a sheet that
// rounds to no grid line cannot be placed; a stack of more than kMaxLayers layers is no plan.
constexpr double kMaxLayers = 10'000;

std::expected<std::vector<double>, Error> fit_to_model(const Mesh& mesh, const LayeringParams& p, std::vector<double> t,
                                                       std::vector<std::string>& warnings) {
  const double height = mesh.summary.bbox_max_mm.z() - mesh.summary.bbox_min_mm.z();
  if (!(height > 0.0)) return t;  // a hand-made Mesh without its summary: the estimator measures it
  if (t.front() > height)
    return invalid(fmt::format("every stock sheet is thicker than the part: the thinnest is {} mm, the part {:.3f} mm "
                               "tall along the stacking axis",
                               t.front(), height));
  std::vector<double> dropped;
  while (t.back() > height) {
    dropped.push_back(t.back());
    t.pop_back();
  }
  if (!dropped.empty()) {
    std::string list;
    for (double d : dropped) list += (list.empty() ? "" : ", ") + fmt::format("{}", d);
    warnings.push_back(fmt::format("stock sheets thicker than the whole part ({:.3f} mm) are not used: {} mm", height, list));
  }
  if (t.front() < 0.5 * p.sub_slice_mm)
    return invalid(fmt::format("stock thickness {} mm is thinner than half the sub-slice spacing ({} mm): no grid line "
                               "can place it; give a sub-slice of {} mm or less, or leave the sheet out",
                               t.front(), p.sub_slice_mm, t.front()));
  if (height / t.front() > kMaxLayers)
    return invalid(fmt::format("the part ({:.3f} mm) in {} mm sheets would be {:.0f} layers, more than {:.0f}: give "
                               "thicker stock",
                               height, t.front(), std::ceil(height / t.front()), kMaxLayers));
  return t;
}

// Where the stack ends against the model's top (issue 17, item 3): taller or shorter, and whether
// the stock could not end it nearer than half its thinnest sheet or within the tolerance.
void add_stack_end_warnings(const Layering& out, double z_base, double thinnest, const LayeringParams& params,
                            std::vector<std::string>& w) {
  if (out.layers.empty()) return;
  const LayerSpan& top = out.layers.back();
  const double off = out.stack_height_mm - out.model_height_mm;
  if (off > 1e-6)
    w.push_back(fmt::format("the stack is {:.3f} mm taller than the model ({:.3f} mm vs {:.3f} mm): the top "
                            "{} mm sheet covers the last {:.3f} mm of the model",
                            off, out.stack_height_mm, out.model_height_mm, top.thickness_mm,
                            z_base + out.model_height_mm - top.z_bottom_mm));
  if (off < -1e-6)
    w.push_back(fmt::format("the stack is {:.3f} mm shorter than the model ({:.3f} mm vs {:.3f} mm): the model's top "
                            "{:.3f} mm is not cut",
                            -off, out.stack_height_mm, out.model_height_mm, -off));
  if (std::abs(off) > 0.5 * thinnest + 1e-6)
    w.push_back(fmt::format("the stock cannot end the stack within half its thinnest sheet ({} mm) of the model's "
                            "top: it ends {:.3f} mm {} it (--side {})",
                            0.5 * thinnest, std::abs(off), off > 0 ? "above" : "below", cut_side_name(params.fit.side)));
  else if (std::abs(off) > params.tolerance_mm + 1e-9 && params.method == LayeringMethod::optimal)
    w.push_back(fmt::format("no stack of this stock ends within the tolerance ({} mm) of the model's top: the nearest "
                            "ends {:.3f} mm {} it",
                            params.tolerance_mm, std::abs(off), off > 0 ? "above" : "below"));
}

// Why the rack cannot make the stack (issue 17, item 5): each thickness it limits, by count or by
// size, and how high the most it allows reaches.
Error rack_error(const layering_detail::Estimator& est, const LayeringParams& params,
                 const layering_detail::LayerChoice& choice) {
  if (choice.state_limit)
    return Error{ErrorCode::limit_exceeded,
                 fmt::format("layering: the rack's sheet counts give more than {} combinations to search; leave the "
                             "counts of plentiful thicknesses out of the stock file",
                             layering_detail::kMaxDpStates)};
  std::string limits;
  for (std::size_t i = 0; i < est.thicknesses().size(); ++i) {
    const double t = est.thicknesses()[i];
    const ThicknessSupply* s = nullptr;
    for (const ThicknessSupply& x : params.supply)
      if (std::abs(x.thickness_mm - t) <= 1e-9) s = &x;
    if (!s || (s->max_layers < 0 && s->rooms.empty())) continue;
    std::string what = s->max_layers >= 0 ? fmt::format("at most {} layer(s)", s->max_layers) : "any number of layers";
    if (!s->rooms.empty()) {
      const auto big = std::max_element(s->rooms.begin(), s->rooms.end(), [](const auto& a, const auto& b) {
        return a.length_mm * a.width_mm < b.length_mm * b.width_mm;
      });
      what += fmt::format(" no larger than {:.0f} x {:.0f} mm", big->length_mm, big->width_mm);
    }
    limits += fmt::format("{}{} mm: {}", limits.empty() ? "" : "; ", t, what);
  }
  return Error{ErrorCode::stock_exhausted,
               fmt::format("layering: the rack cannot make a stack of the model's height ({:.3f} mm): the highest "
                           "stack its sheets allow reaches {:.3f} mm ({}); add sheets to the stock or give more "
                           "thicknesses",
                           est.height(), choice.reached_mm, limits.empty() ? "no thickness fits" : limits)};
}

// Shortfalls: runs of layers where no sheet met the tolerance (the thinnest was used); a last
// layer out of tolerance only for where it ends is said by the warnings, not here.
std::vector<Shortfall> shortfall_runs(const std::vector<LayerSpan>& layers) {
  std::vector<Shortfall> runs;
  for (std::size_t i = 0; i < layers.size(); ++i) {
    const LayerSpan& l = layers[i];
    if (!l.shortfall) continue;
    if (i > 0 && layers[i - 1].shortfall) {
      Shortfall& s = runs.back();
      s.z_to_mm = l.z_top_mm();
      s.deviation_mm = std::max(s.deviation_mm, l.estimated_deviation_mm);
    } else {
      runs.push_back(Shortfall{l.z_bottom_mm, l.z_top_mm(), l.estimated_deviation_mm});
    }
  }
  return runs;
}

}  // namespace

std::expected<Layering, Error> choose_layers(const Mesh& mesh, const LayeringParams& params) {
  auto validated = validate(params);
  if (!validated) return std::unexpected(validated.error());
  std::vector<std::string> stock_warnings;
  auto thicknesses = fit_to_model(mesh, params, std::move(*validated), stock_warnings);
  if (!thicknesses) return std::unexpected(thicknesses.error());
  auto created = layering_detail::Estimator::create(mesh, params, *thicknesses);
  if (!created) return std::unexpected(created.error());
  layering_detail::Estimator& est = **created;
  const std::vector<double>& t = est.thicknesses();

  auto verified = params.method == LayeringMethod::greedy
                      ? std::expected<layering_detail::LayerChoice, Error>(layering_detail::layer_greedy(est, params))
                      : layering_detail::layer_verified(est, mesh, params);
  if (!verified) return std::unexpected(verified.error());
  layering_detail::LayerChoice& choice = *verified;
  if (choice.state_limit || choice.layers.empty()) return std::unexpected(rack_error(est, params, choice));
  const auto& chosen = choice.layers;
  Layering out;
  out.model_height_mm = est.height();
  for (const auto& c : chosen) {
    LayerSpan l;
    l.z_bottom_mm = est.z_base() + c.z_rel;
    l.thickness_mm = t[static_cast<std::size_t>(c.thickness_index)];
    l.estimated_deviation_mm = c.estimate;
    l.within_tolerance = c.within;
    l.shortfall = !c.surface_within;
    out.layers.push_back(l);
  }
  out.stack_height_mm = out.layers.empty() ? 0.0 : out.layers.back().z_top_mm() - est.z_base();
  if (!choice.plans.empty() && choice.plans.size() == out.layers.size()) {
    auto plan = std::make_shared<BevelPlan>();
    plan->fit = params.fit;
    plan->layers = std::move(choice.plans);
    out.plan = std::move(plan);
  }

  out.shortfalls = shortfall_runs(out.layers);

  auto& w = out.warnings;
  w = std::move(stock_warnings);
  if (!mesh.usable()) w.push_back("the mesh has defects that make it unusable as a solid; the layering is approximate");
  for (const auto& s : est.warnings()) w.push_back(s);
  for (double th : t) {
    const double r = th / params.sub_slice_mm;
    if (std::abs(r - std::round(r)) > 1e-6)
      w.push_back(fmt::format("stock thickness {} mm is not a multiple of the sub-slice spacing {} mm: its layers "
                              "are estimated on the nearest grid lines",
                              th, params.sub_slice_mm));
  }
  if (params.bond_mm > 0.0) {
    const double r = params.bond_mm / params.sub_slice_mm;
    if (std::abs(r - std::round(r)) > 1e-6)
      w.push_back(fmt::format("the bond gap ({} mm) puts layers off the {} mm grid: their estimates use the "
                              "nearest grid lines",
                              params.bond_mm, params.sub_slice_mm));
  }
  add_stack_end_warnings(out, est.z_base(), t.front(), params, w);
  for (const Shortfall& s : out.shortfalls) {
    if (params.method == LayeringMethod::greedy)
      w.push_back(fmt::format("between z {:.3f} and {:.3f} mm no sheet meets the area/triangle criteria: the "
                              "thinnest ({} mm) was used (estimated deviation {:.3f} mm)",
                              s.z_from_mm, s.z_to_mm, t.front(), s.deviation_mm));
    else
      w.push_back(fmt::format("between z {:.3f} and {:.3f} mm no sheet meets the tolerance of {} mm: the thinnest "
                              "({} mm) was used (estimated deviation {:.3f} mm)",
                              s.z_from_mm, s.z_to_mm, params.tolerance_mm, t.front(), s.deviation_mm));
  }
  return out;
}

}  // namespace lamina
