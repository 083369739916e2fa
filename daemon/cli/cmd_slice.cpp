// lamina slice MODEL (--step H | --at z1,z2,… | --at-fraction f1,f2,…) [--json FILE]
// Heights are in the build frame, from 0 at the bottom of the model.
#include "commands.hpp"
#include "json_output.hpp"
#include "model_options.hpp"

#include "lamina/core/slice.hpp"

#include <fmt/format.h>

#include <chrono>
#include <expected>
#include <memory>
#include <set>

namespace lamina::cli {
namespace {

struct SliceOptions {
  ModelOptions model;
  double step_mm = 0.0;
  std::vector<double> at_mm;
  std::vector<double> at_fraction;
  std::string json_path;
  double gap_mm = 1.0;
  bool serial = false;
  bool all_rows = false;
};

void print_table(const Mesh& mesh, const std::vector<Slice>& slices, bool all_rows) {
  fmt::print("{:>10} {:>6} {:>6} {:>8} {:>9} {:>14}  {}\n", "z mm", "outer", "holes", "vectors", "surfaces",
             "net area mm2", "notes");
  const std::size_t n = slices.size();
  const bool elide = !all_rows && n > 40;
  for (std::size_t i = 0; i < n; ++i) {
    if (elide && i == 20) fmt::print("{:>10}   ({} more rows: --all-rows or --json)\n", "...", n - 25);
    if (elide && i >= 20 && i < n - 5) continue;
    const Slice& s = slices[i];
    std::size_t vectors = 0;
    std::set<std::int32_t> surfaces;  // how many CAD-like surfaces this section crosses
    for (const Loop& l : s.loops) {
      vectors += l.size();
      for (const std::int32_t f : l.facets)
        if (f >= 0) surfaces.insert(mesh.surface_id[static_cast<std::size_t>(f)]);
    }
    std::string notes;
    if (!s.open_chains.empty()) notes += fmt::format("{} open chain(s); ", s.open_chains.size());
    for (const std::string& w : s.warnings) notes += w + "; ";
    fmt::print("{:>10.4f} {:>6} {:>6} {:>8} {:>9} {:>14.6g}  {}\n", s.z_mm, s.outer_count(), s.hole_count(), vectors,
               surfaces.size(), s.net_area_mm2(), notes);
  }
}

// The heights to slice at, or the exit code after the error was said.
std::expected<std::vector<double>, int> slice_heights(const SliceOptions& o, bool by_step, double height) {
  std::vector<double> zs;
  if (by_step) {
    // Bounded by the model: the plane count is known only once its height is.
    const double planes = planes_by_step(height, o.step_mm);
    if (planes > static_cast<double>(kMaxSlicePlanes)) {
      fmt::print(stderr,
                 "error [invalid_argument]: --step {} mm gives {:.3g} planes over the model's {:.3f} mm, more than "
                 "{}: give --step {:.3g} mm or more\n",
                 o.step_mm, planes, height, kMaxSlicePlanes, height / static_cast<double>(kMaxSlicePlanes));
      return std::unexpected(2);
    }
    zs = heights_by_step(height, o.step_mm);
  }
  for (double z : o.at_mm) {
    if (z < 0.0 || z > height) fmt::print(stderr, "warning: z={} mm is outside the model (0 … {:.4f} mm)\n", z, height);
    zs.push_back(z);
  }
  for (double f : o.at_fraction) zs.push_back(f * height);
  return zs;
}

int run_slice(const SliceOptions& o, bool by_step) {
  auto model = load_model(o.model);
  if (!model) {
    fmt::print(stderr, "error [{}]: {}\n", error_code_name(model.error().code), model.error().message);
    return 1;
  }
  for (const Defect& d : model->mesh.defects)
    if (d.severity == Severity::error || d.severity == Severity::warning)
      fmt::print(stderr, "warning: {}: {}\n", d.code, d.message);
  auto zs = slice_heights(o, by_step, model->mesh.summary.bbox_max_mm.z());
  if (!zs) return zs.error();

  SliceParams params;
  params.gap_close_mm = o.gap_mm;
  params.parallel = !o.serial;
  const auto t0 = std::chrono::steady_clock::now();
  auto slices = slice_mesh(model->mesh, *zs, params);
  const double slice_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!slices) {
    fmt::print(stderr, "error [{}]: {}\n", error_code_name(slices.error().code), slices.error().message);
    return 1;
  }
  print_table(model->mesh, *slices, o.all_rows);
  fmt::print("timing: read {:.3f} s, topology {:.3f} s, slice {:.3f} s ({} slices, {} triangles)\n", model->read_s,
             model->topology_s, slice_s, slices->size(), model->mesh.summary.triangles);
  if (!o.json_path.empty()) {
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(o.json_path.c_str(), "w"), &std::fclose);
    if (!f) {
      fmt::print(stderr, "error [io_error]: cannot write {}\n", o.json_path);
      return 1;
    }
    const nlohmann::json timing{{"read", model->read_s}, {"topology", model->topology_s}, {"slice", slice_s}};
    write_slice_report(f.get(), o.model, *model, *slices, timing);
  }
  return 0;
}

}  // namespace

void add_slice_command(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<SliceOptions>();
  CLI::App* cmd = app.add_subcommand("slice", "Cut the model by horizontal planes into contour loops");
  add_model_options(*cmd, o->model);
  auto* step = cmd->add_option("--step", o->step_mm, "Slice every H mm (planes at H/2, 3H/2, …)")->check(CLI::PositiveNumber);
  auto* at = cmd->add_option("--at", o->at_mm, "Slice at these heights (mm from the bottom)")->delimiter(',');
  auto* frac = cmd->add_option("--at-fraction", o->at_fraction, "Slice at these fractions of the height")
                   ->delimiter(',')
                   ->check(CLI::Range(0.0, 1.0));
  step->excludes(at)->excludes(frac);
  at->excludes(frac);
  cmd->add_option("--json", o->json_path, "Write mesh, slices (every contour vector) and timings as JSON");
  cmd->add_option("--gap", o->gap_mm, "Close open chains whose ends are at most this far apart (mm; 0: never)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("--serial", o->serial, "Slice on one thread");
  cmd->add_flag("--all-rows", o->all_rows, "Print every slice in the table");
  cmd->callback([o, step, at, frac, &exit_code] {
    if (step->count() + at->count() + frac->count() == 0) {
      fmt::print(stderr, "error [invalid_argument]: give one of --step, --at or --at-fraction\n");
      exit_code = 2;
      return;
    }
    exit_code = run_slice(*o, step->count() > 0);
  });
}

}  // namespace lamina::cli
