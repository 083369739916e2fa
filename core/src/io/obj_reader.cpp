// Wavefront OBJ: geometry only. `v x y z [w | r g b]` and `f` with `v`, `v/vt`, `v//vn` or
// `v/vt/vn` corners (1-based, or negative = relative to the vertices read so far). Faces with more
// than three corners are ear-clipped in their best-fit plane. Texture, normal, grouping and
// material statements are skipped; other statements are counted in a note.
#include "geometry/ear_clipping.hpp"
#include "lamina/core/mesh_io.hpp"
#include "io/mesh_io_text.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

namespace lamina {
namespace {

struct Face {
  std::size_t first;  // into the flat index list
  std::uint32_t size;
  std::size_t line;
};

// What the statements of a file hold, before the faces are checked and triangulated.
struct ObjStatements {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::uint32_t> indices;  // 0-based; positive ones checked against the final count
  std::vector<Face> faces;
  std::size_t non_finite = 0;
  std::size_t unknown_statements = 0;
  std::size_t first_unknown_line = 0;
  std::string first_unknown;
};

Error parse_error(std::string_view name, std::size_t line, std::string message) {
  return Error{ErrorCode::parse_error, fmt::format("{}:{}: OBJ: {}", name, line, message)};
}

// Splits a line into whitespace-separated tokens, one at a time.
struct Tokens {
  const char* p;
  const char* end;
  std::string_view next() {
    while (p < end && io_detail::is_space(*p)) ++p;
    const char* b = p;
    while (p < end && !io_detail::is_space(*p)) ++p;
    return {b, static_cast<std::size_t>(p - b)};
  }
};

bool is_skipped_statement(std::string_view kw) {
  static constexpr std::string_view skipped[] = {"vt", "vn",     "vp",     "o",     "g",      "s",
                                                 "l",  "p",      "usemtl", "mtllib", "usemap", "maplib",
                                                 "mg", "lod",    "bevel",  "c_interp", "d_interp", "shadow_obj",
                                                 "trace_obj", "cstype", "deg", "bmat", "step", "curv", "curv2",
                                                 "surf", "parm", "trim", "hole", "scrv", "sp", "end", "con"};
  for (std::string_view s : skipped)
    if (kw == s) return true;
  return false;
}

// The parser of one file's statements; every error names the line.
class ObjParser {
 public:
  ObjParser(std::string_view text, std::string_view name, const io_detail::FileQuote& quote)
      : text_(text), name_(name), quote_(quote) {
    out_.vertices.reserve(text.size() / 64 + 1);
    out_.indices.reserve(text.size() / 16 + 1);
    out_.faces.reserve(text.size() / 64 + 1);
  }

  std::expected<ObjStatements, Error> parse() && {
    const char* p = text_.data();
    const char* const text_end = text_.data() + text_.size();
    if (text_.starts_with("\xEF\xBB\xBF")) p += 3;
    // Lines end with LF (or CRLF: the CR is whitespace); a file without any LF but with CRs uses
    // classic Mac CR line ends.
    const std::string_view body(p, static_cast<std::size_t>(text_end - p));
    const char eol_char =
        body.find('\n') == std::string_view::npos && body.find('\r') != std::string_view::npos ? '\r' : '\n';
    while (p < text_end) {
      ++line_;
      const char* eol = static_cast<const char*>(std::memchr(p, eol_char, static_cast<std::size_t>(text_end - p)));
      if (eol == nullptr) eol = text_end;
      const char* line_end = eol;
      if (const void* hash = std::memchr(p, '#', static_cast<std::size_t>(line_end - p)))
        line_end = static_cast<const char*>(hash);
      Tokens tok{p, line_end};
      p = eol < text_end ? eol + 1 : text_end;
      if (auto r = statement(tok); !r) return std::unexpected(std::move(r.error()));
    }
    return std::move(out_);
  }

 private:
  std::expected<void, Error> statement(Tokens& tok) {
    const std::string_view kw = tok.next();
    if (kw.empty()) return {};
    if (kw == "v") return vertex(tok);
    if (kw == "f") return face(tok);
    if (!is_skipped_statement(kw) && out_.unknown_statements++ == 0) {
      out_.first_unknown = std::string(kw.substr(0, 40));
      out_.first_unknown_line = line_;
    }
    return {};
  }

  std::expected<void, Error> vertex(Tokens& tok) {
    float c[3];
    for (float& value : c) {
      const std::string_view t = tok.next();
      if (t.empty()) return std::unexpected(parse_error(name_, line_, "vertex with fewer than 3 coordinates"));
      const char* end = io_detail::parse_float(t.data(), t.data() + t.size(), value);
      if (end != t.data() + t.size()) {
        return std::unexpected(parse_error(
            name_, line_, fmt::format("expected a vertex coordinate, found {}", quote_.text(t, "a token"))));
      }
      out_.non_finite += !std::isfinite(value);
    }
    out_.vertices.emplace_back(c[0], c[1], c[2]);
    return {};
  }

