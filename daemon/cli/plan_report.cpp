#include "plan_report.hpp"

#include <fmt/format.h>

#include <map>

namespace lamina::cli {
namespace {

using Json = nlohmann::ordered_json;

// 0 / "" mean "not given" in SheetStock; the report says null.
Json or_null(double v) { return v > 0.0 ? Json(v) : Json(nullptr); }

Json sheet_json(const SheetStock& s) {
  return {{"thickness_mm", s.thickness_mm},
          {"width_mm", or_null(s.width_mm)},
          {"length_mm", or_null(s.length_mm)},
          {"count", s.count > 0 ? Json(s.count) : Json(nullptr)},
          {"material", s.material.empty() ? Json(nullptr) : Json(s.material)}};
}

Json settings_json(const PlanOptions& o, const PlanSettings& s) {
  Json stock = Json::array();
  for (const SheetStock& sheet : s.stock.sheets) stock.push_back(sheet_json(sheet));
  Json j{{"stock", std::move(stock)},
         {"stock_source", s.stock_source},
         {"thicknesses_mm", s.thicknesses_mm},
         {"bond_mm", s.bond_mm},
         {"sub_slice_mm", s.sub_slice_mm},
         {"tolerance_mm", s.tolerance_mm},
         {"tilt_max_deg", o.tilt_max_deg},
         {"side", cut_side_name(s.side)},
         {"strategy", bevel_strategy_name(s.strategy)},
         {"layering", layering_method_name(s.layering)},
         {"deviation_step_mm", s.deviation_step_mm},
         {"axis", o.model.axis},
         {"direction", o.model.direction.empty() ? Json(nullptr) : Json(o.model.direction)},
         {"units", o.model.units}};
  return j;
}

Json layer_json(const LayerPlan& l, const LayerSpan* span) {
  int stations = 0;
  for (const LayerOutline& o : l.outlines) stations += static_cast<int>(o.stations.size());
  const auto shape = [&](ProfileShape s) { return l.shape_counts[static_cast<std::size_t>(s)]; };
  return {{"index", l.index},
          {"z_bottom_mm", l.z_bottom_mm},
          {"thickness_mm", l.thickness_mm},
          {"sub_slices", l.sub_slice_z_mm.size()},
          {"passes", l.passes},
          {"max_deviation_mm", l.max_deviation_mm},
          {"profile_deviation_mm", l.profile_deviation_mm},
          {"within_tolerance", l.within_tolerance},
          {"gouge_shift_mm", l.gouge_shift_mm},
          {"gouge_left_mm", l.gouge_left_mm},
          {"estimated_deviation_mm", span ? Json(span->estimated_deviation_mm) : Json(nullptr)},
          {"outlines", l.outlines.size()},
          {"stations", stations},
          {"shapes",
           {{"convex", shape(ProfileShape::convex)},
            {"concave", shape(ProfileShape::concave)},
            {"straight", shape(ProfileShape::straight)},
            {"mixed", shape(ProfileShape::mixed)},
            {"empty", shape(ProfileShape::empty)}}}};
}

Json stack_json(const Layering& layering) {
  std::map<double, int> used;
  for (const LayerSpan& l : layering.layers) ++used[l.thickness_mm];
  Json sheets = Json::object();
  for (const auto& [t, n] : used) sheets[fmt::format("{}", t)] = n;
  return {{"layers", layering.layers.size()},
          {"model_height_mm", layering.model_height_mm},
          {"stack_height_mm", layering.stack_height_mm},
          {"height_difference_mm", layering.stack_height_mm - layering.model_height_mm},
          {"sheets_used", std::move(sheets)}};
}

std::string fixed_or_dash(const Json& v, int decimals) {
  return v.is_number() ? fmt::format("{:.{}f}", v.get<double>(), decimals) : std::string("-");
}

}  // namespace

nlohmann::ordered_json plan_report_json(const PlanOptions& options, const PlanSettings& settings, const LoadedModel& model,
                                const PlanResult& r) {
  const MeshSummary& s = model.mesh.summary;
  Json layers = Json::array();
  for (std::size_t i = 0; i < r.plan.layers.size(); ++i)
    layers.push_back(layer_json(r.plan.layers[i], i < r.layering.layers.size() ? &r.layering.layers[i] : nullptr));
  Json shortfalls = Json::array();
  for (const Shortfall& f : r.layering.shortfalls)
    shortfalls.push_back({{"z_from_mm", f.z_from_mm}, {"z_to_mm", f.z_to_mm}, {"deviation_mm", f.deviation_mm}});
  Json deviation = Json::object();
  for (const StrategyDeviation& d : r.deviations)
    deviation[bevel_strategy_name(d.strategy)] = {{"volume_mm3", d.deviation.volume_mm3},
                                                  {"volume_pct", d.deviation.volume_pct},
                                                  {"max_mm", d.deviation.max_mm},
                                                  {"max_at_mm",
                                                   {d.deviation.max_at_mm.x(), d.deviation.max_at_mm.y(),
                                                    d.deviation.max_at_mm.z()}},
                                                  {"stack_volume_mm3", d.deviation.stack_volume_mm3}};
  const PlanTimings& t = r.timing;
  Json report{{"model",
               {{"file", options.model.path},
                {"format", model.format},
                {"triangles", s.triangles},
                {"volume_mm3", s.volume_mm3},
                {"height_mm", s.bbox_max_mm.z() - s.bbox_min_mm.z()}}},
              {"settings", settings_json(options, settings)},
              {"layers", std::move(layers)},
              {"stack", stack_json(r.layering)},
              {"shortfalls", std::move(shortfalls)},
              {"deviation", std::move(deviation)},
              {"warnings", r.warnings},
              {"timing_s",
               {{"read", t.read},
                {"topology", t.topology},
                {"layering", t.layering},
                {"bevel", t.bevel},
                {"deviation", t.deviation},
                {"write", t.write},
                {"total", t.total}}}};
  return report;
}

void print_plan_tables(std::FILE* out, const nlohmann::ordered_json& report, bool all_rows) {
  const auto& layers = report.at("layers");
  fmt::print(out, "{:>5} {:>9} {:>6} {:>4} {:>6} {:>8} {:>8} {:>3}  {:>6} {:>7} {:>8} {:>5}\n", "layer", "z mm",
             "t mm", "sub", "passes", "dev mm", "est mm", "ok", "convex", "concave", "straight", "mixed");
  const std::size_t n = layers.size();
  const bool elide = !all_rows && n > 40;
  for (std::size_t i = 0; i < n; ++i) {
    if (elide && i == 20) fmt::print(out, "{:>5}   ({} more layers: --all-rows or report.json)\n", "...", n - 25);
    if (elide && i >= 20 && i < n - 5) continue;
    const auto& l = layers[i];
    const auto& sh = l.at("shapes");
    fmt::print(out, "{:>5} {:>9.3f} {:>6.3g} {:>4} {:>6} {:>8.3f} {:>8} {:>3}  {:>6} {:>7} {:>8} {:>5}\n",
               l.at("index").get<int>(), l.at("z_bottom_mm").get<double>(), l.at("thickness_mm").get<double>(),
               l.at("sub_slices").get<int>(), l.at("passes").get<int>(), l.at("max_deviation_mm").get<double>(),
               fixed_or_dash(l.at("estimated_deviation_mm"), 3), l.at("within_tolerance").get<bool>() ? "yes" : "NO",
               sh.at("convex").get<int>(), sh.at("concave").get<int>(), sh.at("straight").get<int>(),
               sh.at("mixed").get<int>());
  }
  fmt::print(out, "  t: sheet thickness; sub: thin slices read; dev: largest distance between the edge the cuts\n"
                  "  leave and the surface; est: the layering's estimate of it; shape columns count cut stations\n\n");

  const std::string chosen = report.at("settings").at("strategy").get<std::string>();
  fmt::print(out, "{:<10} {:>14} {:>9} {:>8}\n", "strategy", "volume mm3", "volume %", "max mm");
  for (const char* name : {"vertical", "sloped", "curved"}) {
    if (!report.at("deviation").contains(name)) continue;
    const auto& d = report.at("deviation").at(name);
    fmt::print(out, "{:<10} {:>14.2f} {:>9.3f} {:>8.3f}{}\n", name, d.at("volume_mm3").get<double>(),
               d.at("volume_pct").get<double>(), d.at("max_mm").get<double>(), name == chosen ? "  (chosen)" : "");
  }
  fmt::print(out, "  (symmetric difference between stack and model, % of the model's {:.6g} mm3; max: largest distance)\n\n",
             report.at("model").at("volume_mm3").get<double>());

  const auto& st = report.at("stack");
  std::string sheets;
  for (const auto& [t, count] : st.at("sheets_used").items())
    sheets += fmt::format("{}{} mm x{}", sheets.empty() ? "" : ", ", t, count.get<int>());
  fmt::print(out, "stack: {} layers ({}), {:.3f} mm high; model {:.3f} mm ({:+.3f} mm)\n", st.at("layers").get<int>(),
             sheets, st.at("stack_height_mm").get<double>(), st.at("model_height_mm").get<double>(),
             st.at("height_difference_mm").get<double>());
  const double tol = report.at("settings").at("tolerance_mm").get<double>();
  for (const auto& f : report.at("shortfalls"))
    fmt::print(out, "shortfall: z {:.3f} … {:.3f} mm: no sheet keeps within {} mm; the thinnest reaches {:.3f} mm\n",
               f.at("z_from_mm").get<double>(), f.at("z_to_mm").get<double>(), tol, f.at("deviation_mm").get<double>());
  const auto& t = report.at("timing_s");
  fmt::print(out, "timing: read {:.3f} s, topology {:.3f} s, layering {:.3f} s, bevel {:.3f} s, deviation {:.3f} s, "
                  "write {:.3f} s, total {:.3f} s\n",
             t.at("read").get<double>(), t.at("topology").get<double>(), t.at("layering").get<double>(),
             t.at("bevel").get<double>(), t.at("deviation").get<double>(), t.at("write").get<double>(),
             t.at("total").get<double>());
}

}  // namespace lamina::cli
