// ASCII STL: one or more blocks of
//   solid [name] { facet normal nx ny nz  outer loop  vertex x y z ×3  endloop  endfacet } endsolid [name]
// Keywords in any case, any whitespace between tokens (CRLF included). A single pointer scan with
// std::from_chars for the numbers; every error names the line and what was expected there.
#include "io/mesh_io_text.hpp"
#include "io/stl_detail.hpp"

#include <fmt/format.h>

#include <cmath>
#include <string>

namespace lamina::io_detail {
namespace {

class Scanner {
 public:
  Scanner(std::string_view text, std::string_view name, const FileQuote& quote)
      : p_(text.data()), end_(text.data() + text.size()), name_(name), quote_(quote) {
    if (text.starts_with("\xEF\xBB\xBF")) p_ += 3;
  }

  // Skips whitespace (counting lines); true if a token follows.
  bool skip_space() {
    while (p_ < end_) {
      const char c = *p_;
      if (c == '\n') {
        ++line_;
      } else if (!is_space(c)) {
        return true;
      }
      ++p_;
    }
    return false;
  }

  std::string_view next_token() {
    skip_space();
    const char* begin = p_;
    while (p_ < end_ && !is_space(*p_)) ++p_;
    return {begin, static_cast<std::size_t>(p_ - begin)};
  }

  // The rest of the current line, trimmed (solid / endsolid names).
  std::string_view rest_of_line() {
    while (p_ < end_ && *p_ != '\n' && is_space(*p_)) ++p_;
    const char* begin = p_;
    while (p_ < end_ && *p_ != '\n') ++p_;
    const char* last = p_;
    while (last > begin && is_space(last[-1])) --last;
    return {begin, static_cast<std::size_t>(last - begin)};
  }

  // The name after "solid": the rest of the line, but stopping before a "facet" or "endsolid"
  // token, so that a whole STL written on one line still parses.
  std::string_view solid_name() {
    while (p_ < end_ && *p_ != '\n' && is_space(*p_)) ++p_;
    const char* begin = p_;
    const char* last = p_;
    while (p_ < end_ && *p_ != '\n') {
      const char* tok = p_;
      while (p_ < end_ && !is_space(*p_)) ++p_;
      const std::string_view word(tok, static_cast<std::size_t>(p_ - tok));
      if (iequals(word, "facet") || iequals(word, "endsolid")) {
        p_ = tok;
        break;
      }
      last = p_;
      while (p_ < end_ && *p_ != '\n' && is_space(*p_)) ++p_;
    }
    return {begin, static_cast<std::size_t>(last - begin)};
  }

  // Expects the keyword `lower` (case-insensitive).
  bool expect(std::string_view lower, Error& error) {
    std::string_view tok = next_token();
    if (iequals(tok, lower)) return true;
    error = unexpected_token(tok, fmt::format("'{}'", lower));
    return false;
  }

  bool read_float(float& out, std::string_view what, Error& error) {
    if (!skip_space()) {
      error = unexpected_token({}, what);
      return false;
    }
    const char* end = parse_float(p_, end_, out);
    if (end == nullptr || (end < end_ && !is_space(*end))) {
      const char* tok_end = p_;
      while (tok_end < end_ && !is_space(*tok_end)) ++tok_end;
      error = unexpected_token({p_, static_cast<std::size_t>(tok_end - p_)}, what);
      return false;
    }
    p_ = end;
    return true;
  }

  Error unexpected_token(std::string_view tok, std::string_view expected) const {
    if (tok.empty()) {
      return Error{ErrorCode::parse_error, fmt::format("{}:{}: ASCII STL: unexpected end of file, expected {}",
                                                       name_, line_, expected)};
    }
    return Error{ErrorCode::parse_error,
                 fmt::format("{}:{}: ASCII STL: expected {}, found {}", name_, line_, expected,
                             quote_.text(tok, "a token"))};
  }

  // True when only whitespace and NUL padding remain.
  bool only_padding_left() {
    for (;;) {
      if (!skip_space()) return true;
      if (*p_ != '\0') return false;
      ++p_;
    }
  }

