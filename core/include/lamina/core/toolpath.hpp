#pragma once
// Toolpaths of one nested sheet (DESIGN step 6): the order of the cuts, pierces, lead-ins and
// lead-outs, trim passes before the pass that frees a part, microjoints, kerf compensation in
// 5 axes, feeds, and the cut time. Everything is in the sheet frame: origin at the sheet's corner,
// z = 0 on the sheet's top face, its bottom at z = −thickness. The tool tip is where the jet's
// axis crosses the top face; the machine's standoff is above it and belongs to the kinematics.
#include "lamina/core/bevel.hpp"
#include "lamina/core/choices.hpp"
#include "lamina/core/error.hpp"
#include "lamina/core/feed.hpp"
#include "lamina/core/kerf.hpp"
#include "lamina/core/nest.hpp"
#include "lamina/core/parts.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <expected>
#include <limits>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace lamina {

enum class MoveKind : std::uint8_t { rapid, pierce, lead_in, cut, lead_out };
const char* move_kind_name(MoveKind kind);

// One move of the tool tip, from the previous move's end to this one's end. The tool axis turns
// linearly (and is renormalised) along the move. A pierce stands still for dwell_s with the jet on.
struct ToolMove {
  MoveKind kind = MoveKind::rapid;
  Eigen::Vector3d tip_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  // unit, tip → nozzle
  double feed_mm_per_s = 0.0;  // the jet's cutting speed; 0 for rapids (the machine's rapid rate)
  // How long the move takes. Cutting moves: the longer of the jet's travel at the top and at the
  // bottom face, at feed_mm_per_s — so a move that only turns the head about the tip (a fan of
  // lines at a corner) still takes the time its bottom point needs. Rapids: distance / rapid rate.
  // Pierces: dwell_s. Posts derive F from this: G93 F = 1/minutes; G94 F = tip distance/minutes.
  double duration_s = 0.0;
  double dwell_s = 0.0;        // pierce only
  bool jet_on = false;         // the jet's state during the move (on from the pierce to the end of the lead-out)
  int contour = -1;            // index into SheetToolpath::contours; -1 for rapids between contours
  bool tilt_limited = false;   // a cut whose jet compensation the head's tilt limit held back (drawn on the sheet)
  // Not a planned point but one on the way to the next: a move that turns the head further than
  // ToolpathParams::max_turn_per_move_rad goes out in pieces, all but the last of them marked.
  bool turn_piece = false;
};

// One cut from pierce to lead-out: a whole pass around an outline, or a run of it (a trim run,
// or a segment between microjoints).
struct ToolContour {
  int placement = -1;  // index into NestedSheet::placements
  int part = -1;       // index into the parts span
  std::string label;   // the part's label, "L3-2" (part_label), for markers an operator reads
  int outline = -1;    // index into LayerPlan::outlines; -1 for a dowel hole
  int pass = -1;       // index into LayerOutline::passes
  bool is_hole = false;
  bool frees = false;   // part of the pass that separates the outline's inside from its outside
  bool closed = false;  // goes all the way round (no tabs, not a trim run)
  // [first, end) into SheetToolpath::moves: the rapid over the pierce point at safe height, the rapid
  // down, pierce, lead-in, cuts, lead-out, the rapid up. A link resuming "at the start of the contour"
  // starts with the first of them.
  std::size_t first_move = 0, end_move = 0;
  Eigen::Vector2d pierce_mm = Eigen::Vector2d::Zero();
};

// A microjoint left uncut on a freeing pass: from → to along the outline (sheet frame, top face).
struct Microjoint {
  int placement = -1;
  Eigen::Vector2d from_mm = Eigen::Vector2d::Zero(), to_mm = Eigen::Vector2d::Zero();
};

struct CutTime {
  double cutting_s = 0.0;   // lead-ins, cuts, lead-outs at their feeds
  double rapid_s = 0.0;     // rapids at rapid_mm_per_s (straight-line distance)
  double pierce_s = 0.0;    // pierce dwells
  double total_s = 0.0;
  double cut_length_mm = 0.0, rapid_length_mm = 0.0;
  int pierces = 0;
};

