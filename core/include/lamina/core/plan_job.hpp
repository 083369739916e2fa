#pragma once
// One entry point for a whole plan (issue 18): a mesh and validated settings in; the layers, the
// bevel cuts, the deviation of the same layering cut three ways, the stack as STL bytes, and —
// with cut settings — the parts nested on the rack's sheets with one G-code program and one SVG
// drawing per sheet; and the typed report (plan_report.hpp) that every front end reads. Files
// are read and written by the callers: `lamina plan` (which is also laminad's planner child) and,
// later, the web console.
#include "lamina/core/bevel.hpp"
#include "lamina/core/cam_settings.hpp"
#include "lamina/core/deviation.hpp"
#include "lamina/core/error.hpp"
#include "lamina/core/layering.hpp"
#include "lamina/core/mesh.hpp"
#include "lamina/core/nest.hpp"
#include "lamina/core/parts.hpp"
#include "lamina/core/plan_report.hpp"
#include "lamina/core/post.hpp"
#include "lamina/core/stock.hpp"
#include "lamina/core/toolpath.hpp"

#include <expected>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace lamina {

// The plan's own settings, validated, in core units (mm, rad).
struct PlanSettings {
  Stock stock;                        // the rack, or sheets of unknown size
  std::string stock_source;           // "default", "--stock", or the stock file's path
  std::vector<double> thicknesses_mm; // distinct, ascending
  double bond_mm = 0.0;
  double sub_slice_mm = 0.5;
  double tolerance_mm = 0.2;
  double tilt_max_rad = 0.0;
  double tilt_max_deg = 0.0;          // as given, for the report (tilt_max_rad is what is used)
  double deviation_step_mm = 0.1;
  // The deviation of the two strategies not chosen, on the same layering: worth seeing while
  // choosing one, and it doubles a plan's time (issue 22), so only when asked.
  bool compare_strategies = false;
  CutSide side = CutSide::outside;
  BevelStrategy strategy = BevelStrategy::curved;
  LayeringMethod layering = LayeringMethod::optimal;
  std::vector<std::string> warnings;  // settings that are allowed but doubtful
};

LayeringParams layering_params(const PlanSettings& s);
BevelParams bevel_params(const PlanSettings& s, BevelStrategy strategy);
DeviationParams deviation_params(const PlanSettings& s);

// What the report says of the model as its caller read it.
struct ModelEcho {
  std::string file;    // as given
  std::string format;  // the reader's name of the format
  std::string units = "mm", axis = "z";
  std::vector<double> direction;  // empty: the axis
  double read_s = 0.0, topology_s = 0.0;
  std::optional<ReportCad> cad;  // what a STEP / IGES file told the plan (the report's model.cad)
  std::optional<ReportDeviationReference> deviation_reference;  // with PlanJobRequest::deviation_reference
};

struct PlanJobRequest {
  PlanSettings settings;
  std::optional<CamSettings> cam;     // none: stop after the stack (no nesting, programs, drawings)
  ModelEcho model;
  std::vector<std::string> warnings;  // the caller's, about the model; first in the report
  // The surface the report's deviation is measured against, in the planned mesh's frame: a finer
  // tessellation of a B-rep (the planned one is up to its chord off the CAD surface). Null: the
  // planned mesh. The layering's and bevels' own estimates always use the planned mesh.
  std::shared_ptr<const Mesh> deviation_reference;
};

// The phases of plan_job, in the order they run. Errors say in which one they arose.
enum class PlanPhase { checking, choosing_layers, planning_bevels, nesting_and_programs, measuring_deviation, writing_stack };
const char* plan_phase_name(PlanPhase phase);  // "choosing layers", …

// A phase starts (done = total = 0), then its steps finish (done of total; total may grow when a
// phase learns it needs more, as the rack's rounds do). One call at a time, on the caller's thread.
struct PlanStep {
  PlanPhase phase = PlanPhase::checking;
  int done = 0;
  int total = 0;
};
using PlanProgressFn = std::function<void(const PlanStep&)>;

struct SheetOutput {
  NestedSheet sheet;
  SheetToolpath toolpath;
  PostedProgram program;
  std::string svg;
  std::string program_name, svg_name;  // sheet-<n>.nc, sheet-<n>.svg
  std::string material;
};

struct CamTimings {  // seconds
  double parts = 0.0, nest = 0.0, toolpath = 0.0, post = 0.0, svg = 0.0;
};

struct CamResult {
  std::vector<Part> parts;
  std::vector<SheetOutput> sheets;
  CamTimings timing;
  std::vector<std::string> warnings;
};

struct StrategyDeviation {
  BevelStrategy strategy = BevelStrategy::curved;
  Deviation deviation;
};

struct PlanJobResult {
  Layering layering;
  BevelPlan plan;                             // the chosen strategy's
  // The chosen strategy's, and with compare_strategies the same layering cut the other ways too
  // (vertical, sloped, curved order).
  std::vector<StrategyDeviation> deviations;
  std::optional<CamResult> cam;
  std::string stack_stl;                      // binary STL of the stack
  std::string as_cut_stl;                     // binary STL of the parts as cut (lamina plan --as-cut; empty without)
  // report.json. timing_s.write and .total cover plan_job's part; the caller adds its own
  // writing and reading to them.
  PlanReport report;
};

struct PlanJobError {
  PlanPhase phase = PlanPhase::checking;
  Error error;
};

std::expected<PlanJobResult, PlanJobError> plan_job(const Mesh& mesh, const PlanJobRequest& request,
                                                    const PlanProgressFn& progress = {});

// ---- the pieces of plan_job, public for their tests ----

// The stock with sizes filled in for sheets known by thickness only (the machine's default size).
Stock sized_stock(const Stock& stock, const MachineConfig& machine, std::vector<std::string>& warnings);

// Parts, nesting, one toolpath, program and drawing per sheet. When the rack runs out of sheets
// (ErrorCode::stock_exhausted), `shortages` (if given) says which thicknesses and how many of
// their layers were placed whole. `on_step(done, total)` after each part the nesting places and
// then each sheet's program (the total grows by the sheets once the nesting knows them); one call
// at a time.
std::expected<CamResult, Error> plan_cam(const BevelPlan& plan, const Stock& stock, const CamSettings& settings,
                                         const std::string& title, std::vector<SheetShortage>* shortages = nullptr,
                                         const std::function<void(int, int)>& on_step = {});

// The rack as the layering sees it (issue 17, item 5): one entry per thickness whose sheets have
// a known size, the room a layer's outline has on each (the sheet less its margin on both sides
// and the kerf the part's footprint adds around the outline). Counts not limited yet.
std::vector<ThicknessSupply> rack_supply(const Stock& stock, double margin_mm, double kerf_mm);

// Lowers the count of every thickness the nesting ran out of to the layers it placed whole (and
// at least one below what the layering used, so every round changes the plan), and says so in
// `warnings`. False when a shortage names a thickness the layering did not use.
bool lower_rack_limits(std::vector<ThicknessSupply>& supply, const std::vector<SheetShortage>& shortages,
                       const Layering& layering, const Stock& stock, std::vector<std::string>& warnings);

// The report of a finished plan, all but timing_s (plan_job fills that with what it measured).
PlanReport make_plan_report(const Mesh& mesh, const PlanJobRequest& request, const PlanJobResult& result);

}  // namespace lamina
