// lamina plan MODEL --out DIR: the edge of plan_job (lamina/core/plan_job.hpp): options and files
// in, DIR/stack.stl, the sheets' programs and drawings and DIR/report.json out, tables printed.
#include "as_cut_files.hpp"
#include "commands.hpp"
#include "malloc_tuning.hpp"
#include "plan_cam.hpp"
#include "plan_output.hpp"
#include "plan_options.hpp"
#include "plan_progress.hpp"
#include "plan_report.hpp"

#include "lamina/core/elapsed.hpp"
#include "lamina/core/as_cut.hpp"
#include "lamina/core/plan_job.hpp"
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


int report_error(const Error& e, int exit_code = 1) {
  fmt::print(stderr, "error [{}]: {}\n", error_code_name(e.code), e.message);
  return exit_code;
}

// Settings the model makes absurd (exit 2, like every usage error) are found while checking the
// request and choosing the layers; a later stage's invalid_argument is the data's (exit 1).
int exit_code_of(const Error& e) { return e.code == ErrorCode::invalid_argument ? 2 : 1; }
int exit_code_of(const PlanJobError& e) {
  return e.phase == PlanPhase::checking || e.phase == PlanPhase::choosing_layers ? exit_code_of(e.error) : 1;
}

// What the report says before planning: the settings' doubts, the mesh's defects, a size that
// suggests the wrong units, shells that overlap.
std::vector<std::string> model_warnings(const PlanSettings& settings, const Mesh& mesh, const PlanOptions& o,
                                        const std::optional<CamSettings>& cam) {
  std::vector<std::string> w = settings.warnings;
  for (const Defect& d : mesh.defects)
    if (d.severity == Severity::error || d.severity == Severity::warning) w.push_back(d.code + ": " + d.message);
  const double sheet_longest_mm = cam ? std::max(cam->machine.sheet_width_mm, cam->machine.sheet_length_mm) : 2500.0;
  if (auto note = implausible_size(mesh, o.model, sheet_longest_mm)) w.push_back(*note);
  if (auto note = overlapping_shells(mesh)) w.push_back(*note);
  return w;
}

// Sheet files (and an as-cut mesh) of an earlier run that this run does not rewrite must not be
// mistaken for its own.
bool is_sheet_file(const std::string& name) {
  return (name.starts_with("sheet-") && (name.ends_with(".nc") || name.ends_with(".svg"))) || name == "as-cut.stl";
}

// Every file is made in memory first: a failure anywhere writes nothing. Returns 0 or 1.
int write_plan(const PlanOptions& o, PlanJobResult& r, PlanProgress& progress, Clock::time_point t_start) {
  if (r.cam) progress.phase("writing sheets");
  const auto t0 = Clock::now();
  auto out = StagedOutput::open(o.out_dir);
  if (!out) return report_error(out.error());
  if (auto w = out->stage("stack.stl", r.stack_stl); !w) return report_error(w.error());
  if (!r.as_cut_stl.empty())
    if (auto w = out->stage("as-cut.stl", r.as_cut_stl); !w) return report_error(w.error());
  if (r.cam)
    for (const SheetOutput& s : r.cam->sheets)
      for (const auto& [name, bytes] : {std::pair{s.program_name, &s.program.text}, std::pair{s.svg_name, &s.svg}})
        if (auto w = out->stage(name, *bytes); !w) return report_error(w.error());
  r.report.timing_s.write += seconds_since(t0);
  r.report.timing_s.total = seconds_since(t_start);
  if (auto w = out->stage("report.json", plan_report_json(r.report)); !w) return report_error(w.error());
  if (auto w = out->publish(is_sheet_file); !w) return report_error(w.error());
  progress.done();
  return 0;
}

// --as-cut: the sheets as the machine cut them, measured against the model beside the plan.
int add_as_cut(const std::string& dir, const Mesh& mesh, PlanJobResult& r) {
  if (!r.cam) return report_error({ErrorCode::invalid_argument, "--as-cut needs the sheets' programs (leave out --no-programs)"}, 2);
  auto cut = read_cut_sheets(dir, *r.cam);
  if (!cut) return report_error(cut.error());
  std::vector<NestedSheet> sheets;
  for (const SheetOutput& s : r.cam->sheets) sheets.push_back(s.sheet);
  auto d = measure_as_cut(mesh, r.plan, r.cam->parts, sheets, *cut, AsCutParams{});
  if (!d) return report_error(d.error());
  r.report.as_cut = report_as_cut(*d, dir);
  r.as_cut_stl = binary_stl_bytes(as_cut_mesh(d->slabs), "lamina as cut, measured from " + fs::path(dir).filename().string());
  return 0;
}

