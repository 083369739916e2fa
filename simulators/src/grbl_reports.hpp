#pragma once
// Text the grbl personality sends, formatted as grblHAL does (report.c of grblHAL/core):
// the banner, the `?` status report, `$I` build info, `$G` parser state, `$$` settings.
// Kept apart from the protocol state machine so the formats can be read (and tested) in one
// place. Every line ends in "\r\n" (grblHAL's ASCII_EOL).
#include <cstddef>
#include <optional>
#include <string>

#include "machine.hpp"

namespace lamina::sim::grbl {

inline constexpr const char* kEol = "\r\n";
inline constexpr const char* kVersion = "1.1f";
inline constexpr const char* kBuildDate = "20231210";

// grblHAL's welcome message: an empty line first (it starts with ASCII_EOL), so a client
// that was mid-line still sees the banner on its own line.
std::string banner();

// The parser's modal state as far as `$G` shows it. The protocol keeps it from the blocks it
// accepted because the Machine does not expose its modal state.
struct ModalView {
  MotionMode motion = MotionMode::rapid;
  bool inches = false;
  bool relative = false;
  bool inverse_time = false;
  double feed = 0;  // last F word, in the program's units
};

// `<Idle|MPos:…|Bf:…|Ln:…|FS:…,0|WCO:…|Ov:…|A:…>` — grblHAL's report_realtime_status with
// $10 = machine position, buffer state, line numbers, feed/speed, work offset and overrides.
// Stateful as grblHAL is: WCO and Ov come every few reports (report.c's wco_counter and
// override_counter), A: with Ov while an output is on or in the report after it changed.
class StatusReporter {
 public:
  // report_init_message: the banner zeroes both counters, so the next report has Ov.
  void restart();
  std::string report(const Machine& machine, std::size_t rx_free_bytes, double now_s);

 private:
  bool wco_due(bool busy, bool idle);
  bool overrides_due(bool busy, bool wco_now);

  int wco_counter_ = 0, override_counter_ = 0;
  bool report_wco_ = false;          // sys.report.wco: WCO in the next report
  bool report_accessories_ = false;  // sys.report.spindle / coolant: A: in the next report
  Accessories last_accessories_;
  std::uint64_t last_program_ends_ = 0;
};

// `$I`: [VER:], [OPT:<flags>,<planner blocks>,<rx bytes>,<axes>,<tools>], [AXS:], [NEWOPT:],
// [FIRMWARE:] (grblHAL's extended form, compatibility level 0). No trailing ok.
std::string build_info(std::size_t planner_blocks, std::size_t rx_buffer_bytes);

// `$G`: [GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]. No trailing ok.
std::string parser_state(const ModalView& modal, const Accessories& accessories);

// `$$`: the few settings a sender looks at. No trailing ok.
std::string settings_dump();

// `$` alone: grblHAL's one-line help. No trailing ok.
std::string help();

}  // namespace lamina::sim::grbl
