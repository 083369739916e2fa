#include "plan_cam.hpp"

#include "lamina/core/sheet_svg.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <numbers>

namespace lamina::cli {
namespace {

using Json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
constexpr double kDeg = std::numbers::pi / 180.0;

// The material a sheet is cut as when neither --material nor the stock names one.
constexpr const char* kDefaultMaterial = "aluminium 6061-T6";

Error usage(std::string m) { return {ErrorCode::invalid_argument, std::move(m)}; }

}  // namespace

void add_cam_options(CLI::App& cmd, CamOptions& o) {
  cmd.add_option("--machine", o.machine_file, "Machine file: head, post, motion, cutting, jet, feed, nest (TOML; default config/machine.toml)");
  cmd.add_option("--materials", o.materials_file, "Materials file (TOML; default config/materials.toml)");
  cmd.add_option("--material", o.material, "Cut every sheet as this material (a name in the materials file)");
  cmd.add_option("--nest", o.nest, "Nesting: shape (true shape, libnest2d) or matrix (the paper's rows)")
      ->check(CLI::IsMember({"shape", "matrix"}));
  cmd.add_option("--post", o.post, "G-code dialect")->check(CLI::IsMember({"grblhal", "fanuc", "linuxcnc"}));
  cmd.add_option("--rtcp", o.rtcp, "The controller does RTCP (true: tip coordinates, G43.4) or not (false: pivot coordinates, G93)");
  cmd.add_option("--feed-model", o.feed_model, "Feed model: zeng-kim or limbachiya-patel (the paper's eq. 3)")
      ->check(CLI::IsMember({"zeng-kim", "limbachiya-patel"}));
  cmd.add_option("--quality", o.quality, "Zeng–Kim quality level 1 (separation) … 5 (finest)")->check(CLI::Range(1, 5));
  cmd.add_option("--kerf", o.kerf_mm, "Kerf width (mm)")->check(CLI::Range(0.0, 10.0));
  cmd.add_option("--spacing", o.spacing_mm, "Clear gap between parts on a sheet (mm)")->check(CLI::Range(0.0, 1000.0));
  cmd.add_option("--margin", o.margin_mm, "Clear band along the sheet's edges (mm)")->check(CLI::Range(0.0, 1000.0));
  cmd.add_option("--lead-in", o.lead_in_mm, "Lead-in length (mm)")->check(CLI::Range(0.0, 100.0));
  cmd.add_option("--lead-out", o.lead_out_mm, "Lead-out length (mm)")->check(CLI::Range(0.0, 100.0));
  cmd.add_option("--pierce-dwell", o.pierce_dwell_s, "Pierce dwell (s)")->check(CLI::Range(0.0, 600.0));
  cmd.add_option("--microjoints", o.microjoints, "Microjoints per outer outline (0: none)")->check(CLI::Range(0, 100));
  cmd.add_option("--microjoint-width", o.microjoint_width_mm, "Uncut width of a microjoint (mm)")->check(CLI::Range(0.01, 50.0));
  cmd.add_option("--dowels", o.dowels, "Registration dowel holes through every layer (0: none)")->check(CLI::Range(0, 64));
  cmd.add_option("--dowel-diameter", o.dowel_diameter_mm, "Dowel hole diameter (mm)")->check(CLI::Range(0.5, 100.0));
  cmd.add_option("--fill-holes", o.fill_holes, "Nest smaller parts inside the holes of larger ones (true/false)");
  cmd.add_flag("--no-programs", o.no_programs, "Stop after the stack: no nesting, programs or sheet drawings");
}

std::expected<CamSettings, Error> resolve_cam_settings(const CamOptions& o) {
  CamSettings s;
  const std::filesystem::path dir = default_config_dir();
  s.machine_source = o.machine_file.empty() ? (dir / "machine.toml").string() : o.machine_file;
  s.materials_source = o.materials_file.empty() ? (dir / "materials.toml").string() : o.materials_file;
  auto machine = read_machine_file(s.machine_source);
  if (!machine) return std::unexpected(machine.error());
  s.machine = std::move(*machine);
  auto materials = load_materials(s.materials_source);
  if (!materials) return std::unexpected(materials.error());
  s.materials = std::move(*materials);
  s.machine.cutting.jet = s.materials.jet;  // the pump and head are described with the materials

  MachineConfig& m = s.machine;
  if (o.nest) m.nest.method = *o.nest == "matrix" ? NestMethod::matrix : NestMethod::shape;
  if (o.post)
    m.post.dialect = *o.post == "fanuc" ? PostDialect::fanuc : *o.post == "linuxcnc" ? PostDialect::linuxcnc : PostDialect::grblhal;
  if (o.rtcp) m.head.rtcp = *o.rtcp;
  if (o.feed_model) m.cutting.feed.model = *o.feed_model == "limbachiya-patel" ? FeedModel::limbachiya_patel : FeedModel::zeng_kim;
  if (o.quality) m.cutting.feed.quality = *o.quality;
  if (o.kerf_mm) m.cutting.kerf_mm = *o.kerf_mm;
  if (o.spacing_mm) m.nest.spacing_mm = *o.spacing_mm;
  if (o.margin_mm) m.nest.margin_mm = *o.margin_mm;
  if (o.fill_holes) m.nest.fill_holes = *o.fill_holes;
  if (o.lead_in_mm) m.cutting.lead_in_mm = *o.lead_in_mm;
  if (o.lead_out_mm) m.cutting.lead_out_mm = *o.lead_out_mm;
  if (o.pierce_dwell_s) m.cutting.pierce_dwell_s = *o.pierce_dwell_s;
  if (o.microjoints) m.cutting.microjoints = *o.microjoints;
  if (o.microjoint_width_mm) m.cutting.microjoint_width_mm = *o.microjoint_width_mm;
  if (o.dowel_diameter_mm) m.cutting.dowel_diameter_mm = *o.dowel_diameter_mm;
  s.parts.kerf_mm = m.cutting.kerf_mm;
  s.parts.dowels.count = o.dowels.value_or(0);
  s.parts.dowels.diameter_mm = m.cutting.dowel_diameter_mm;
  if (o.material) {
    auto found = find_material(s.materials, *o.material);
    if (!found) return std::unexpected(usage("--material: " + found.error().message));
    s.material_override = *o.material;
  }
  if (m.post.dialect == PostDialect::grblhal && m.head.rtcp)
    return std::unexpected(usage("grblHAL has no RTCP (G43.4): use --rtcp false (pivot coordinates and G93), or "
                                 "--post fanuc / linuxcnc for a controller that keeps the tool tip"));
  // A pierce in the gap between two parts must not land in the neighbour.
  if (m.nest.spacing_mm < m.cutting.lead_in_mm + m.cutting.kerf_mm)
    return std::unexpected(usage(fmt::format(
        "spacing {} mm is less than lead-in {} mm + kerf {} mm: outer pierces would land in the neighbouring part",
        m.nest.spacing_mm, m.cutting.lead_in_mm, m.cutting.kerf_mm)));
  return s;
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
                                         const std::string& title, std::vector<SheetShortage>* shortages) {
  CamResult r;
  const MachineConfig& m = settings.machine;
  auto t0 = Clock::now();
  auto parts = make_parts(plan, settings.parts);
  if (!parts) return std::unexpected(parts.error());
  r.parts = std::move(*parts);
  r.timing.parts = seconds_since(t0);

  t0 = Clock::now();
  auto nest = nest_parts(r.parts, stock, m.nest, shortages);
  if (!nest) return std::unexpected(nest.error());
  r.timing.nest = seconds_since(t0);

  for (NestedSheet& sheet : nest->sheets) {
    SheetOutput out;
    out.material = !settings.material_override.empty() ? settings.material_override : sheet.material;
    if (out.material.empty()) {
      out.material = kDefaultMaterial;
      if (r.warnings.empty() || r.warnings.back().find("no material") == std::string::npos)
        r.warnings.push_back(fmt::format("sheets with no material are cut as {} (--material NAME to choose)", kDefaultMaterial));
    }
    sheet.material = out.material;  // what it is cut as, for the drawing's legend
    auto material = find_material(settings.materials, out.material);
    if (!material) return std::unexpected(Error{material.error().code, fmt::format("sheet {}: {}", sheet.index, material.error().message)});

    t0 = Clock::now();
    auto toolpath = plan_sheet_toolpath(plan, r.parts, sheet, *material, m.cutting);
    if (!toolpath) return std::unexpected(toolpath.error());
    r.timing.toolpath += seconds_since(t0);

    t0 = Clock::now();
    PostParams post = m.post;
    post.program_number = m.post.program_number + sheet.index - 1;
    post.title = fmt::format("{} sheet {} {}mm {}", title, sheet.index, sheet.thickness_mm, out.material);
    auto program = post_program(*toolpath, m.head, post);
    if (!program) return std::unexpected(Error{program.error().code, fmt::format("sheet {}: {}", sheet.index, program.error().message)});
    r.timing.post += seconds_since(t0);

    t0 = Clock::now();
    SheetSvgParams svg;
    svg.title = title;
    svg.estimated_time_s = toolpath->time.total_s;
    svg.dowel_diameter_mm = m.cutting.dowel_diameter_mm;
    out.svg = sheet_svg(plan, r.parts, sheet, *toolpath, svg);
    r.timing.svg += seconds_since(t0);

    out.program_name = fmt::format("sheet-{}.nc", sheet.index);
    out.svg_name = fmt::format("sheet-{}.svg", sheet.index);
    out.sheet = std::move(sheet);
    out.toolpath = std::move(*toolpath);
    out.program = std::move(*program);
    r.sheets.push_back(std::move(out));
  }
  return r;
}

Json sheets_json(const CamResult& r) {
  Json sheets = Json::array();
  for (const SheetOutput& s : r.sheets) {
    Json parts = Json::array();
    for (const Placement& pl : s.sheet.placements) {
      const Part& p = r.parts[static_cast<std::size_t>(pl.part)];
      parts.push_back({{"layer", p.layer},
                       {"island", p.island},
                       {"label", part_label(p)},
                       {"x_mm", pl.offset_mm.x()},
                       {"y_mm", pl.offset_mm.y()},
                       {"rotation_deg", pl.rotation_rad / kDeg},
                       {"inside", pl.host >= 0 ? Json(part_label(r.parts[static_cast<std::size_t>(
                                                     s.sheet.placements[static_cast<std::size_t>(pl.host)].part)]))
                                               : Json(nullptr)},
                       {"dowels", p.dowels_mm.size()}});
    }
    const CutTime& t = s.toolpath.time;
    const PostedProgram& prog = s.program;
    sheets.push_back(
        {{"index", s.sheet.index},
         {"thickness_mm", s.sheet.thickness_mm},
         {"width_mm", s.sheet.width_mm},
         {"length_mm", s.sheet.length_mm},
         {"material", s.material},
         {"program", s.program_name},
         {"svg", s.svg_name},
         {"estimated_time_s", t.total_s},
         {"time_s", {{"cutting", t.cutting_s}, {"rapids", t.rapid_s}, {"pierces", t.pierce_s}}},
         {"cut_length_mm", t.cut_length_mm},
         {"pierces", t.pierces},
         {"contours", s.toolpath.contours.size()},
         {"microjoints", s.toolpath.microjoints.size()},
         {"utilisation", s.sheet.utilisation},
         {"program_bytes", prog.text.size()},
         {"program_lines", prog.lines},
         {"five_axis_moves", prog.five_axis_moves},
         {"bytes_per_five_axis_move",
          prog.five_axis_moves ? Json(static_cast<double>(prog.five_axis_bytes) / prog.five_axis_moves) : Json(nullptr)},
         {"parts", std::move(parts)}});
  }
  return sheets;
}

Json cam_json(const CamSettings& s, const CamResult& r) {
  const MachineConfig& m = s.machine;
  return {{"machine_file", s.machine_source},
          {"materials_file", s.materials_source},
          {"nest", nest_method_name(m.nest.method)},
          {"spacing_mm", m.nest.spacing_mm},
          {"margin_mm", m.nest.margin_mm},
          {"fill_holes", m.nest.fill_holes},
          {"post", post_dialect_name(m.post.dialect)},
          {"rtcp", m.head.rtcp},
          {"feed_model", feed_model_name(m.cutting.feed.model)},
          {"quality", m.cutting.feed.quality},
          {"kerf_mm", m.cutting.kerf_mm},
          {"lead_in_mm", m.cutting.lead_in_mm},
          {"lead_out_mm", m.cutting.lead_out_mm},
          {"pierce_dwell_s", m.cutting.pierce_dwell_s},
          {"microjoints", m.cutting.microjoints},
          {"microjoint_width_mm", m.cutting.microjoint_width_mm},
          {"dowels", s.parts.dowels.count},
          {"dowel_diameter_mm", s.parts.dowels.diameter_mm},
          {"parts", r.parts.size()},
          {"timing_s",
           {{"parts", r.timing.parts}, {"nest", r.timing.nest}, {"toolpath", r.timing.toolpath}, {"post", r.timing.post},
            {"svg", r.timing.svg}}}};
}

void print_sheet_table(std::FILE* out, const Json& report) {
  if (!report.contains("sheets")) return;
  fmt::print(out, "{:>5} {:>6} {:>11} {:>5} {:>6} {:>7} {:>9} {:>8} {:>9} {:>7}  {}\n", "sheet", "t mm", "size mm",
             "parts", "util %", "pierces", "cut m", "time", "NC bytes", "B/5ax", "material");
  double total = 0.0;
  for (const auto& s : report.at("sheets")) {
    const double t = s.at("estimated_time_s").get<double>();
    total += t;
    const auto& b = s.at("bytes_per_five_axis_move");
    fmt::print(out, "{:>5} {:>6.3g} {:>11} {:>5} {:>6.1f} {:>7} {:>9.2f} {:>5}:{:02} {:>9} {:>7}  {}\n",
               s.at("index").get<int>(), s.at("thickness_mm").get<double>(),
               fmt::format("{:g}x{:g}", s.at("length_mm").get<double>(), s.at("width_mm").get<double>()),
               s.at("parts").size(), 100.0 * s.at("utilisation").get<double>(), s.at("pierces").get<int>(),
               s.at("cut_length_mm").get<double>() / 1000.0, static_cast<int>(t) / 60, static_cast<int>(t) % 60,
               s.at("program_bytes").get<std::size_t>(), b.is_number() ? fmt::format("{:.1f}", b.get<double>()) : "-",
               s.at("material").get<std::string>());
  }
  const auto& c = report.at("cam");
  fmt::print(out, "  {} sheets, {} parts, estimated cutting {}:{:02}:{:02} (h:m:s); {} nesting, {} post{}\n",
             report.at("sheets").size(), c.at("parts").get<int>(), static_cast<int>(total) / 3600,
             static_cast<int>(total) / 60 % 60, static_cast<int>(total) % 60, c.at("nest").get<std::string>(),
             c.at("post").get<std::string>(), c.at("rtcp").get<bool>() ? " (RTCP)" : " (pivot coordinates, G93)");
  const auto& t = c.at("timing_s");
  fmt::print(out, "  timing: parts {:.3f} s, nest {:.3f} s, toolpaths {:.3f} s, post {:.3f} s, svg {:.3f} s\n\n",
             t.at("parts").get<double>(), t.at("nest").get<double>(), t.at("toolpath").get<double>(),
             t.at("post").get<double>(), t.at("svg").get<double>());
}

}  // namespace lamina::cli