  std::expected<void, Error> face(Tokens& tok) {
    Face face{out_.indices.size(), 0, line_};
    for (std::string_view t = tok.next(); !t.empty(); t = tok.next()) {
      std::int64_t index = 0;
      const char* t_end = t.data() + t.size();
      const char* end = io_detail::parse_int(t.data(), t_end, index);
      bool well_formed = end != nullptr && (end == t_end || *end == '/');
      for (const char* q = end; well_formed && q < t_end; ++q)
        well_formed = (*q >= '0' && *q <= '9') || *q == '/' || *q == '-' || *q == '+';
      if (!well_formed) {
        return std::unexpected(parse_error(name_, line_,
                                           fmt::format("expected a face corner (v, v/vt, v//vn or v/vt/vn), found {}",
                                                       quote_.text(t, "a token"))));
      }
      if (index == 0)
        return std::unexpected(parse_error(name_, line_, "vertex index 0 is invalid (OBJ indices start at 1)"));
      const std::int64_t resolved = index > 0 ? index - 1 : static_cast<std::int64_t>(out_.vertices.size()) + index;
      if (resolved < 0) {
        return std::unexpected(
            parse_error(name_, line_,
                        fmt::format("relative vertex index{} is out of range ({} vertices defined so far)",
                                    quote_.value(index), out_.vertices.size())));
      }
      if (resolved > std::int64_t{UINT32_MAX - 1})
        return std::unexpected(
            parse_error(name_, line_, fmt::format("vertex index{} is out of range", quote_.value(index))));
      out_.indices.push_back(static_cast<std::uint32_t>(resolved));
      ++face.size;
    }
    if (face.size < 3)
      return std::unexpected(
          parse_error(name_, line_, fmt::format("face with {} vertices (at least 3 needed)", face.size)));
    out_.faces.push_back(face);
    return {};
  }

  std::string_view text_;
  std::string_view name_;
  io_detail::FileQuote quote_;
  ObjStatements out_;
  std::size_t line_ = 0;
};

// Every face's triangles, corners copied from the vertices; polygons ear-clipped.
std::expected<TriangleSoup, Error> triangulate_faces(const ObjStatements& in, std::string_view name,
                                                     const io_detail::FileQuote& quote, std::size_t& polygons) {
  TriangleSoup soup;
  soup.format = "obj";
  std::size_t triangle_total = 0;
  for (const Face& f : in.faces) triangle_total += f.size - 2;
  soup.corners.reserve(3 * triangle_total);

  std::vector<Eigen::Vector3f> polygon;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  geometry_detail::EarClippingScratch scratch;
  for (const Face& f : in.faces) {
    const std::uint32_t* idx = in.indices.data() + f.first;
    for (std::uint32_t k = 0; k < f.size; ++k) {
      if (idx[k] >= in.vertices.size()) {
        return std::unexpected(parse_error(
            name, f.line, fmt::format("vertex index{} is out of range (the file defines {} vertices)",
                                      quote.value(std::uint64_t{idx[k]} + 1), in.vertices.size())));
      }
    }
    if (f.size == 3) {
      for (int k = 0; k < 3; ++k) soup.corners.push_back(in.vertices[idx[k]]);
      continue;
    }
    ++polygons;
    polygon.clear();
    for (std::uint32_t k = 0; k < f.size; ++k) polygon.push_back(in.vertices[idx[k]]);
    triangles.clear();
    if (!geometry_detail::triangulate_polygon(polygon, triangles, scratch)) {
      return std::unexpected(Error{
          ErrorCode::limit_exceeded,
          fmt::format("{}:{}: OBJ: the face of {} corners could not be triangulated within the work bound (it "
                      "crosses itself or is as jagged as noise); split it into smaller faces",
                      name, f.line, f.size)});
    }
    for (const auto& t : triangles)
      for (std::uint32_t k : t) soup.corners.push_back(polygon[k]);
  }
  return soup;
}

void append_notes(TriangleSoup& soup, const ObjStatements& in, std::size_t polygons, std::string_view name,
                  const io_detail::FileQuote& quote) {
  if (polygons > 0) {
    soup.notes.push_back({"polygons_triangulated",
                          fmt::format("{}: {} faces with more than 3 vertices were triangulated", name, polygons)});
  }
  if (in.unknown_statements > 0) {
    const std::string first = quote.either(fmt::format("{} on line {}", io_detail::quote_excerpt(in.first_unknown),
                                                       in.first_unknown_line),
                                           fmt::format("on line {}", in.first_unknown_line));
    soup.notes.push_back({"unknown_statements", fmt::format("{}: {} unrecognised statements ignored (first: {})", name,
                                                            in.unknown_statements, first)});
  }
  if (in.non_finite > 0) {
    soup.notes.push_back({"non_finite_coordinates",
                          fmt::format("{}: {} vertex coordinates are NaN or infinite (kept as read)", name,
                                      in.non_finite)});
  }
}

}  // namespace

std::expected<TriangleSoup, Error> parse_obj(std::string_view text, std::string_view name,
                                             const MeshReadOptions& options) {
  const io_detail::FileQuote quote(options.quote_file_text);
  auto statements = ObjParser(text, name, quote).parse();
  if (!statements) return std::unexpected(std::move(statements.error()));
  if (statements->faces.empty()) {
    return std::unexpected(Error{ErrorCode::empty_mesh, fmt::format("{}: OBJ has no faces ({} vertices)", name,
                                                                    statements->vertices.size())});
  }
  std::size_t polygons = 0;
  auto soup = triangulate_faces(*statements, name, quote, polygons);
  if (!soup) return soup;
  append_notes(*soup, *statements, polygons, name, quote);
  return soup;
}

}  // namespace lamina