// Compensation of the jet's real kerf (kerf.hpp, docs/jet.md): off keeps today's programs bit
// for bit; taper offsets the top and the bottom of every cut line by their own half widths, which
// turns the axis about the travel so the part's wall runs along the planned line; full also aims
// the exit ahead of the line by the trail-back, leaning the axis along the travel; automatic is
// full for a material with a calibration and off for one without (the default).
enum class JetCompensationMode : std::uint8_t { off, taper, full, automatic };
const ChoiceTable<JetCompensationMode>& jet_compensation_modes();  // "auto", "off", "taper", "full"
const char* jet_compensation_name(JetCompensationMode mode);
struct SheetToolpath {
  int sheet = 0;  // NestedSheet::index
  double thickness_mm = 0.0;
  JetCompensationMode jet_compensation = JetCompensationMode::off;  // what this sheet got (never automatic)
  // Lines of the sheet's passes (trimming passes included, cut or not) whose compensation the
  // tilt limit held back: lines planned at the limit already cannot lean further.
  std::size_t jet_tilt_limited = 0;
  // Lines whose corner the trail-back's corner speeds could not bring within the allowance at
  // the slowest feed they allow (JetCorners::min_fraction).
  std::size_t jet_corners_floored = 0;
  std::vector<ToolMove> moves;  // starts with a rapid to the park position at safe height, ends with one back to it
  std::vector<ToolContour> contours;
  std::vector<Microjoint> microjoints;
  CutTime time;
};

// Which corners the trail-back's corner speeds slow down for (jet_corners.hpp). At an outside
// corner of the part the lagging lower jet cuts into the part; at an inside one it leaves a
// fillet of material at the bottom, which a shop may accept (or clean up) rather than pay for.
enum class InsideCorners : std::uint8_t { slow, keep };
const ChoiceTable<InsideCorners>& inside_corner_strategies();  // "slow", "keep"
const char* inside_corners_name(InsideCorners s);

struct JetCorners {
  double error_mm = 0.05;      // the largest corner error of the jet's lower part allowed
  double min_fraction = 0.1;   // of the feed: the slowest a corner is cut
  InsideCorners inside = InsideCorners::slow;
};

struct JetCompensation {
  JetCompensationMode mode = JetCompensationMode::off;
  JetCorners corners;  // used wherever a kerf model is (taper and full)
  std::map<std::string, KerfModel, std::less<>> kerf_by_material;  // a sheet's material must be here when on
  double tilt_max_rad = 1.0471975511965976;  // the head's limit: beyond it the line is held at it and counted
};

struct ToolpathParams {
  double kerf_mm = 0.9;            // the same kerf the parts' footprints were made with
  double lead_in_mm = 3.0;         // pierce point to the contour, into the scrap (shortened to fit small holes)
  double lead_out_mm = 1.5;        // from the contour's end back into the scrap
  double pierce_dwell_s = 1.0;     // jet on, standing still, before the lead-in starts
  double safe_z_mm = 10.0;         // rapids travel at this height above the sheet's top
  int microjoints = 0;             // per outer outline's freeing pass, evenly spaced by length
  double microjoint_width_mm = 0.6;  // uncut length of one microjoint
  double dowel_diameter_mm = 6.0;    // of the parts' dowel holes (Part::dowels_mm), cut vertical
  double rapid_mm_per_s = 250.0;
  // The head's rotary axes' fastest rates ([motion] a_/c_max_deg_per_min; infinite: not limited).
  // A feed that would turn A or C faster is lowered to what they reach: a controller would slow
  // the move anyway, and the jet's kerf at the slower feed is not the one planned (a tilted jet
  // following a curve turns C at the curvature; on thin sheets the feed is fast).
  double a_max_rad_per_s = std::numeric_limits<double>::infinity();
  double c_max_rad_per_s = std::numeric_limits<double>::infinity();
  // No move turns the jet's axis by more than this: a pivot head without RTCP interpolates its
  // joints, so in a move that turns the axis by θ its tip strays from the straight line by up to
  // pivot·(1 − cos θ/2) — 20 mm, through the sheet, for a lead-in from the vertical pierce to a
  // 60° line at a 150 mm pivot. Longer turns are split (the tip along its line, the axis by
  // slerp, the time shared): 2° keeps a 150 mm pivot's tip within 0.023 mm.
  double max_turn_per_move_rad = 0.03490658503988659;
  // Slow-down into sharp corners: a corner turning more than corner_angle_rad (in the top face) is
  // entered and left at feed · max(corner_min_fraction, cos(turn/2)).
  double corner_angle_rad = 0.5235987755982988;  // 30°
  double corner_min_fraction = 0.25;
  bool part_on_right = true;  // outer loops clockwise, holes counter-clockwise (the jet's good side)
  Eigen::Vector2d park_mm = Eigen::Vector2d::Zero();  // where the head waits before and after the sheet
  JetSetup jet;
  FeedParams feed;
  JetCompensation jet_compensation;
};

// The times and lengths of a list of moves (rapids at their distance, pierces counted).
CutTime cut_time(std::span<const ToolMove> moves);

// The toolpath of one nested sheet. material is the sheet's; plan and parts are what the nest was
// made from. Holes of a part are cut before its outer outline; trim runs before the freeing pass.
std::expected<SheetToolpath, Error> plan_sheet_toolpath(const BevelPlan& plan, std::span<const Part> parts,
                                                        const NestedSheet& sheet, const Material& material,
                                                        const ToolpathParams& params);

}  // namespace lamina
