#pragma once
// One G-code line as the simulated controller reads it: words, modal commands and the Grbl
// status code a real controller would answer. The simulator's own parser: it shares nothing
// with core/post or drivers/ on purpose (an independent peer catches misunderstandings).
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace lamina::sim {

// Grbl / grblHAL status codes (grblHAL core errors.h numbering) for the errors the simulator
// implements. Sent as `error:N`.
enum class GrblStatus : int {
  ok = 0,
  expected_command_letter = 1,
  bad_number_format = 2,
  invalid_statement = 3,      // unknown $ command
  negative_value = 4,
  idle_error = 8,             // $ command that needs Idle
  system_gc_lock = 9,         // G-code refused: alarm or error lock
  soft_limit = 10,
  overflow = 11,              // line longer than the line buffer
  unsupported_command = 20,   // unknown G/M code
  modal_group_violation = 21,
  undefined_feed_rate = 22,
  command_value_not_integer = 23,
  axis_command_conflict = 24,  // G28 and a motion command (G0-G3) in one block
  word_repeated = 25,
  no_axis_words = 26,
  invalid_line_number = 27,
  value_word_missing = 28,
  g53_invalid_motion_mode = 30,  // G53 outside G0/G1
  no_axis_words_in_plane = 32,   // an arc without X or Y
  invalid_target = 33,
  arc_radius_error = 34,
  no_offsets_in_plane = 35,      // an I/J arc without I and J
  unused_words = 36,             // also a letter this machine has no axis for (B on XYZAC)
  value_out_of_range = 39,
};

// Grbl / grblHAL alarm codes the simulator raises (`ALARM:N`).
enum class GrblAlarm : int {
  hard_limit = 1,
  soft_limit = 2,
  abort_cycle = 3,  // reset while moving: position may be lost
  estop = 10,
  // Simulator-specific codes of the xonxoff (Fanuc drip-feed) personality, outside grbl's range:
  program_error = 80,    // a block the parser / executor refused: a Fanuc stops with an alarm
  buffer_overflow = 87,  // bytes beyond the margin after DC3 (Fanuc's PS087 BUFFER OVERFLOW)
};

inline constexpr int kAxisCount = 5;  // X Y Z A C
// Machine position: X, Y, Z in mm; A, C in degrees (as the controller reports them).
using AxisValues = std::array<double, kAxisCount>;
inline constexpr std::array<char, kAxisCount> kAxisLetters{'X', 'Y', 'Z', 'A', 'C'};

enum class MotionMode { none, rapid, linear, arc_cw, arc_ccw, dwell };

// grblHAL's spindle (M3 cw, M4 ccw, M5 off) and coolant (M7 mist, M8 flood, M9 both off)
// outputs. On this machine the cutting head's valve is the spindle output (the jet).
enum class SpindleCommand { off, cw, ccw };
enum class CoolantCommand { mist, flood, off };

// What one line asks for, after parsing and validation against the modal state it will run in.
struct Block {
  std::string source;                       // the line as received (no end-of-line)
  std::optional<std::int64_t> line_number;  // N word
  MotionMode motion = MotionMode::none;     // motion in this block (G0/G1/G2/G3 modal or G4)
  std::array<std::optional<double>, kAxisCount> axis_words;  // as written (units of the block)
  // Arc words as written, like the axis words: G20 may come from an earlier line, so the
  // executor converts them to mm with its modal units (the _mm names are what they become).
  std::optional<double> i_mm, j_mm, k_mm, r_mm;
  std::optional<double> feed_word;                           // F as written
  std::optional<double> dwell_s;                             // G4 P, converted by dwell_p_unit_s
  std::optional<bool> set_inches;                            // G20 true / G21 false
  std::optional<bool> set_relative;                          // G91 true / G90 false
  std::optional<bool> set_inverse_time;                      // G93 true / G94 false
  std::optional<bool> jet_on;                                // configured jet-on / jet-off M-code
  std::optional<SpindleCommand> spindle;                     // M3 / M4 / M5
  std::optional<CoolantCommand> coolant;                     // M7 / M8 / M9
  bool machine_coords = false;                               // G53: this move in machine coordinates
  bool go_home = false;                                      // G28: via the axis words to the stored home
  bool program_end = false;                                  // M2 / M30
  // A value word nothing on the line uses (B, D, E, H, L, Q, U, V, W here): grblHAL keeps such
  // letters as macro parameters and answers unused_words once every other check passed.
  bool unused_word = false;
  bool percent = false;                                      // a `%` program delimiter line
  bool comment_only = false;                                 // nothing but comments / blank
};

struct ParseParams {
  // M4 turns grblHAL's spindle on counter-clockwise: for a waterjet that is the jet as well.
  std::vector<int> jet_on_mcodes{3, 4};
  std::vector<int> jet_off_mcodes{5};
  std::size_t max_line_chars = 256;  // grblHAL LINE_BUFFER_SIZE is 257 with the terminator
  // Seconds per unit of G4 P: Grbl and LinuxCNC read seconds (1), Fanuc milliseconds (0.001).
  double dwell_p_unit_s = 1.0;
  // Accept an O program number (Fanuc: `O1000` at the head of the program) and ignore it.
  bool accept_program_number = false;
};

struct ParseResult {
  GrblStatus status = GrblStatus::ok;
  Block block;
};

// Parse one line (without its end-of-line). Words are case-insensitive, spaces ignored,
// `( )` and `;` comments skipped, N numbers kept. Letters grblHAL keeps as parameters (B on an
// XYZAC machine, D, E, H, L, Q, U, V, W) set unused_word (the executor answers unused_words
// after its own checks); bad numbers → bad_number_format; a repeated word →
// word_repeated; two motion commands → modal_group_violation. Checks that need the modal
// state (feed missing, G93 without F) are the executor's.
// Further: an unterminated `(` → expected_command_letter; a non-letter where a word starts →
// expected_command_letter; non-integer G/M → command_value_not_integer; unknown G/M codes →
// unsupported_command (G17 G40 G49 G54 G80 are accepted no-ops; G28 and G53 are understood);
// two codes of one modal group (G20 G21, M3 M5, M7 M9, G4 G53…) → modal_group_violation;
// G28 with G0-G3 → axis_command_conflict; N negative, fractional or above
// 10000000 → invalid_line_number; negative F or P → negative_value; G4 without P →
// value_word_missing; P without G4 → unused_words; G4 with axis words →
// modal_group_violation; longer than max_line_chars → overflow. T and S are ignored.
ParseResult parse_block(std::string_view line, const ParseParams& params);

}  // namespace lamina::sim
