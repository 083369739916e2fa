// The report of a finished plan (plan_report.hpp), built from its typed result.
#include "lamina/core/plan_job.hpp"

#include <fmt/format.h>

#include <cmath>
#include <map>
#include <numbers>

namespace lamina {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// 0 / "" mean "not given" in SheetStock; the report says null.
std::optional<double> given(double v) { return v > 0.0 ? std::optional(v) : std::nullopt; }

ReportSettings settings_report(const PlanJobRequest& q) {
  const PlanSettings& s = q.settings;
  ReportSettings r;
  for (const SheetStock& sheet : s.stock.sheets)
    r.stock.push_back({sheet.thickness_mm, given(sheet.width_mm), given(sheet.length_mm),
                       sheet.count > 0 ? std::optional<std::int64_t>(sheet.count) : std::nullopt,
                       sheet.material.empty() ? std::nullopt : std::optional(sheet.material),
                       sheet.slot.empty() ? std::nullopt : std::optional(sheet.slot)});
  r.stock_source = s.stock_source;
  r.thicknesses_mm = s.thicknesses_mm;
  r.bond_mm = s.bond_mm;
  r.sub_slice_mm = s.sub_slice_mm;
  r.tolerance_mm = s.tolerance_mm;
  r.tilt_max_deg = s.tilt_max_deg;
  r.side = cut_side_name(s.side);
  r.strategy = bevel_strategy_name(s.strategy);
  r.layering = layering_method_name(s.layering);
  r.deviation_step_mm = s.deviation_step_mm;
  r.compare_strategies = s.compare_strategies;
  r.axis = q.model.axis;
  if (!q.model.direction.empty()) r.direction = q.model.direction;
  r.units = q.model.units;
  return r;
}

ReportLayer layer_report(const LayerPlan& l, const LayerSpan* span) {
  std::int64_t stations = 0;
  for (const LayerOutline& o : l.outlines) stations += static_cast<std::int64_t>(o.stations.size());
  const auto shape = [&](ProfileShape s) { return static_cast<std::int64_t>(l.shape_counts[static_cast<std::size_t>(s)]); };
  ReportLayer r;
  r.index = l.index;
  r.z_bottom_mm = l.z_bottom_mm;
  r.thickness_mm = l.thickness_mm;
  r.sub_slices = static_cast<std::int64_t>(l.sub_slice_z_mm.size());
  r.passes = l.passes;
  r.max_deviation_mm = l.max_deviation_mm;
  r.profile_deviation_mm = l.profile_deviation_mm;
  r.within_tolerance = l.within_tolerance;
  r.gouge_shift_mm = l.gouge_shift_mm;
  r.gouge_left_mm = l.gouge_left_mm;
  if (span) r.estimated_deviation_mm = span->estimated_deviation_mm;
  r.outlines = static_cast<std::int64_t>(l.outlines.size());
  r.stations = stations;
  r.shapes = {shape(ProfileShape::convex), shape(ProfileShape::concave), shape(ProfileShape::straight),
              shape(ProfileShape::mixed), shape(ProfileShape::empty)};
  r.outline_simplified = l.outline_simplified;
  return r;
}

ReportStack stack_report(const Layering& layering) {
  std::map<double, std::int64_t> used;
  for (const LayerSpan& l : layering.layers) ++used[l.thickness_mm];
  ReportStack r;
  r.layers = static_cast<std::int64_t>(layering.layers.size());
  r.model_height_mm = layering.model_height_mm;
  r.stack_height_mm = layering.stack_height_mm;
  r.height_difference_mm = layering.stack_height_mm - layering.model_height_mm;
  for (const auto& [t, n] : used) r.sheets_used.emplace_back(fmt::format("{}", t), n);
  return r;
}

ReportDeviation deviation_report(const Deviation& d) {
  return {d.volume_mm3, d.volume_pct, d.max_mm, {d.max_at_mm.x(), d.max_at_mm.y(), d.max_at_mm.z()}, d.stack_volume_mm3};
}

ReportCam cam_report(const CamSettings& s, const CamResult& r) {
  const MachineConfig& m = s.machine;
  ReportCam c;
  c.machine_file = s.machine_source;
  c.materials_file = s.materials_source;
  c.nest = nest_method_name(m.nest.method);
  c.spacing_mm = m.nest.spacing_mm;
  c.margin_mm = m.nest.margin_mm;
  c.fill_holes = m.nest.fill_holes;
  c.post = post_dialect_name(m.post.dialect);
  c.rtcp = m.head.rtcp;
  c.head = ReportHead{m.head.pivot_mm, m.head.a_sign, m.head.c_sign, m.head.c_offset_rad / kDeg};
  c.jet_compensation = jet_compensation_name(m.cutting.jet_compensation.mode);
  if (!s.kerf_source.empty()) c.kerf_file = s.kerf_source;
  c.corner_error_mm = m.cutting.jet_compensation.corners.error_mm;
  c.inside_corners = inside_corners_name(m.cutting.jet_compensation.corners.inside);
  const auto per_min = [](double rad_per_s) { return std::isfinite(rad_per_s) ? std::optional(rad_per_s * 60.0 / kDeg) : std::nullopt; };
  c.a_max_deg_per_min = per_min(m.cutting.a_max_rad_per_s);
  c.c_max_deg_per_min = per_min(m.cutting.c_max_rad_per_s);
  c.feed_model = feed_model_name(m.cutting.feed.model);
  c.quality = m.cutting.feed.quality;
  c.kerf_mm = m.cutting.kerf_mm;
  c.lead_in_mm = m.cutting.lead_in_mm;
  c.lead_out_mm = m.cutting.lead_out_mm;
  c.pierce_dwell_s = m.cutting.pierce_dwell_s;
  c.microjoints = m.cutting.microjoints;
  c.microjoint_width_mm = m.cutting.microjoint_width_mm;
  c.dowels = s.parts.dowels.count;
  c.dowel_diameter_mm = s.parts.dowels.diameter_mm;
  c.parts = static_cast<std::int64_t>(r.parts.size());
  c.timing_s = {r.timing.parts, r.timing.nest, r.timing.toolpath, r.timing.post, r.timing.svg};
  return c;
}

ReportPart part_report(const SheetOutput& s, const Placement& pl, const std::vector<Part>& parts) {
  const Part& p = parts[static_cast<std::size_t>(pl.part)];
  ReportPart r{p.layer, p.island, part_label(p), pl.offset_mm.x(), pl.offset_mm.y(), pl.rotation_rad / kDeg, {},
               static_cast<std::int64_t>(p.dowels_mm.size())};
  if (pl.host >= 0)
    r.inside = part_label(parts[static_cast<std::size_t>(s.sheet.placements[static_cast<std::size_t>(pl.host)].part)]);
  return r;
}

ReportSheet sheet_report(const SheetOutput& s, const std::vector<Part>& parts) {
  const CutTime& t = s.toolpath.time;
  const PostedProgram& prog = s.program;
  ReportSheet r;
  r.index = s.sheet.index;
  r.thickness_mm = s.sheet.thickness_mm;
  r.width_mm = s.sheet.width_mm;
  r.length_mm = s.sheet.length_mm;
  r.material = s.material;
  if (!s.sheet.slot.empty()) r.slot = s.sheet.slot;
  r.program = s.program_name;
  r.svg = s.svg_name;
  r.estimated_time_s = t.total_s;
  r.time_s = {t.cutting_s, t.rapid_s, t.pierce_s};
  r.cut_length_mm = t.cut_length_mm;
  r.pierces = t.pierces;
  r.contours = static_cast<std::int64_t>(s.toolpath.contours.size());
  r.microjoints = static_cast<std::int64_t>(s.toolpath.microjoints.size());
  r.utilisation = s.sheet.utilisation;
  r.program_bytes = static_cast<std::int64_t>(prog.text.size());
  r.program_lines = static_cast<std::int64_t>(prog.lines);
  r.five_axis_moves = static_cast<std::int64_t>(prog.five_axis_moves);
  if (prog.five_axis_moves) r.bytes_per_five_axis_move = static_cast<double>(prog.five_axis_bytes) / prog.five_axis_moves;
  for (const Placement& pl : s.sheet.placements) r.parts.push_back(part_report(s, pl, parts));
  r.setup_lines = static_cast<std::int64_t>(prog.setup_lines);
  r.jet_compensation = jet_compensation_name(s.toolpath.jet_compensation);
  r.jet_tilt_limited = static_cast<std::int64_t>(s.toolpath.jet_tilt_limited);
  if (s.toolpath.jet_corners_floored) r.jet_corners_floored = static_cast<std::int64_t>(s.toolpath.jet_corners_floored);
  for (std::size_t c = 0; c < prog.contour_lines.size(); ++c)
    r.contour_lines.push_back({static_cast<std::int64_t>(c), static_cast<std::int64_t>(prog.contour_lines[c]),
                             static_cast<std::int64_t>(prog.contour_last_cut_lines[c])});
  return r;
}

}  // namespace

