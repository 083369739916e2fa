#pragma once
// Number and comment text of G-code words (post-processors only). Units are converted before
// these are called: the text is what the controller reads.
#include <string>
#include <string_view>

namespace lamina::post_detail {

// `value` rounded to `decimals` places, trailing zeros dropped: 1.5 → "1.5", 2 → "2", −0.0001 at 3
// places → "0". With keep_point (Fanuc) a whole number keeps its point ("2.", "0."): without it,
// Fanuc reads X2 as 2 least input increments (0.002 mm), not 2 mm.
std::string format_number(double value, int decimals, bool keep_point);

// Significant-figure variant for inverse-time F words: at least `significant` significant digits,
// never more than max_decimals places.
std::string format_significant(double value, int significant, int max_decimals, bool keep_point);

// Comment text safe on grblHAL, LinuxCNC and Fanuc: upper case, only A–Z 0–9 space . - + _ / : = #,
// runs of spaces collapsed, at most max_chars characters. The caller adds the parentheses.
std::string comment_text(std::string_view text, std::size_t max_chars);

}  // namespace lamina::post_detail
