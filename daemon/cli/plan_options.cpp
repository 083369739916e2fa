#include "plan_options.hpp"

#include "model_options.hpp"
#include "stock_config.hpp"

#include "lamina/core/mesh_io.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <numbers>

namespace lamina::cli {
namespace {

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// A number in [lo, hi] (lo excluded when `open_lo`), in `unit`; CLI11's own range message prints
// DBL_MAX in full, this one says what is wanted.
CLI::Validator in_range(double lo, bool open_lo, double hi, std::string unit) {
  const std::string want = hi < 1e300 ? fmt::format("{} {} … {} {}", open_lo ? "above" : "from", lo, hi, unit)
                                      : fmt::format("{} {} {}", open_lo ? ">" : ">=", lo, unit);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        const std::string_view t = trimmed(text);
        double v = 0.0;
        const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
        if (t.empty() || ec != std::errc{} || end != t.data() + t.size() || !std::isfinite(v))
          return fmt::format("'{}' is not a number", text);
        if (v < lo || (open_lo && v == lo) || v > hi) return fmt::format("{} is out of range: must be {}", text, want);
        return {};
      },
      want, "range");
}

}  // namespace

std::expected<std::vector<double>, std::string> parse_thickness_list(std::string_view text) {
  constexpr std::string_view hint = "(thicknesses in mm, separated by commas, e.g. 1,2.5,5,10)";
  std::vector<double> out;
  if (trimmed(text).empty()) return std::unexpected(fmt::format("empty stock list {}", hint));
  for (std::size_t pos = 0;;) {
    const std::size_t comma = text.find(',', pos);
    const std::string_view item = trimmed(text.substr(pos, comma == std::string_view::npos ? comma : comma - pos));
    if (item.empty()) return std::unexpected(fmt::format("empty item in '{}' {}", text, hint));
    double v = 0.0;
    const auto [end, ec] = std::from_chars(item.data(), item.data() + item.size(), v);
    if (ec != std::errc{} || end != item.data() + item.size() || !std::isfinite(v))
      return std::unexpected(fmt::format("'{}' is not a number {}", item, hint));
    if (v <= 0.0) return std::unexpected(fmt::format("'{}': a sheet thickness must be > 0 mm", item));
    out.push_back(v);
    if (comma == std::string_view::npos) break;
    pos = comma + 1;
  }
  return out;
}

void add_plan_options(CLI::App& cmd, PlanOptions& o) {
  add_model_options(cmd, o.model);
  cmd.add_option("--stock", o.stock_list,
                 "Sheet thicknesses (mm), comma-separated; replaces the sheets of --stock-file")
      ->check(CLI::Validator(
          [](std::string& v) -> std::string {
            auto list = parse_thickness_list(v);
            return list ? std::string{} : list.error();
          },
          "MM,MM,…", "thickness list"))
      ->each([&o](const std::string&) { o.stock_list_given = true; })
      ->capture_default_str();
  cmd.add_option("--stock-file", o.stock_file, "The rack as a TOML file of [[sheet]] tables (see config/stock.toml)");
  cmd.add_option("--bond", o.bond_mm, "Bonding gap between layers (mm)")->check(in_range(0.0, false, 1e308, "mm"))->capture_default_str();
  cmd.add_option("--sub-slice", o.sub_slice_mm, "Spacing of the thin slices inside a layer (mm)")
      ->check(in_range(0.0, true, 1e308, "mm"))
      ->capture_default_str();
  cmd.add_option("--tolerance", o.tolerance_mm, "Allowed deviation of a layer's edge from the surface (mm)")
      ->check(in_range(0.0, true, 1e308, "mm"))
      ->capture_default_str();
  cmd.add_option("--tilt-max", o.tilt_max_deg, "The machine's largest jet tilt from vertical (degrees)")
      ->check(in_range(0.0, false, 89.0, "degrees"))
      ->capture_default_str();
  cmd.add_option("--side", o.side, "Which side of the surface cuts may lie on")
      ->check(CLI::IsMember(cut_sides().names()))
      ->capture_default_str();
  cmd.add_option("--strategy", o.strategy, "How layer edges are cut: curved form, one sloped chord, vertical")
      ->check(CLI::IsMember(bevel_strategies().names()))
      ->capture_default_str();
  cmd.add_option("--layering", o.layering, "Layer choice: optimal (dynamic programme) or greedy (the paper's rule)")
      ->check(CLI::IsMember(layering_methods().names()))
      ->capture_default_str();
  cmd.add_option("--deviation-step", o.deviation_step_mm, "Spacing of the sections the deviation is integrated over (mm)")
      ->check(in_range(0.0, true, 1e308, "mm"))
      ->capture_default_str();
  cmd.add_option("--deviation-chord-tolerance", o.deviation_chord_mm,
                 "STEP / IGES: measure the deviation against the file tessellated to this chord, mm (0: against the "
                 "planned tessellation; default a tenth of its chord: the CAD surface to within that)")
      ->check(CLI::Range(0.0, 10.0));
  cmd.add_option("--deviation-against", o.deviation_against,
                 "Measure the deviation against this file of the same part, in the same coordinates (e.g. the "
                 "customer's STEP for a plan of its STL)");
  cmd.add_option("--compare-strategies", o.compare_strategies,
                 "Also measure the deviation of the strategies not chosen, on the same layering (true/false; it "
                 "about doubles the time)")
      ->capture_default_str();
  cmd.add_option("--out", o.out_dir, "Folder for report.json, stack.stl and, unless --no-programs, each sheet's program and drawing "
                 "(sheet-1.nc, sheet-1.svg, …); created if missing")->required();
  cmd.add_flag("--json", o.json, "Print the report as JSON on stdout instead of the tables");
  cmd.add_option("--progress-fd", o.progress_fd, "Write one JSON line per planning phase to this open file descriptor")
      ->check(CLI::NonNegativeNumber);
  cmd.add_flag("--all-rows", o.all_rows, "Print every layer in the table");
  cmd.add_option("--as-cut", o.as_cut_dir,
                 "Folder of the sheets as cut (sheet-<n>.ascut.json from lamina-sim --as-cut): measure the part as cut "
                 "beside the plan (report.json's as_cut)");
  cmd.footer(
      "All plan lengths (--stock, --bond, --sub-slice, --tolerance, --deviation-step) are in mm and\n"
      "--tilt-max in degrees, whatever --units says: --units is the unit of the model file only.\n"
      "Exit status: 0 planned, 1 the model, the stock file, nesting or the output folder failed, 2 usage error\n"
      "(also a value the model makes absurd: a sheet thicker than the part, a grid too fine for its height).\n"
      "A run that fails leaves --out as it found it.");
}

