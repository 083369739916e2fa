#pragma once
// Post-processors (DESIGN step 8): a sheet's toolpath → a G-code program in a controller's dialect.
// Compact lines (modal words omitted, trailing zeros stripped, no spaces) because at 115200 baud
// every byte is machine time. Contours are marked with a comment `(CONTOUR n ...)` at their pierce
// so the machine link can resume at the start of a contour.
#include "lamina/core/choices.hpp"
#include "lamina/core/error.hpp"
#include "lamina/core/kinematics.hpp"
#include "lamina/core/toolpath.hpp"

#include <cstddef>
#include <cstdint>
#include <expected>
#include <string>
#include <vector>

namespace lamina {

enum class PostDialect : std::uint8_t { grblhal, fanuc, linuxcnc };
// What a dialect's controller can do, as far as the post and its callers need to know.
struct PostDialectTraits {
  std::string_view controller;  // as its maker writes it: "grblHAL"
  bool rtcp = false;  // keeps the tool tip itself (G43.4 or TCP kinematics); else pivot coordinates and G93
};
const ChoiceTable<PostDialect, PostDialectTraits>& post_dialects();  // "grblhal", "fanuc", "linuxcnc"
const char* post_dialect_name(PostDialect dialect);

struct PostParams {
  PostDialect dialect = PostDialect::grblhal;
  int linear_decimals = 3;   // mm
  int angular_decimals = 4;  // degrees (4: 1e-4° on a 150 mm pivot is 0.26 µm at the tip)
  // Without RTCP: A and C are not rewritten while the axis they give stays within one linear step
  // of the planned one at the sheet's far face (thickness times the angle between them), and are
  // written with the fewest decimals that keep it there; X Y Z follow the angles written, so the
  // tip does not move. Off: every change that shows in angular_decimals is written.
  bool hold_rotary_within_step = true;
  int feed_decimals = 1;     // most decimals of a G94 F (mm/min); both F kinds get 4 significant digits
  std::string jet_on = "M3";   // M-code(s) that open the cutting-head valve
  std::string jet_off = "M5";
  int program_number = 1000;   // fanuc: O number
  std::string title;           // first comment line (part of the job, sheet, thickness, material)
};

struct PostedProgram {
  std::string text;
  std::size_t lines = 0;
  std::size_t motion_lines = 0;        // G0/G1 lines
  std::size_t five_axis_moves = 0;     // motion lines that carry A or C
  std::size_t five_axis_bytes = 0;     // their bytes, newline included
  // Where each contour is, for the link's resume point (issue 18: handed over with the program,
  // never parsed back from its comments): 1-based line of each contour's marker (its safe
  // restart: the lines after it restate every modal word), and of its last cutting move (a
  // motion line with the jet on; 0 when the contour has none), per ToolContour. The lines
  // before the first contour are the program's set-up.
  std::vector<std::size_t> contour_lines;
  std::vector<std::size_t> contour_last_cut_lines;
  std::size_t setup_lines = 0;
  std::vector<AxisPose> poses;         // machine axes at the end of every ToolMove (same order)
};

// Errors name the move (contour, index) that the machine cannot reach: tilt beyond the A limits,
// a contour whose C travel exceeds a limited C range; and a setup the dialect cannot run (grblhal
// with head.rtcp: grblHAL has no G43.4). docs/posts.md has the conventions of every dialect.
std::expected<PostedProgram, Error> post_program(const SheetToolpath& toolpath, const HeadKinematics& head,
                                                 const PostParams& params);

}  // namespace lamina
