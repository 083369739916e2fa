// plan_job (plan_job.hpp): the stages of a plan put together once, for every front end.
#include "lamina/core/elapsed.hpp"
#include "lamina/core/plan_job.hpp"
#include "lamina/core/stack_mesh.hpp"

#include <fmt/format.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

namespace lamina {
namespace {

using Clock = std::chrono::steady_clock;

// At most this many layouts of the stack against the rack: each lowers a thickness's count.
constexpr int kMaxRackRounds = 16;

std::unexpected<PlanJobError> failed(PlanPhase phase, Error e) { return std::unexpected(PlanJobError{phase, std::move(e)}); }

class Progress {
 public:
  explicit Progress(const PlanProgressFn& fn) : fn_(fn) {}
  void start(PlanPhase p) { step(p, 0, 0); }
  void step(PlanPhase p, int done, int total) {
    if (fn_) fn_(PlanStep{p, done, total});
  }

 private:
  const PlanProgressFn& fn_;
};

// A parameter the model makes absurd is a usage error, found before any work (issue 17, item 7):
// the layering checks its own grid and stock at once; the deviation's sections are counted here,
// not after the layering and bevels have run.
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

void add_tolerance_warnings(const PlanSettings& settings, const BevelPlan& plan, std::vector<std::string>& warnings) {
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
}

// Layers that do not fit any sheet of their thickness whose size is known.
void add_fit_warnings(const PlanSettings& settings, const BevelPlan& plan, std::vector<std::string>& warnings) {
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

struct Run {
  const Mesh& mesh;
  const PlanJobRequest& q;
  Progress progress;
  PlanJobResult r;
  ReportTiming timing;
  std::vector<std::string> warnings;
  std::shared_ptr<const ModelDistanceIndex> model_index;  // model_index(): built on first use
};

// What the plan alone decides, without the rack: its deviation(s) and its stack as STL.
struct PlanMeasures {
  std::expected<std::vector<StrategyDeviation>, PlanJobError> deviations;
  double deviation_s = 0.0;
  std::string stack_stl;
  double write_s = 0.0;
};

// The model's triangle tree, built on first use and shared by the layering and the deviation.
std::shared_ptr<const ModelDistanceIndex> model_index(Run& run) {
  if (!run.model_index) run.model_index = std::make_shared<const ModelDistanceIndex>(run.mesh, true);
  return run.model_index;
}

// The layers and their cuts, once (no programs).
std::expected<void, PlanJobError> layers_and_bevels(Run& run, const LayeringParams& params, bool first_round) {
  if (first_round) run.progress.start(PlanPhase::choosing_layers);
  LayeringParams p = params;
  p.on_round = [&](int done, int bound) { run.progress.step(PlanPhase::choosing_layers, done, bound); };
  auto t0 = Clock::now();
  p.model_index = model_index(run);
  auto layering = choose_layers(run.mesh, p);
  run.timing.layering += seconds_since(t0);
  if (!layering) return failed(PlanPhase::choosing_layers, layering.error());
  run.r.layering = std::move(*layering);

  if (first_round) run.progress.start(PlanPhase::planning_bevels);
  t0 = Clock::now();
  if (run.r.layering.plan) {  // the layering planned its layers with these parameters already
    // Taken, not copied (the 1M sphere's plan is ~30 MB): nothing reads the layering's after this.
    run.r.plan = std::move(*run.r.layering.plan);
    run.r.layering.plan.reset();
  } else {
    auto plan = plan_bevels(run.mesh, run.r.layering.layers, bevel_params(run.q.settings, run.q.settings.strategy));
    if (!plan) return failed(PlanPhase::planning_bevels, plan.error());
    run.r.plan = std::move(*plan);
  }
  run.timing.bevel += seconds_since(t0);
  return {};
}

std::string stl_header(const PlanJobRequest& q, const BevelPlan& plan) {
  // Never "solid…": readers would take the file for ASCII STL.
  std::string h = fmt::format("lamina stack: {} layers, {} cut, of {}", plan.layers.size(),
                              bevel_strategy_name(q.settings.strategy),
                              std::filesystem::path(q.model.file).filename().string());
  if (h.size() > 80) h.resize(80);
  return h;
}

// The chosen strategy's deviation and, when asked, the same layering cut the other two ways (the
// chosen strategy's plan is reused, not recomputed), then the stack as STL. Reports no progress:
// it runs beside the nesting, whose thread reports (plan_on_rack, adopt_measures).
PlanMeasures measure_plan(Run& run) {
  constexpr BevelStrategy kAll[] = {BevelStrategy::vertical, BevelStrategy::sloped, BevelStrategy::curved};
  const PlanSettings& settings = run.q.settings;
  std::vector<BevelStrategy> measured{settings.strategy};
  if (settings.compare_strategies) measured.assign(std::begin(kAll), std::end(kAll));
  PlanMeasures m;
  auto t0 = Clock::now();
  std::vector<StrategyDeviation> deviations;
  for (const BevelStrategy s : measured) {
    std::optional<BevelPlan> other;
    if (s != settings.strategy) {
      BevelParams geometry_only = bevel_params(settings, s);
      geometry_only.measure_surface_distance = false;  // its stack is measured as a whole below
      auto p = plan_bevels(run.mesh, run.r.layering.layers, geometry_only);
      if (!p) {
        m.deviations = failed(PlanPhase::measuring_deviation, p.error());
        return m;
      }
      other = std::move(*p);
    }
    const Mesh& reference = run.q.deviation_reference ? *run.q.deviation_reference : run.mesh;
    DeviationParams dp = deviation_params(settings);
    if (&reference == &run.mesh) dp.model_index = run.model_index;  // the layering's (layers_and_bevels)
    auto d = measure_deviation(reference, other ? *other : run.r.plan, dp);
    if (!d) {
      m.deviations = failed(PlanPhase::measuring_deviation, d.error());
      return m;
    }
    deviations.push_back({s, *d});
  }
  m.deviations = std::move(deviations);
  m.deviation_s = seconds_since(t0);
  // Not needed past the deviation (the stack is written without it; 1M sphere: 53 MB); a round
  // the rack sends back builds it again.
  run.model_index.reset();
  t0 = Clock::now();
  m.stack_stl = binary_stl_bytes(stack_mesh(run.r.plan), stl_header(run.q, run.r.plan));
  m.write_s = seconds_since(t0);
  return m;
}

// The plan's measures taken, their progress said in phase order (they ran beside the nesting
// when there were sheets to cut, and are done or nearly done by now).
std::expected<void, PlanJobError> adopt_measures(Run& run, PlanMeasures m) {
  run.progress.start(PlanPhase::measuring_deviation);
  if (!m.deviations) return std::unexpected(m.deviations.error());
  run.r.deviations = std::move(*m.deviations);
  const int n = static_cast<int>(run.r.deviations.size());
  for (int i = 1; i <= n; ++i) run.progress.step(PlanPhase::measuring_deviation, i, n);
  run.timing.deviation = m.deviation_s;
  run.progress.start(PlanPhase::writing_stack);
  run.r.stack_stl = std::move(m.stack_stl);
  run.timing.write = m.write_s;
  return {};
}

// Layers, bevels and (with cut settings) parts, nesting and programs, fitted to the rack (issue
// 17, item 5): a layer is only cut from sheets its outlines fit, and when the nesting runs out of
// a thickness, that thickness is limited to the layers its sheets held and the stack is laid out
// again, so the plan fits the rack or one error says which thickness runs out.
//
// The plan's measures (deviation, stack STL) need the plan alone: they run beside the nesting
// and programs on the thread pool (the 1M sphere's 2.6 MB program is one thread's work, and kept
// a core idle for 0.2 s). A round the rack sends back was measured for nothing; it is rare, and
// the measures of the plan that fits are the ones kept.
std::expected<void, PlanJobError> plan_on_rack(Run& run) {
  const PlanSettings& settings = run.q.settings;
  const std::optional<CamSettings>& cam = run.q.cam;
  std::vector<std::string> rack_warnings;  // said after the layering's, before the sheets'
  std::optional<Stock> stock;
  if (cam) stock = sized_stock(settings.stock, cam->machine, rack_warnings);
  LayeringParams params = layering_params(settings);
  params.supply = cam ? rack_supply(*stock, cam->machine.nest.margin_mm, cam->parts.kerf_mm)
                      : rack_supply(settings.stock, 0.0, 0.0);
  const std::string title = std::filesystem::path(run.q.model.file).filename().string();
  for (int round = 0;; ++round) {
    if (auto ok = layers_and_bevels(run, params, round == 0); !ok) return ok;
    if (!cam) {
      if (auto ok = adopt_measures(run, measure_plan(run)); !ok) return ok;
      break;
    }
    if (round == 0) run.progress.start(PlanPhase::nesting_and_programs);
    std::vector<SheetShortage> shortages;
    PlanMeasures measures;
    tbb::task_group beside;
    beside.run([&] { measures = measure_plan(run); });
    auto c = plan_cam(run.r.plan, *stock, *cam, title, &shortages,
                      [&](int done, int total) { run.progress.step(PlanPhase::nesting_and_programs, done, total); });
    beside.wait();
    if (c) {
      run.r.cam = std::move(*c);
      if (auto ok = adopt_measures(run, std::move(measures)); !ok) return ok;
      break;
    }
    if (c.error().code != ErrorCode::stock_exhausted || round + 1 >= kMaxRackRounds ||
        !lower_rack_limits(params.supply, shortages, run.r.layering, *stock, rack_warnings))
      return failed(PlanPhase::nesting_and_programs, c.error());
  }
  auto& w = run.warnings;
  w.insert(w.end(), run.r.layering.warnings.begin(), run.r.layering.warnings.end());
  add_tolerance_warnings(settings, run.r.plan, w);
  add_fit_warnings(settings, run.r.plan, w);
  w.insert(w.end(), rack_warnings.begin(), rack_warnings.end());
  if (run.r.cam) w.insert(w.end(), run.r.cam->warnings.begin(), run.r.cam->warnings.end());
  return {};
}

}  // namespace

const char* plan_phase_name(PlanPhase phase) {
  switch (phase) {
    case PlanPhase::checking: return "checking";
    case PlanPhase::choosing_layers: return "choosing layers";
    case PlanPhase::planning_bevels: return "planning bevels";
    case PlanPhase::nesting_and_programs: return "nesting and programs";
    case PlanPhase::measuring_deviation: return "measuring deviation";
    case PlanPhase::writing_stack: return "writing the stack";
  }
  return "?";
}

std::expected<PlanJobResult, PlanJobError> plan_job(const Mesh& mesh, const PlanJobRequest& request,
                                                    const PlanProgressFn& progress) {
  const auto t_start = Clock::now();
  if (auto ok = check_against_model(request.settings, mesh); !ok) return failed(PlanPhase::checking, ok.error());
  Run run{mesh, request, Progress(progress), {}, {}, request.warnings, {}};
  if (auto ok = plan_on_rack(run); !ok) return std::unexpected(ok.error());

  run.timing.read = request.model.read_s;
  run.timing.topology = request.model.topology_s;
  run.timing.total = seconds_since(t_start);
  run.r.report = make_plan_report(mesh, request, run.r);
  run.r.report.warnings = std::move(run.warnings);
  run.r.report.timing_s = run.timing;
  return std::move(run.r);
}

LayeringParams layering_params(const PlanSettings& s) {
  LayeringParams p;
  p.thicknesses_mm = s.thicknesses_mm;
  p.bond_mm = s.bond_mm;
  p.sub_slice_mm = s.sub_slice_mm;
  p.tolerance_mm = s.tolerance_mm;
  p.method = s.layering;
  p.fit.side = s.side;
  p.fit.strategy = s.strategy;
  p.fit.tilt_max_rad = s.tilt_max_rad;
  return p;
}

BevelParams bevel_params(const PlanSettings& s, BevelStrategy strategy) {
  BevelParams p;
  p.fit.side = s.side;
  p.fit.strategy = strategy;
  p.fit.tilt_max_rad = s.tilt_max_rad;
  p.sub_slice_mm = s.sub_slice_mm;
  p.tolerance_mm = s.tolerance_mm;
  return p;
}

DeviationParams deviation_params(const PlanSettings& s) {
  DeviationParams p;
  p.step_mm = s.deviation_step_mm;
  return p;
}

}  // namespace lamina
