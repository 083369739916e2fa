// The cut-program stage of a plan (issue 4): parts, nesting on the stock's sheets, one toolpath,
// G-code program and SVG drawing per sheet.
#include "lamina/core/elapsed.hpp"
#include "lamina/core/plan_job.hpp"
#include "lamina/core/sheet_svg.hpp"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <mutex>
#include <optional>

namespace lamina {
namespace {

using Clock = std::chrono::steady_clock;

// The material a sheet is cut as when neither --material nor the stock names one.
constexpr const char* kDefaultMaterial = "aluminium 6061-T6";

Error on_sheet_error(const NestedSheet& sheet, const Error& e) {
  return Error{e.code, fmt::format("sheet {}: {}", sheet.index, e.message)};
}

// The material a sheet is cut as; says once when the default is taken.
std::string material_of(const NestedSheet& sheet, const CamSettings& settings, std::vector<std::string>& warnings) {
  std::string material = !settings.material_override.empty() ? settings.material_override : sheet.material;
  if (!material.empty()) return material;
  if (warnings.empty() || warnings.back().find("no material") == std::string::npos)
    warnings.push_back(fmt::format("sheets with no material are cut as {} (--material NAME to choose)", kDefaultMaterial));
  return kDefaultMaterial;
}

// What cutting one sheet says and how long its steps took (the sheets are cut side by side).
struct SheetLog {
  std::vector<std::string> warnings;
  CamTimings timing;
};

// One sheet's toolpath, program and drawing.
std::expected<SheetOutput, Error> cut_sheet(const BevelPlan& plan, const std::vector<Part>& parts, NestedSheet sheet,
                                            const CamSettings& settings, const std::string& title, SheetLog& r) {
  const MachineConfig& m = settings.machine;
  SheetOutput out;
  out.material = material_of(sheet, settings, r.warnings);
  sheet.material = out.material;  // what it is cut as, for the drawing's legend
  auto material = find_material(settings.materials, out.material);
  if (!material) return std::unexpected(on_sheet_error(sheet, material.error()));

  auto t0 = Clock::now();
  auto toolpath = plan_sheet_toolpath(plan, parts, sheet, *material, m.cutting);
  if (!toolpath) return std::unexpected(toolpath.error());
  r.timing.toolpath += seconds_since(t0);

  t0 = Clock::now();
  PostParams post = m.post;
  post.program_number = m.post.program_number + sheet.index - 1;
  post.title = fmt::format("{} sheet {} {}mm {}", title, sheet.index, sheet.thickness_mm, out.material);
  auto program = post_program(*toolpath, m.head, post);
  if (!program) return std::unexpected(on_sheet_error(sheet, program.error()));
  r.timing.post += seconds_since(t0);

  t0 = Clock::now();
  SheetSvgParams svg;
  svg.title = title;
  svg.estimated_time_s = toolpath->time.total_s;
  svg.dowel_diameter_mm = m.cutting.dowel_diameter_mm;
  out.svg = sheet_svg(plan, parts, sheet, *toolpath, svg);
  r.timing.svg += seconds_since(t0);

  out.program_name = fmt::format("sheet-{}.nc", sheet.index);
  out.svg_name = fmt::format("sheet-{}.svg", sheet.index);
  out.sheet = std::move(sheet);
  out.toolpath = std::move(*toolpath);
  out.program = std::move(*program);
  return out;
}

}  // namespace

std::expected<Material, Error> find_material(const MaterialsConfig& config, std::string_view name) {
  if (auto it = config.materials.find(name); it != config.materials.end()) return it->second;
  std::string known;
  for (const auto& [n, m] : config.materials) known += fmt::format("{}'{}'", known.empty() ? "" : ", ", n);
  return std::unexpected(
      Error{ErrorCode::invalid_argument, fmt::format("unknown material '{}' (known: {})", name, known)});
}

Stock sized_stock(const Stock& stock, const MachineConfig& machine, std::vector<std::string>& warnings) {
  Stock out = stock;
  bool filled = false;
  for (SheetStock& s : out.sheets)
    if (s.width_mm <= 0.0 || s.length_mm <= 0.0) {
      s.width_mm = machine.sheet_width_mm;
      s.length_mm = machine.sheet_length_mm;
      filled = true;
    }
  if (filled)
    warnings.push_back(fmt::format("sheets given by thickness only are taken as {} x {} mm (machine file [nest]); give "
                                   "sizes and counts with --stock-file",
                                   machine.sheet_width_mm, machine.sheet_length_mm));
  return out;
}

std::expected<CamResult, Error> plan_cam(const BevelPlan& plan, const Stock& stock, const CamSettings& settings,
                                         const std::string& title, std::vector<SheetShortage>* shortages,
                                         const std::function<void(int, int)>& on_step) {
  CamResult r;
  auto t0 = Clock::now();
  auto parts = make_parts(plan, settings.parts);
  if (!parts) return std::unexpected(parts.error());
  r.parts = std::move(*parts);
  r.timing.parts = seconds_since(t0);

  // The steps: each part placed, then each sheet cut. The Menger sponge's 399 parts nested for
  // over a minute with the bar standing still (issue 22); the sheets are not known until the
  // nesting ends, so the total counts one until then.
  std::mutex progress;
  int done = 0, total = static_cast<int>(r.parts.size()) + 1;
  bool nesting = true;
  auto step = [&] {
    const std::lock_guard lock(progress);
    ++done;
    if (nesting) total = std::max(total, done + 1);  // a part placed again after a sheet kind ran out
    if (on_step) on_step(done, total);
  };
  t0 = Clock::now();
  NestParams nest_params = settings.machine.nest;
  nest_params.on_placed = step;
  auto nest = nest_parts(r.parts, stock, nest_params, shortages);
  if (!nest) return std::unexpected(nest.error());
  r.timing.nest = seconds_since(t0);

  // The sheets side by side (each its own toolpath, program and drawing; the sphere's four took
  // 0.45 s one after the other), then taken in sheet order: the first failing sheet's error, the
  // warnings as one after the other would say them (each once), the steps' times summed.
  const std::size_t sheet_count = nest->sheets.size();
  std::vector<std::optional<std::expected<SheetOutput, Error>>> outs(sheet_count);
  std::vector<SheetLog> logs(sheet_count);
  nesting = false;
  total = done + static_cast<int>(sheet_count);
  tbb::parallel_for(std::size_t{0}, sheet_count, [&](std::size_t i) {
    outs[i] = cut_sheet(plan, r.parts, std::move(nest->sheets[i]), settings, title, logs[i]);
    step();
  });
  for (std::size_t i = 0; i < sheet_count; ++i) {
    if (!*outs[i]) return std::unexpected(outs[i]->error());
    r.sheets.push_back(std::move(**outs[i]));
    for (std::string& w : logs[i].warnings)
      if (std::find(r.warnings.begin(), r.warnings.end(), w) == r.warnings.end()) r.warnings.push_back(std::move(w));
    r.timing.toolpath += logs[i].timing.toolpath;
    r.timing.post += logs[i].timing.post;
    r.timing.svg += logs[i].timing.svg;
  }
  return r;
}

}  // namespace lamina
