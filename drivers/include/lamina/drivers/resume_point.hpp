#pragma once
// Where a stopped cut may safely go on: pure functions over the program, its map and what the
// controller reported. A job never resumes by itself; the operator's resume restarts at the
// start of the contour that was being cut, after a retract and the program's modal set-up, so
// no contour that had finished is cut again. Where the contours are is the post's knowledge,
// handed over with the program (ProgramMap, from the plan's report: issue 18); a program from
// elsewhere is mapped from its `(CONTOUR n …)` markers.
#include <cstddef>
#include <expected>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "lamina/drivers/link_error.hpp"

namespace lamina::drivers {

// True when the line makes the controller plan a block: axis words or a dwell (Grbl keeps
// comments and modal-only lines out of its planner).
bool takes_planner_block(std::string_view line);

// The first line the controller may not have finished. `accepted_count` lines of the program
// (from its start) were acknowledged, and `queued_blocks` planner blocks (the running one
// included) were in use at that moment: those belong to the last acknowledged block lines.
std::size_t first_unfinished_line(const std::vector<std::string>& program, std::size_t accepted_count,
                                  std::size_t queued_blocks);

// Where a program's contours are. Indices are 0-based program lines.
struct ContourSpan {
  int contour = -1;                  // its number (the marker's n)
  std::size_t start_index = 0;       // its first line: a safe restart (the post restates every modal word)
  std::optional<std::size_t> last_cut_index;  // its last cutting move (jet on); none: it cuts nothing
};
struct ProgramMap {
  std::size_t setup_end = 0;         // lines [0, setup_end) are the program's set-up
  std::vector<ContourSpan> contours; // in program order
};

// The map of a program that carries the post's `(CONTOUR n …)` markers: a contour starts at its
// marker, its cuts are the motion lines while the jet M-code (M3/M4 … M5) is on. Empty
// contours when it has none.
ProgramMap program_map_from_markers(const std::vector<std::string>& program);

struct ResumePlan {
  std::size_t restart_index = 0;       // program line to stream from
  int contour = -1;                    // its contour number (-1: before the first contour)
  std::vector<std::string> preamble;   // modal set-up and retract, streamed first
};

// `safe_z_mm`: height to retract to before the first rapid (the contour's own rapid height is
// used when its first G0 line carries a Z).
std::expected<ResumePlan, LinkError> plan_resume(const std::vector<std::string>& program, const ProgramMap& map,
                                                 std::size_t first_unfinished, double safe_z_mm = 10.0);

}  // namespace lamina::drivers
