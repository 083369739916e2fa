#pragma once
// report.json as one typed struct (issue 18): what a plan hands to every front end — the CLI's
// tables and --json, laminad's job record, the web console. The file is this struct's one
// serialisation: plan_report_json() writes it and parse_plan_report() reads it back, both from
// the same field tables (src/plan/plan_report_json.cpp), so a field cannot be renamed on one side
// only; a file that does not match (a missing or unknown key, a wrong type) is refused with the
// key's path. Units are in the field names, as in the file.
#include "lamina/core/error.hpp"

#include <array>
#include <cstdint>
#include <expected>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace lamina {

// What a STEP or IGES file told the plan (docs/step.md): its unit, how finely it was tessellated,
// whose normals the bevel plan read, its solids and how many faces of each surface kind.
struct ReportCadSolid {
  std::string name;
  std::int64_t faces = 0, triangles = 0;
};
struct ReportCad {
  std::string length_unit;          // as the file names it ("MILLIMETRE", "INCH"); empty: not said
  double chord_tolerance_mm = 0.0;  // the tessellation's largest distance from the B-rep surface
  std::string surface_normals;      // "exact" (the B-rep surface's) or "facet" (the triangles')
  std::vector<ReportCadSolid> solids;
  std::vector<std::pair<std::string, std::int64_t>> surface_kinds;  // kind → faces, kinds present
};

// What the report's deviation was measured against when it is not the planned mesh: a STEP
// file tessellated finer than for planning (the CAD surface to within that chord), or another
// file of the same part (--deviation-against: a mesh plan measured against the customer's STEP).
struct ReportDeviationReference {
  std::string file, format;
  std::int64_t triangles = 0;
  std::optional<double> chord_tolerance_mm;  // a STEP / IGES reference's; null for a mesh
};

struct ReportModel {
  std::string file, format;
  std::int64_t triangles = 0;
  double volume_mm3 = 0.0, height_mm = 0.0;
  std::optional<ReportCad> cad;  // a B-rep file only; left out of the file for a mesh
  std::optional<ReportDeviationReference> deviation_reference;  // left out: the planned mesh
};

struct ReportStockSheet {  // a sheet (type) of the rack; null: not given
  double thickness_mm = 0.0;
  std::optional<double> width_mm, length_mm;
  std::optional<std::int64_t> count;
  std::optional<std::string> material;
  std::optional<std::string> slot;  // where it lies on the rack; left out of the file when not given
};

struct ReportSettings {
  std::vector<ReportStockSheet> stock;
  std::string stock_source;  // "default", "--stock", or the stock file's path
  std::vector<double> thicknesses_mm;
  double bond_mm = 0.0, sub_slice_mm = 0.0, tolerance_mm = 0.0, tilt_max_deg = 0.0;
  std::string side, strategy, layering;
  double deviation_step_mm = 0.0;
  // false: `deviation` holds the chosen strategy's only. Absent in reports written before it
  // (issue 22), which measured all three.
  std::optional<bool> compare_strategies;
  std::string axis;
  std::optional<std::vector<double>> direction;
  std::string units;
};

struct ReportShapes {  // cut stations per profile shape
  std::int64_t convex = 0, concave = 0, straight = 0, mixed = 0, empty = 0;
};

struct ReportLayer {
  std::int64_t index = 0;
  double z_bottom_mm = 0.0, thickness_mm = 0.0;
  std::int64_t sub_slices = 0, passes = 0;
  double max_deviation_mm = 0.0, profile_deviation_mm = 0.0;
  bool within_tolerance = false;
  double gouge_shift_mm = 0.0, gouge_left_mm = 0.0;
  std::optional<double> estimated_deviation_mm;
  std::int64_t outlines = 0, stations = 0;
  ReportShapes shapes;
  // Its stations stand on an outline simplified off the material (docs/bevels.md); absent in
  // reports written before the field was.
  std::optional<bool> outline_simplified;
};

struct ReportStack {
  std::int64_t layers = 0;
  double model_height_mm = 0.0, stack_height_mm = 0.0, height_difference_mm = 0.0;
  std::vector<std::pair<std::string, std::int64_t>> sheets_used;  // thickness ("2.5") → layers, thinnest first
};

struct ReportShortfall {
  double z_from_mm = 0.0, z_to_mm = 0.0, deviation_mm = 0.0;
};

struct ReportDeviation {
  double volume_mm3 = 0.0, volume_pct = 0.0, max_mm = 0.0;
  std::array<double, 3> max_at_mm{};
  double stack_volume_mm3 = 0.0;
};

struct ReportTiming {  // seconds
  double read = 0.0, topology = 0.0, layering = 0.0, bevel = 0.0, deviation = 0.0, write = 0.0, total = 0.0;
};

struct ReportCamTiming {  // seconds
  double parts = 0.0, nest = 0.0, toolpath = 0.0, post = 0.0, svg = 0.0;
};

// The head as the program's coordinates need it (kinematics.hpp), so a reader of sheet-<n>.nc (the
// web console's 3D toolpath) turns its X Y Z A C into the tool tip and axis without the machine
// file. Degrees, as the program's A and C are.
struct ReportHead {
  double pivot_mm = 0.0;
  std::int64_t a_sign = 1, c_sign = 1;
  double c_offset_deg = 0.0;
};

