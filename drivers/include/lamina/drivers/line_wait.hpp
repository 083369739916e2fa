#pragma once
// When a Grbl-family controller answers a program line — what the streamer must know to tell a
// working controller from a stalled one. Most lines are answered as soon as the parser has
// taken them into the planner; some are answered only when everything before them has run
// (grblHAL's protocol_buffer_synchronize), and a dwell only after the dwell too. While such a
// line waits, the controller reports Idle with lines unanswered: that is work, not a stall.
#include <string_view>

namespace lamina::drivers {

struct LineWait {
  // Answered only when the motion before it is done: a spindle (jet) or coolant change
  // (M3/M4/M5, an S word, M7/M8/M9), a dwell (G4), a pause or program end (M0/M1/M2/M30), a
  // tool change (M6), a wait on an input (M66), a stored offset written to non-volatile memory
  // (G10 L2/L20, G28.1/G30.1).
  bool syncs = false;
  // G4 P: seconds the controller stands Idle after the sync before it answers. 0 otherwise.
  // (M0/M1 wait for a cycle start in Hold, a state the stall rule does not judge.)
  double dwell_s = 0;
};

// Reads the G and M words of one line (comments in parentheses or after ';' skipped, letters in
// either case, spaces allowed between a letter and its number, as Grbl's parser allows).
// Unreadable text counts as an ordinary line: the controller will refuse it with error:N.
LineWait grbl_line_wait(std::string_view line);

}  // namespace lamina::drivers
