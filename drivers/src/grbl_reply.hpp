#pragma once
// The reply grammar shared by the Grbl character-counting and the send-response protocols:
// received bytes → lines → what each line is. One place, so both protocols read a controller
// the same way.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "lamina/drivers/line_protocol.hpp"

namespace lamina::drivers::detail {

// Splits received bytes into lines ended by LF or CR LF, keeping a partial line across calls
// (a serial read may end anywhere, even between CR and LF).
class ReplyLineSplitter {
 public:
  std::vector<std::string> feed(std::string_view bytes);
  void clear() { partial_.clear(); }

 private:
  std::string partial_;
};

enum class ReplyKind {
  ok,       // `ok`: the oldest line in flight was taken
  error,    // `error:N` (or Grbl 0.9's `error:Text`): the oldest line in flight was refused
  alarm,    // `ALARM:N`
  banner,   // `Grbl 1.1h ['$' for help]`, `GrblHAL 1.1f …`: the controller (re)started
  status,   // `<…>` real-time report
  info,     // `[…]` push message or `$I`/`$G` answer, `$N=…` setting, `>…:ok` startup line
  unknown,  // anything else: garbled bytes or a controller we do not understand
};

struct Reply {
  ReplyKind kind = ReplyKind::unknown;
  int code = 0;  // error / alarm number, 0 when the controller sent text instead
  std::string line;
};

Reply classify_reply(std::string_view line);

// Folds `[OPT:flags,blocks,rx[,axes…]]` and `[AXS:n:letters]` into `info`; false for other lines.
bool learn_build_info(std::string_view line, ControllerInfo& info);

// The operator's wording of an error or alarm reply ("bad number format (2)", or Grbl 0.9's text).
std::string error_meaning(const Reply& reply);
std::string alarm_meaning(const Reply& reply);

}  // namespace lamina::drivers::detail