struct ReportCam {
  std::string machine_file, materials_file, nest;
  double spacing_mm = 0.0, margin_mm = 0.0;
  bool fill_holes = false;
  std::string post;
  bool rtcp = false;
  std::optional<ReportHead> head;  // absent in reports written before it (0.7.0 and older)
  std::optional<std::string> jet_compensation, kerf_file;  // as asked ("auto"…), and the calibrations' file; absent before 0.8
  // The trail-back's corner speeds (--corner-error, --inside-corners) and the head's rotary rates
  // (degrees/min; absent when not limited): absent in reports written before issue 20's corners.
  std::optional<double> corner_error_mm, a_max_deg_per_min, c_max_deg_per_min;
  std::optional<std::string> inside_corners;
  std::string feed_model;
  std::int64_t quality = 0;
  double kerf_mm = 0.0, lead_in_mm = 0.0, lead_out_mm = 0.0, pierce_dwell_s = 0.0;
  std::int64_t microjoints = 0;
  double microjoint_width_mm = 0.0;
  std::int64_t dowels = 0;
  double dowel_diameter_mm = 0.0;
  std::int64_t parts = 0;
  ReportCamTiming timing_s;
};

struct ReportPart {  // a part placed on a sheet
  std::int64_t layer = 0, island = 0;
  std::string label;
  double x_mm = 0.0, y_mm = 0.0, rotation_deg = 0.0;
  std::optional<std::string> inside;  // the label of the part whose hole holds it
  std::int64_t dowels = 0;
};

struct ReportSheetTime {  // seconds
  double cutting = 0.0, rapids = 0.0, pierces = 0.0;
};

// Where a contour sits in its sheet's program (the post's PostedProgram): laminad resumes a
// stopped cut at a contour's line, and knows a contour whose last cut ran is finished.
struct ReportContour {
  std::int64_t index = 0;          // the contour's number, as its (CONTOUR n …) marker says
  std::int64_t line = 0;           // 1-based line of its start (the marker; a safe restart)
  std::int64_t last_cut_line = 0;  // 1-based line of its last cutting move; 0: none
};

struct ReportSheet {
  std::int64_t index = 0;
  double thickness_mm = 0.0, width_mm = 0.0, length_mm = 0.0;
  std::string material;
  std::optional<std::string> slot;  // the rack slot of its stock entry, when the stock file names one
  std::string program, svg;  // file names in the plan's folder
  double estimated_time_s = 0.0;
  ReportSheetTime time_s;
  double cut_length_mm = 0.0;
  std::int64_t pierces = 0, contours = 0, microjoints = 0;
  double utilisation = 0.0;
  std::int64_t program_bytes = 0, program_lines = 0, five_axis_moves = 0;
  std::optional<double> bytes_per_five_axis_move;
  std::vector<ReportPart> parts;
  std::int64_t setup_lines = 0;  // the program's set-up: its lines before the first contour
  std::vector<ReportContour> contour_lines;
  std::optional<std::string> jet_compensation;  // what this sheet got: off, taper, full (absent before 0.8)
  std::optional<std::int64_t> jet_tilt_limited;  // its cut lines whose compensation the tilt limit held back
  // Its lines whose corner the trail-back's corner speeds left beyond --corner-error at their
  // slowest feed (absent when none, and before issue 20's corner work).
  std::optional<std::int64_t> jet_corners_floored;
};

// The part as cut, beside the plan (lamina plan --as-cut; lamina/core/as_cut.hpp): both measured
// the same way, slab by slab at the depths the cut sheets were sectioned at.
struct ReportAsCutFigures {
  double volume_mm3 = 0.0, volume_pct = 0.0, max_mm = 0.0;
  std::array<double, 3> max_at_mm{};
};

struct ReportAsCutLayer {
  std::int64_t layer = 0;
  double model_volume_mm3 = 0.0;
  ReportAsCutFigures planned, as_cut;
  std::int64_t parts = 0, parts_freed = 0;
};

struct ReportAsCut {
  std::string dir;  // where the sheets' sections were read
  double model_volume_mm3 = 0.0;
  ReportAsCutFigures planned, as_cut;
  std::int64_t parts = 0, parts_freed = 0;
  std::vector<std::string> not_freed;
  std::vector<ReportAsCutLayer> layers;
};

struct PlanReport {
  ReportModel model;
  ReportSettings settings;
  std::vector<ReportLayer> layers;
  ReportStack stack;
  std::vector<ReportShortfall> shortfalls;
  std::vector<std::pair<std::string, ReportDeviation>> deviation;  // strategy name → its deviation, in planning order
  std::vector<std::string> warnings;
  ReportTiming timing_s;
  std::optional<ReportCam> cam;                  // absent when no programs were made
  std::optional<std::vector<ReportSheet>> sheets;  // likewise
  std::optional<ReportAsCut> as_cut;               // only with --as-cut
};

// report.json's text: two-space indented, keys in the order above, a newline at the end.
std::string plan_report_json(const PlanReport& report);
// The report's model.cad alone, as it writes it (`lamina check --json` gives the same object).
std::string report_cad_json(const ReportCad& cad);

// Reads report.json back. ErrorCode::parse_error naming the path of what does not match
// ("report.json: sheets[1].program: missing", "…: expected a number, found a string").
std::expected<PlanReport, Error> parse_plan_report(std::string_view text);

}  // namespace lamina