PlanReport make_plan_report(const Mesh& mesh, const PlanJobRequest& request, const PlanJobResult& result) {
  const MeshSummary& s = mesh.summary;
  PlanReport r;
  r.model = {request.model.file, request.model.format, static_cast<std::int64_t>(s.triangles), s.volume_mm3,
             s.bbox_max_mm.z() - s.bbox_min_mm.z(), request.model.cad, request.model.deviation_reference};
  r.settings = settings_report(request);
  const auto& spans = result.layering.layers;
  for (std::size_t i = 0; i < result.plan.layers.size(); ++i)
    r.layers.push_back(layer_report(result.plan.layers[i], i < spans.size() ? &spans[i] : nullptr));
  r.stack = stack_report(result.layering);
  for (const Shortfall& f : result.layering.shortfalls) r.shortfalls.push_back({f.z_from_mm, f.z_to_mm, f.deviation_mm});
  for (const StrategyDeviation& d : result.deviations)
    r.deviation.emplace_back(bevel_strategy_name(d.strategy), deviation_report(d.deviation));
  if (result.cam) {
    r.cam = cam_report(*request.cam, *result.cam);
    r.sheets.emplace();
    for (const SheetOutput& sheet : result.cam->sheets) r.sheets->push_back(sheet_report(sheet, result.cam->parts));
  }
  return r;
}

}  // namespace lamina
