// lamina plan MODEL --out DIR: layers from the stock, the bevel cuts of each layer, the deviation
// of the same layering cut three ways (vertical, sloped, curved), DIR/stack.stl and DIR/report.json.
#include "commands.hpp"
#include "plan_cam.hpp"
#include "plan_output.hpp"
#include "plan_options.hpp"
#include "plan_progress.hpp"
#include "plan_rack.hpp"
#include "plan_report.hpp"

#include "lamina/core/deviation.hpp"
#include "lamina/core/stack_mesh.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <cmath>
#include <memory>
#include <optional>
#include <unistd.h>

namespace lamina::cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

int report_error(const Error& e, int exit_code = 1) {
  fmt::print(stderr, "error [{}]: {}\n", error_code_name(e.code), e.message);
  return exit_code;
}

// What the layering and the plan leave for a person to decide: layers over tolerance, and layers
// that do not fit any sheet of their thickness whose size is known.
void add_plan_warnings(const PlanSettings& settings, const BevelPlan& plan, std::vector<std::string>& warnings) {
  int over = 0;
  const LayerPlan* worst = nullptr;
  for (const LayerPlan& l : plan.layers) {
    if (l.within_tolerance) continue;
    ++over;
    if (!worst || l.max_deviation_mm > worst->max_deviation_mm) worst = &l;
  }
  if (worst)
    warnings.push_back(fmt::format("{} layer(s) exceed the tolerance of {} mm (worst: layer {}, {:.3f} mm)", over,
                                   settings.tolerance_mm, worst->index, worst->max_deviation_mm));

  // Outside cuts that still take part material where the stations could not move far enough
  // (issue 17, item 1): said per layer, with the depth.
  for (const LayerPlan& l : plan.layers)
    if (l.gouge_left_mm > 1e-3)
      warnings.push_back(fmt::format("layer {} (z {:.3f}–{:.3f} mm): the cuts take up to {:.3f} mm of the part where a "
                                     "sharp corner slides across the layer; stations were moved out by up to {:.3f} mm",
                                     l.index, l.z_bottom_mm, l.z_top_mm(), l.gouge_left_mm, l.gouge_shift_mm));

  for (const LayerPlan& l : plan.layers) {
    double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
    for (const LayerOutline& o : l.outlines)
      for (const CutStation& s : o.stations) {
        x0 = std::min(x0, s.base_mm.x()), x1 = std::max(x1, s.base_mm.x());
        y0 = std::min(y0, s.base_mm.y()), y1 = std::max(y1, s.base_mm.y());
      }
    if (x1 < x0) continue;
    const double a = std::max(x1 - x0, y1 - y0), b = std::min(x1 - x0, y1 - y0);
    bool known = false, fits = false;
    for (const SheetStock& s : settings.stock.sheets) {
      if (std::abs(s.thickness_mm - l.thickness_mm) > 1e-9 || s.width_mm <= 0.0 || s.length_mm <= 0.0) continue;
      known = true;
      fits = fits || (a <= std::max(s.width_mm, s.length_mm) && b <= std::min(s.width_mm, s.length_mm));
    }
    if (known && !fits)
      warnings.push_back(fmt::format("layer {} ({:.4g} x {:.4g} mm) is larger than every {} mm sheet in the stock", l.index,
                                     x1 - x0, y1 - y0, l.thickness_mm));
  }
}

std::string stl_header(const PlanOptions& o, const PlanResult& r) {
  // Never "solid…": readers would take the file for ASCII STL.
  std::string h = fmt::format("lamina stack: {} layers, {} cut, of {}", r.plan.layers.size(), o.strategy,
                              fs::path(o.model.path).filename().string());
  if (h.size() > 80) h.resize(80);
  return h;
}

// A parameter the model makes absurd is a usage error (exit 2), found before any work (issue 17,
// item 7): the layering checks its own grid and stock at once; the deviation's sections are
// counted here, not after the layering and bevels have run.
std::expected<void, Error> check_against_model(const PlanSettings& s, const Mesh& mesh) {
  const double height = mesh.summary.bbox_max_mm.z() - mesh.summary.bbox_min_mm.z();
  const double sections = std::ceil(height / s.deviation_step_mm);
  if (sections > kMaxDeviationSections)
    return std::unexpected(Error{ErrorCode::invalid_argument,
                                 fmt::format("--deviation-step {} mm gives {:.3g} sections over the model's {:.3f} mm, "
                                             "more than {:.0f}: give --deviation-step {:.3g} mm or more",
                                             s.deviation_step_mm, sections, height, kMaxDeviationSections,
                                             height / kMaxDeviationSections)});
  return {};
}

