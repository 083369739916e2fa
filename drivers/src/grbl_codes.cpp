#include "grbl_codes.hpp"

#include <fmt/format.h>

namespace lamina::drivers::detail {
namespace {

// Short wording of our own for the operator's screen; the number is appended so the manual
// (grblHAL wiki "Errors and Alarms") can be looked up.
const char* error_text(int code) {
  switch (code) {
    case 1: return "expected a command letter";
    case 2: return "bad number format";
    case 3: return "invalid '$' statement";
    case 4: return "negative value where a positive one is expected";
    case 5: return "homing is not enabled";
    case 6: return "step pulse shorter than the minimum";
    case 7: return "settings read failed (defaults restored)";
    case 8: return "'$' command only allowed when idle";
    case 9: return "G-code locked out (alarm or jog)";
    case 10: return "soft limits need homing enabled";
    case 11: return "line too long (overflow)";
    case 12: return "step rate above the maximum";
    case 13: return "safety door open";
    case 14: return "build info or startup line too long";
    case 15: return "jog target beyond machine travel";
    case 16: return "invalid jog command";
    case 17: return "laser mode needs PWM output";
    case 18: return "reset asserted";
    case 19: return "non-positive value";
    case 20: return "unsupported or invalid G-code command";
    case 21: return "two commands of the same modal group";
    case 22: return "feed rate undefined";
    case 23: return "command value must be an integer";
    case 24: return "two commands that need axis words";
    case 25: return "repeated word";
    case 26: return "no axis words where required";
    case 27: return "invalid line number";
    case 28: return "missing value word";
    case 29: return "unsupported work coordinate system";
    case 30: return "G53 only with G0 or G1";
    case 31: return "axis words with no command using them";
    case 32: return "arc without an in-plane axis word";
    case 33: return "invalid motion target";
    case 34: return "invalid arc radius";
    case 35: return "arc without an in-plane offset";
    case 36: return "unused value words";
    case 37: return "G43.1 offset not on the tool length axis";
    case 38: return "invalid tool number";
    case 39: return "value out of range";
    case 40: return "not allowed while a tool change is pending";
    case 41: return "spindle not running";
    case 42: return "plane must be ZX";
    case 43: return "maximum feed rate exceeded";
    case 44: return "spindle speed out of range";
    case 45: return "limit switch engaged: only homing allowed";
    case 46: return "homing required";
    case 47: return "current tool not set";
    case 48: return "value word conflict";
    case 49: return "power-on self test failed";
    case 50: return "emergency stop active";
    case 51: return "motor fault";
    case 52: return "setting value out of range";
    case 53: return "setting not available";
    case 54: return "retract position below drill depth";
    case 55: return "illegal homing configuration";
    case 56: return "coordinate system locked";
    case 57: return "unexpected file demarcation";
    case 77: return "authentication required";
    case 78: return "access denied";
    case 79: return "not allowed while a critical event is active";
    default: return nullptr;
  }
}

const char* alarm_text(int code) {
  switch (code) {
    case 1: return "hard limit (position lost, re-home)";
    case 2: return "soft limit: target beyond machine travel";
    case 3: return "reset while moving (position lost, re-home)";
    case 4: return "probe not in the expected initial state";
    case 5: return "probe did not make contact";
    case 6: return "homing cycle was reset";
    case 7: return "safety door opened during homing";
    case 8: return "homing pull-off did not clear the limit switch";
    case 9: return "homing could not find the limit switch";
    case 10: return "emergency stop";
    case 11: return "homing required";
    case 12: return "limit switch engaged";
    case 13: return "probe protection triggered";
    case 14: return "spindle did not reach speed";
    case 15: return "homing could not find the second switch of a squared axis";
    case 16: return "power-on self test failed";
    case 17: return "motor fault";
    case 18: return "homing failed: bad configuration";
    default: return nullptr;
  }
}

std::string with_code(const char* text, const char* unknown, int code) {
  return fmt::format("{} ({})", text ? text : unknown, code);
}

}  // namespace

std::string grbl_error_meaning(int code) { return with_code(error_text(code), "unknown error", code); }
std::string grbl_alarm_meaning(int code) { return with_code(alarm_text(code), "unknown alarm", code); }

}  // namespace lamina::drivers::detail