  std::size_t line() const { return line_; }
  std::size_t remaining() const { return static_cast<std::size_t>(end_ - p_); }

 private:
  const char* p_;
  const char* end_;
  std::string_view name_;
  FileQuote quote_;
  std::size_t line_ = 1;
};

struct Solid {
  std::string name;
  std::size_t facets = 0;
};

// "'a' 12 facets, 'b' 3 facets" (names only when quoting: they are the file's text).
std::string solid_list(const std::vector<Solid>& solids, const FileQuote& quote) {
  std::string parts;
  for (const Solid& s : solids) {
    if (!parts.empty()) parts += ", ";
    if (quote.quoting()) parts += fmt::format("'{}' ", s.name);
    parts += fmt::format("{} facets", s.facets);
  }
  return parts;
}

}  // namespace

std::expected<TriangleSoup, Error> parse_stl_ascii(std::string_view text, std::string_view name,
                                                   const FileQuote& quote) {
  TriangleSoup soup;
  soup.format = "stl-ascii";
  // A facet takes at least ~ 100 bytes of text; reserving from that avoids most regrowth.
  soup.corners.reserve(3 * (text.size() / 128 + 1));

  Scanner in(text, name, quote);
  StlNormalStats normals;
  std::size_t non_finite = 0;
  std::size_t non_finite_triangles = 0;
  std::vector<Solid> solids;
  bool missing_endsolid = false;
  Error error{ErrorCode::parse_error, {}};

  for (;;) {
    // "solid [name]"
    if (std::string_view tok = in.next_token(); !iequals(tok, "solid")) {
      return std::unexpected(in.unexpected_token(tok, solids.empty() ? "'solid'" : "'solid' or end of file"));
    }
    Solid solid{std::string(in.solid_name()), 0};

    for (;;) {
      std::string_view tok = in.next_token();
      if (tok.empty()) {  // end of file without "endsolid": tolerated, noted
        missing_endsolid = true;
        break;
      }
      if (iequals(tok, "endsolid")) {
        in.rest_of_line();
        break;
      }
      if (!iequals(tok, "facet")) return std::unexpected(in.unexpected_token(tok, "'facet' or 'endsolid'"));

      float n[3];
      if (!in.expect("normal", error)) return std::unexpected(error);
      for (float& v : n)
        if (!in.read_float(v, "a normal component", error)) return std::unexpected(error);
      normals.add(n[0], n[1], n[2]);

      if (!in.expect("outer", error) || !in.expect("loop", error)) return std::unexpected(error);
      unsigned bad = 0;
      for (int k = 0; k < 3; ++k) {
        float c[3];
        if (!in.expect("vertex", error)) return std::unexpected(error);
        for (float& v : c) {
          if (!in.read_float(v, "a vertex coordinate", error)) return std::unexpected(error);
          bad += !std::isfinite(v);
        }
        soup.corners.emplace_back(c[0], c[1], c[2]);
      }
      non_finite += bad;
      non_finite_triangles += bad != 0;
      if (!in.expect("endloop", error) || !in.expect("endfacet", error)) return std::unexpected(error);
      ++solid.facets;
    }
    solids.push_back(std::move(solid));
    if (missing_endsolid || in.only_padding_left()) break;
  }

  if (soup.corners.empty()) {
    return std::unexpected(Error{ErrorCode::empty_mesh, fmt::format("{}: ASCII STL with no facets", name)});
  }
  if (missing_endsolid) {
    soup.notes.push_back({"missing_endsolid", fmt::format("{}:{}: ASCII STL ends without 'endsolid' (after {} facets)",
                                                          name, in.line(), solids.back().facets)});
  }
  if (solids.size() > 1) {
    soup.notes.push_back(
        {"multiple_solids", fmt::format("{}: {} solid blocks: {}", name, solids.size(), solid_list(solids, quote))});
  }
  normals.append_notes(soup.notes, name, quote);
  append_non_finite_note(soup.notes, name, non_finite, non_finite_triangles);
  return soup;
}

}  // namespace lamina::io_detail