void print_plan(const PlanOptions& o, const PlanJobResult& r) {
  if (o.json) {
    fmt::print("{}", plan_report_json(r.report));
  } else {
    const fs::path dir(o.out_dir);
    print_plan_tables(stdout, r.report, o.all_rows);
    fmt::print("\n");
    print_sheet_table(stdout, r.report);
    if (r.report.as_cut) {
      fmt::print("\n");
      print_as_cut_table(stdout, *r.report.as_cut, o.all_rows);
    }
    fmt::print("wrote {} ({} bytes), {}", (dir / "stack.stl").string(), r.stack_stl.size(), (dir / "report.json").string());
    if (!r.as_cut_stl.empty()) fmt::print(", {} (the parts as cut)", (dir / "as-cut.stl").string());
    if (r.cam && !r.cam->sheets.empty())
      fmt::print(", and {} program(s) + drawing(s) {}/sheet-<n>.nc, .svg", r.cam->sheets.size(), dir.string());
    fmt::print("\n");
  }
  std::fflush(stdout);  // warnings after the tables they refer to, even when both go to one pipe
  for (const std::string& w : r.report.warnings) fmt::print(stderr, "warning: {}\n", w);
}

int run_plan(const PlanOptions& o, const CamOptions& cam_options) {
  const auto t_start = Clock::now();
  PlanJobRequest request;
  auto settings = resolve_plan_settings(o);
  if (!settings) return report_error(settings.error(), exit_code_of(settings.error()));
  request.settings = std::move(*settings);
  if (!cam_options.no_programs) {
    auto c = resolve_cam_settings(cam_options);
    if (!c) return report_error(c.error(), exit_code_of(c.error()));
    request.cam = std::move(*c);
  }
  // A typo in --out must not cost a full plan; nothing is created before the plan is whole.
  if (auto ok = check_out_dir(o.out_dir); !ok) return report_error(ok.error());
  ModelOptions model_options = o.model;
  if (!model_options.chord_tolerance_mm) model_options.chord_tolerance_mm = o.tolerance_mm / 10;
  // A B-rep file is read twice: once to plan, once finer for the deviation's reference.
  const std::optional<ModelOptions> reference_options = deviation_reference_options(o, model_options);
  PlanProgress progress(o.progress_fd, (request.cam ? 7 : 5) + (reference_options ? 1 : 0));

  progress.phase("reading the model");
  auto model = load_model(model_options);
  if (!model) return report_error(model.error());
  const Mesh& mesh = model->mesh;
  if (!mesh.usable())
    return report_error({ErrorCode::invalid_argument,
                         fmt::format("{} is not usable as a solid (see lamina check {})", o.model.path, o.model.path)});
  request.model = {o.model.path, model->format, o.model.units, o.model.axis, o.model.direction, model->read_s,
                   model->topology_s, cad_report(*model, model_options), std::nullopt};
  if (reference_options) {
    progress.phase("reading the deviation's reference");
    auto reference = load_reference(*reference_options, mesh);
    if (!reference) return report_error(reference.error());
    request.deviation_reference = std::move(reference->mesh);
    request.model.deviation_reference = std::move(reference->echo);
  }
  request.warnings = model_warnings(request.settings, mesh, o, request.cam);

  auto r = plan_job(mesh, request, [&](const PlanStep& step) {
    if (step.done == 0 && step.total == 0) {
      if (gives_back_freed_pages_before(step.phase)) give_back_freed_pages();
      progress.phase(plan_phase_name(step.phase));
    }
    else
      progress.within(plan_phase_name(step.phase), step.done, step.total);
  });
  if (!r) return report_error(r.error().error, exit_code_of(r.error()));
  if (!o.as_cut_dir.empty())
    if (int code = add_as_cut(o.as_cut_dir, mesh, *r)) return code;
  if (int code = write_plan(o, *r, progress, t_start)) return code;
  print_plan(o, *r);
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
