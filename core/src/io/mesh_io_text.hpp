#pragma once
// Private helpers shared by the text readers (ASCII STL, OBJ): character classes, keyword
// comparison, number parsing with std::from_chars, and quoting of offending input in messages.
#include <fmt/format.h>

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>

namespace lamina::io_detail {

constexpr bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

constexpr char ascii_lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

// Case-insensitive equality; `lower` must already be lower case.
constexpr bool iequals(std::string_view s, std::string_view lower) {
  if (s.size() != lower.size()) return false;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (ascii_lower(s[i]) != lower[i]) return false;
  return true;
}

constexpr bool istarts_with(std::string_view s, std::string_view lower) {
  return s.size() >= lower.size() && iequals(s.substr(0, lower.size()), lower);
}

// Parses a float from [first, last) (a leading '+' is accepted, unlike std::from_chars).
// Values beyond float range become ±inf, values below it 0 (as a float store would). Returns the end
// of the number, or nullptr when no number starts at `first`.
inline const char* parse_float(const char* first, const char* last, float& out) {
  const char* p = first;
  if (p < last && *p == '+') {
    ++p;
    if (p < last && *p == '-') return nullptr;
  }
  auto [end, ec] = std::from_chars(p, last, out);
  if (ec == std::errc{}) return end;
  if (ec == std::errc::result_out_of_range) {
    double d = 0.0;
    auto [end_d, ec_d] = std::from_chars(p, last, d);
    if (ec_d == std::errc{}) {
      out = static_cast<float>(d);
      return end_d;
    }
    if (ec_d == std::errc::result_out_of_range) {  // beyond double too: keep the sign, saturate
      bool negative = *p == '-';
      bool tiny = false;
      for (const char* q = p; q < end_d; ++q)
        if (*q == 'e' || *q == 'E') tiny = q + 1 < end_d && q[1] == '-';
      out = tiny ? (negative ? -0.0f : 0.0f)
                 : (negative ? -std::numeric_limits<float>::infinity() : std::numeric_limits<float>::infinity());
      return end_d;
    }
  }
  return nullptr;
}

// Parses a signed integer from [first, last) (leading '+' accepted). nullptr when none or out of range.
inline const char* parse_int(const char* first, const char* last, std::int64_t& out) {
  const char* p = first;
  if (p < last && *p == '+') {
    ++p;
    if (p < last && *p == '-') return nullptr;
  }
  auto [end, ec] = std::from_chars(p, last, out);
  return ec == std::errc{} ? end : nullptr;
}

// The offending input for an error message: at most `max_chars`, non-printable bytes as \xNN.
inline std::string quote_excerpt(std::string_view s, std::size_t max_chars = 40) {
  std::string out = "'";
  std::size_t n = 0;
  for (char c : s) {
    if (n == max_chars) {
      out += "...";
      break;
    }
    auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7f) {
      out += c;
    } else {
      static constexpr char hex[] = "0123456789abcdef";
      out += "\\x";
      out += hex[u >> 4];
      out += hex[u & 15];
    }
    ++n;
  }
  out += "'";
  return out;
}

// How a reader's messages show the file's own bytes (MeshReadOptions::quote_file_text). Quoting
// off, a message keeps where and what was expected and says only how long the bytes were: a
// client must not be able to read a file through the errors of a reader pointed at it.
class FileQuote {
 public:
  explicit FileQuote(bool quote) : quote_(quote) {}

  bool quoting() const { return quote_; }

  // A piece of the file: an excerpt in quotes, or e.g. "a token of 7 bytes" for noun "a token".
  std::string text(std::string_view s, std::string_view noun) const {
    if (quote_) return quote_excerpt(s);
    return fmt::format("{} of {} byte{}", noun, s.size(), s.size() == 1 ? "" : "s");
  }

  // A value stored in the file, to follow its noun: " 12", or nothing ("vertex index{} is ...").
  template <class T>
  std::string value(const T& v) const {
    return quote_ ? fmt::format(" {}", v) : std::string();
  }

  // `s` formatted (it holds file values) when quoting, else `neutral`.
  std::string either(std::string s, std::string_view neutral) const { return quote_ ? std::move(s) : std::string(neutral); }

 private:
  bool quote_;
};

}  // namespace lamina::io_detail