std::optional<ModelOptions> deviation_reference_options(const PlanOptions& o, const ModelOptions& planned) {
  const bool against_other = !o.deviation_against.empty();
  const std::string& path = against_other ? o.deviation_against : planned.path;
  if (!is_cad_path(path)) {
    if (!against_other) return std::nullopt;  // a mesh plan is measured against its own mesh
    ModelOptions other = planned;
    other.path = path;
    return other;
  }
  // A B-rep: ten times finer than the plan's tessellation unless told (0: the planned one's; for
  // the model itself, the planned mesh).
  const double planned_chord = planned.chord_tolerance_mm.value_or(o.tolerance_mm / 10);
  double chord = o.deviation_chord_mm.value_or(planned_chord / 10);
  if (chord <= 0) {
    if (!against_other) return std::nullopt;
    chord = planned_chord;
  }
  ModelOptions fine = planned;
  fine.path = path;
  fine.units = "mm";  // a STEP file names its own
  fine.chord_tolerance_mm = chord;
  return fine;
}

std::expected<PlanSettings, Error> resolve_plan_settings(const PlanOptions& o) {
  PlanSettings s;
  if (!o.stock_file.empty()) {
    auto stock = read_stock_file(o.stock_file);
    if (!stock) return std::unexpected(stock.error());
    s.stock = std::move(*stock);
    s.stock_source = o.stock_file;
  }
  if (o.stock_list_given || o.stock_file.empty()) {
    auto list = parse_thickness_list(o.stock_list);
    if (!list) return std::unexpected(Error{ErrorCode::invalid_argument, "--stock: " + list.error()});
    if (!o.stock_file.empty())
      s.warnings.push_back(fmt::format("--stock {} replaces the sheets of {}", o.stock_list, o.stock_file));
    s.stock = sheets_of_unknown_size(*list);
    s.stock_source = o.stock_list_given ? "--stock" : "default";
  }
  s.thicknesses_mm = stock_thicknesses(s.stock);
  s.bond_mm = o.bond_mm;
  s.sub_slice_mm = o.sub_slice_mm;
  s.tolerance_mm = o.tolerance_mm;
  s.tilt_max_deg = o.tilt_max_deg;
  s.tilt_max_rad = o.tilt_max_deg * std::numbers::pi / 180.0;  // the one degree → radian conversion
  s.deviation_step_mm = o.deviation_step_mm;
  s.compare_strategies = o.compare_strategies;
  auto side = cut_sides().parse(o.side);
  auto strategy = bevel_strategies().parse(o.strategy);
  auto layering = layering_methods().parse(o.layering);
  for (const auto* e : {side ? nullptr : &side.error(), strategy ? nullptr : &strategy.error(),
                        layering ? nullptr : &layering.error()})
    if (e) return std::unexpected(*e);
  s.side = *side;
  s.strategy = *strategy;
  s.layering = *layering;
  const double thinnest = s.thicknesses_mm.front();
  if (s.sub_slice_mm > thinnest)
    s.warnings.push_back(fmt::format("--sub-slice {} mm is more than the thinnest sheet ({} mm): layers of that "
                                     "sheet are read at their faces only",
                                     s.sub_slice_mm, thinnest));
  if (s.deviation_step_mm > 0.5 * thinnest)
    s.warnings.push_back(fmt::format("--deviation-step {} mm is coarse for {} mm sheets: the deviation volume is "
                                     "approximate",
                                     s.deviation_step_mm, thinnest));
  return s;
}

}  // namespace lamina::cli