int exit_code_of(const Error& e) { return e.code == ErrorCode::invalid_argument ? 2 : 1; }

// Sheet files of an earlier run that this run does not rewrite must not be mistaken for its own.
bool is_sheet_file(const std::string& name) {
  return name.starts_with("sheet-") && (name.ends_with(".nc") || name.ends_with(".svg"));
}

// At most this many layouts of the stack against the rack: each lowers a thickness's count.
constexpr int kMaxRackRounds = 16;

// Layers, bevels and (unless --no-programs) parts, nesting and programs, fitted to the rack
// (issue 17, item 5): a layer is only cut from sheets its outlines fit, and when the nesting runs
// out of a thickness, that thickness is limited to the layers its sheets held and the stack is
// laid out again, so the plan fits the rack or one error says which thickness runs out.
// Returns 0, or the exit code after the error was said.
int plan_on_rack(const Mesh& mesh, const PlanSettings& settings, const std::optional<CamSettings>& cam_settings,
                 const std::optional<Stock>& stock, const std::string& title, std::vector<std::string> rack_warnings,
                 PlanProgress& progress, PlanResult& r, std::optional<CamResult>& cam) {
  LayeringParams params = layering_params(settings);
  params.supply = cam_settings ? rack_supply(*stock, cam_settings->machine.nest.margin_mm, cam_settings->parts.kerf_mm)
                               : rack_supply(settings.stock, 0.0, 0.0);
  for (int round = 0;; ++round) {
    if (round == 0) progress.phase("choosing layers");
    auto t0 = Clock::now();
    auto layering = choose_layers(mesh, params);
    r.timing.layering += seconds_since(t0);
    if (!layering) return report_error(layering.error(), exit_code_of(layering.error()));
    r.layering = std::move(*layering);

    if (round == 0) progress.phase("planning bevels");
    t0 = Clock::now();
    if (r.layering.plan) {  // the layering planned its layers with these parameters already
      r.plan = *r.layering.plan;
    } else {
      auto plan = plan_bevels(mesh, r.layering.layers, bevel_params(settings, settings.strategy));
      if (!plan) return report_error(plan.error());
      r.plan = std::move(*plan);
    }
    r.timing.bevel += seconds_since(t0);
    if (!cam_settings) break;

    if (round == 0) progress.phase("nesting and programs");
    std::vector<SheetShortage> shortages;
    auto c = plan_cam(r.plan, *stock, *cam_settings, title, &shortages);
    if (c) {
      cam = std::move(*c);
      break;
    }
    if (c.error().code != ErrorCode::stock_exhausted || round + 1 >= kMaxRackRounds ||
        !lower_rack_limits(params.supply, shortages, r.layering, *stock, rack_warnings))
      return report_error(c.error());
  }
  r.warnings.insert(r.warnings.end(), r.layering.warnings.begin(), r.layering.warnings.end());
  add_plan_warnings(settings, r.plan, r.warnings);
  r.warnings.insert(r.warnings.end(), rack_warnings.begin(), rack_warnings.end());
  if (cam) r.warnings.insert(r.warnings.end(), cam->warnings.begin(), cam->warnings.end());
  return 0;
}

// The same layering cut three ways; the chosen strategy's plan is reused, not recomputed.
std::expected<void, Error> measure_strategies(const Mesh& mesh, const PlanSettings& settings, PlanResult& r) {
  for (const BevelStrategy s : {BevelStrategy::vertical, BevelStrategy::sloped, BevelStrategy::curved}) {
    std::optional<BevelPlan> other;
    if (s != settings.strategy) {
      BevelParams geometry_only = bevel_params(settings, s);
      geometry_only.measure_surface_distance = false;  // its stack is measured as a whole below
      auto p = plan_bevels(mesh, r.layering.layers, geometry_only);
      if (!p) return std::unexpected(p.error());
      other = std::move(*p);
    }
    auto d = measure_deviation(mesh, other ? *other : r.plan, deviation_params(settings));
    if (!d) return std::unexpected(d.error());
    r.deviations.push_back({s, *d});
  }
  return {};
}

