#pragma once
// What grblHAL's numbered replies mean (errors.h / alarms.h numbering, which keeps classic
// Grbl 1.1's numbers and extends them), so a stopped job names the reason, not just a number.
#include <string>

namespace lamina::drivers::detail {

// "unsupported or invalid G-code command (20)"; unknown codes still carry their number.
std::string grbl_error_meaning(int code);
// "soft limit: target beyond machine travel (2)"
std::string grbl_alarm_meaning(int code);

}  // namespace lamina::drivers::detail
