#include "plan_cam.hpp"

#include "kerf_files.hpp"
#include "toml_file.hpp"


#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <numbers>

namespace lamina::cli {
namespace {

Error usage(std::string m) { return {ErrorCode::invalid_argument, std::move(m)}; }

// The kerf calibrations for --jet-compensation: read when there are some. auto without any is
// today's programs; taper or full without the file, or a --kerf-file that is not there, is an error.
std::expected<void, Error> resolve_jet_compensation(const CamOptions& o, CamSettings& s) {
  JetCompensation& jc = s.machine.cutting.jet_compensation;
  jc.mode = o.jet_compensation ? jet_compensation_modes().parse(*o.jet_compensation).value() : JetCompensationMode::automatic;
  jc.tilt_max_rad = std::min(-s.machine.head.a_min_rad, s.machine.head.a_max_rad);
  if (o.corner_error_mm) jc.corners.error_mm = *o.corner_error_mm;
  if (o.inside_corners) jc.corners.inside = inside_corner_strategies().parse(*o.inside_corners).value();
  if (jc.mode == JetCompensationMode::off) return {};
  const std::filesystem::path file =
      o.kerf_file.empty() ? std::filesystem::path(s.materials_source).parent_path() / "kerf.toml" : std::filesystem::path(o.kerf_file);
  if (!std::filesystem::exists(file)) {
    if (jc.mode == JetCompensationMode::automatic && o.kerf_file.empty()) return {};
    return std::unexpected(usage(fmt::format("--jet-compensation {}: no kerf calibrations in {} (lamina calibrate coupon, then "
                                             "lamina calibrate fit; docs/jet.md)",
                                             jet_compensation_name(jc.mode), file.string())));
  }
  auto text = read_config_file(file.string(), "kerf");
  if (!text) return std::unexpected(text.error());
  auto calibrations = parse_kerf_toml(*text, file.string());
  if (!calibrations) return std::unexpected(calibrations.error());
  for (const auto& [material, k] : *calibrations) jc.kerf_by_material.emplace(material, k.model);
  s.kerf_source = file.string();
  return {};
}

}  // namespace

void add_cam_options(CLI::App& cmd, CamOptions& o) {
  cmd.add_option("--machine", o.machine_file, "Machine file: head, post, motion, cutting, jet, feed, nest (TOML; default config/machine.toml)");
  cmd.add_option("--materials", o.materials_file, "Materials file (TOML; default config/materials.toml)");
  cmd.add_option("--material", o.material, "Cut every sheet as this material (a name in the materials file)");
  cmd.add_option("--nest", o.nest, "Nesting: shape (true shape, libnest2d) or matrix (the paper's rows)")
      ->check(CLI::IsMember(nest_methods().names()));
  cmd.add_option("--post", o.post, "G-code dialect")->check(CLI::IsMember(post_dialects().names()));
  cmd.add_option("--rtcp", o.rtcp, "The controller does RTCP (true: tip coordinates, G43.4) or not (false: pivot coordinates, G93)");
  cmd.add_option("--feed-model", o.feed_model, "Feed model: zeng-kim or limbachiya-patel (the paper's eq. 3)")
      ->check(CLI::IsMember(feed_models().names()));
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
  cmd.add_option("--jet-compensation", o.jet_compensation,
                 "The jet's real kerf (docs/jet.md): auto (full where the material is calibrated), off, taper or full")
      ->check(CLI::IsMember(jet_compensation_modes().names()));
  cmd.add_option("--kerf-file", o.kerf_file, "Kerf calibrations (lamina calibrate fit; default: kerf.toml beside the materials file)");
  cmd.add_option("--corner-error", o.corner_error_mm,
                 "Under jet compensation: the largest error the jet's lagging lower part may leave at a corner; "
                 "corners are slowed until the kerf model's trail-back keeps it (mm, default 0.05)")
      ->check(CLI::Range(0.001, 10.0));
  cmd.add_option("--inside-corners", o.inside_corners,
                 "Under jet compensation, inside corners of a part: slow (like outside ones) or keep the feed "
                 "(a fillet of material stays at the bottom)")
      ->check(CLI::IsMember(inside_corner_strategies().names()));
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
  // Names were checked against the same tables by the options (IsMember): parse cannot fail here.
  if (o.nest) m.nest.method = nest_methods().parse(*o.nest).value();
  if (o.post) m.post.dialect = post_dialects().parse(*o.post).value();
  if (o.rtcp) m.head.rtcp = *o.rtcp;
  if (o.feed_model) m.cutting.feed.model = feed_models().parse(*o.feed_model).value();
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
  if (const auto* dialect = post_dialects().find(m.post.dialect); m.head.rtcp && !dialect->traits.rtcp) {
    std::vector<std::string_view> with_rtcp;
    for (const auto& d : post_dialects().rows())
      if (d.traits.rtcp) with_rtcp.push_back(d.name);
    return std::unexpected(usage(fmt::format("{} has no RTCP (G43.4): use --rtcp false (pivot coordinates and G93), or "
                                             "--post {} for a controller that keeps the tool tip",
                                             dialect->traits.controller, fmt::join(with_rtcp, " / "))));
  }
  if (auto jet = resolve_jet_compensation(o, s); !jet) return std::unexpected(jet.error());
  // A pierce in the gap between two parts must not land in the neighbour.
  if (m.nest.spacing_mm < m.cutting.lead_in_mm + m.cutting.kerf_mm)
    return std::unexpected(usage(fmt::format(
        "spacing {} mm is less than lead-in {} mm + kerf {} mm: outer pierces would land in the neighbouring part",
        m.nest.spacing_mm, m.cutting.lead_in_mm, m.cutting.kerf_mm)));
  return s;
}

void print_sheet_table(std::FILE* out, const PlanReport& report) {
  if (!report.sheets || !report.cam) return;
  fmt::print(out, "{:>5} {:>6} {:>11} {:>5} {:>6} {:>7} {:>9} {:>8} {:>9} {:>7}  {}\n", "sheet", "t mm", "size mm",
             "parts", "util %", "pierces", "cut m", "time", "NC bytes", "B/5ax", "material");
  double total = 0.0;
  for (const ReportSheet& s : *report.sheets) {
    const double t = s.estimated_time_s;
    total += t;
    const auto& b = s.bytes_per_five_axis_move;
    fmt::print(out, "{:>5} {:>6.3g} {:>11} {:>5} {:>6.1f} {:>7} {:>9.2f} {:>5}:{:02} {:>9} {:>7}  {}\n", s.index,
               s.thickness_mm, fmt::format("{:g}x{:g}", s.length_mm, s.width_mm), s.parts.size(),
               100.0 * s.utilisation, s.pierces, s.cut_length_mm / 1000.0, static_cast<int>(t) / 60,
               static_cast<int>(t) % 60, s.program_bytes, b ? fmt::format("{:.1f}", *b) : "-",
               s.slot ? fmt::format("{} (slot {})", s.material, *s.slot) : s.material);
  }
  const ReportCam& c = *report.cam;
  fmt::print(out, "  {} sheets, {} parts, estimated cutting {}:{:02}:{:02} (h:m:s); {} nesting, {} post{}\n",
             report.sheets->size(), c.parts, static_cast<int>(total) / 3600, static_cast<int>(total) / 60 % 60,
             static_cast<int>(total) % 60, c.nest, c.post, c.rtcp ? " (RTCP)" : " (pivot coordinates, G93)");
  const ReportCamTiming& t = c.timing_s;
  fmt::print(out, "  timing: parts {:.3f} s, nest {:.3f} s, toolpaths {:.3f} s, post {:.3f} s, svg {:.3f} s\n\n",
             t.parts, t.nest, t.toolpath, t.post, t.svg);
}

}  // namespace lamina::cli