int run_plan(const PlanOptions& o, const CamOptions& cam_options) {
  const auto t_start = Clock::now();
  auto settings = resolve_plan_settings(o);
  if (!settings) return report_error(settings.error(), exit_code_of(settings.error()));
  std::optional<CamSettings> cam_settings;
  if (!cam_options.no_programs) {
    auto c = resolve_cam_settings(cam_options);
    if (!c) return report_error(c.error(), exit_code_of(c.error()));
    cam_settings = std::move(*c);
  }
  // A typo in --out must not cost a full plan; nothing is created before the plan is whole.
  if (auto ok = check_out_dir(o.out_dir); !ok) return report_error(ok.error());
  const fs::path dir(o.out_dir);
  PlanProgress progress(o.progress_fd, cam_settings ? 7 : 5);

  progress.phase("reading the model");
  auto model = load_model(o.model);
  if (!model) return report_error(model.error());
  const Mesh& mesh = model->mesh;
  PlanResult r;
  r.warnings = settings->warnings;
  for (const Defect& d : mesh.defects)
    if (d.severity == Severity::error || d.severity == Severity::warning) r.warnings.push_back(d.code + ": " + d.message);
  if (!mesh.usable())
    return report_error({ErrorCode::invalid_argument,
                         fmt::format("{} is not usable as a solid (see lamina check {})", o.model.path, o.model.path)});
  r.timing.read = model->read_s;
  r.timing.topology = model->topology_s;
  const double sheet_longest_mm =
      cam_settings ? std::max(cam_settings->machine.sheet_width_mm, cam_settings->machine.sheet_length_mm) : 2500.0;
  if (auto note = implausible_size(mesh, o.model, sheet_longest_mm)) r.warnings.push_back(*note);
  if (auto note = overlapping_shells(mesh)) r.warnings.push_back(*note);
  if (auto ok = check_against_model(*settings, mesh); !ok) return report_error(ok.error(), exit_code_of(ok.error()));

  std::optional<CamResult> cam;
  std::optional<Stock> stock;
  std::vector<std::string> stock_warnings;  // said after the layering's, before the sheets'
  if (cam_settings) stock = sized_stock(settings->stock, cam_settings->machine, stock_warnings);
  const std::string title = fs::path(o.model.path).filename().string();
  if (int code = plan_on_rack(mesh, *settings, cam_settings, stock, title, std::move(stock_warnings), progress, r, cam))
    return code;

  progress.phase("measuring deviation");
  auto t0 = Clock::now();
  if (auto ok = measure_strategies(mesh, *settings, r); !ok) return report_error(ok.error());
  r.timing.deviation = seconds_since(t0);

  // Every file is made in memory first: a failure anywhere writes nothing.
  progress.phase("writing the stack");
  t0 = Clock::now();
  const std::string stl = binary_stl_bytes(stack_mesh(r.plan), stl_header(o, r));
  r.timing.write = seconds_since(t0);
  if (cam) progress.phase("writing sheets");
  t0 = Clock::now();
  auto out = StagedOutput::open(o.out_dir);
  if (!out) return report_error(out.error());
  if (auto w = out->stage("stack.stl", stl); !w) return report_error(w.error());
  if (cam)
    for (const SheetOutput& s : cam->sheets)
      for (const auto& [name, bytes] : {std::pair{s.program_name, &s.program.text}, std::pair{s.svg_name, &s.svg}})
        if (auto w = out->stage(name, *bytes); !w) return report_error(w.error());
  r.timing.write += seconds_since(t0);
  r.timing.total = seconds_since(t_start);

  nlohmann::ordered_json report = plan_report_json(o, *settings, *model, r);
  if (cam) {
    report["cam"] = cam_json(*cam_settings, *cam);
    report["sheets"] = sheets_json(*cam);
  }
  if (auto w = out->stage("report.json", report.dump(2) + "\n"); !w) return report_error(w.error());
  if (auto w = out->publish(is_sheet_file); !w) return report_error(w.error());
  progress.done();

  if (o.json) {
    fmt::print("{}\n", report.dump(2));
  } else {
    print_plan_tables(stdout, report, o.all_rows);
    fmt::print("\n");
    print_sheet_table(stdout, report);
    fmt::print("wrote {} ({} bytes), {}", (dir / "stack.stl").string(), stl.size(), (dir / "report.json").string());
    if (cam && !cam->sheets.empty())
      fmt::print(", and {} program(s) + drawing(s) {}/sheet-<n>.nc, .svg", cam->sheets.size(), dir.string());
    fmt::print("\n");
  }
  std::fflush(stdout);  // warnings after the tables they refer to, even when both go to one pipe
  for (const std::string& w : r.warnings) fmt::print(stderr, "warning: {}\n", w);
  return 0;
}

}  // namespace

void add_plan_command(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<PlanOptions>();
  auto cam = std::make_shared<CamOptions>();
  CLI::App* cmd = app.add_subcommand(
      "plan",
      "Choose layers from the stock, plan the bevel cuts, nest the parts on sheets, write DIR/stack.stl, "
      "DIR/sheet-<n>.nc and .svg, and DIR/report.json");
  add_plan_options(*cmd, *o);
  add_cam_options(*cmd, *cam);
  cmd->callback([o, cam, &exit_code] { exit_code = run_plan(*o, *cam); });
}

}  // namespace lamina::cli
