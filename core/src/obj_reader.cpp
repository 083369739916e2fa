// Wavefront OBJ: geometry only. `v x y z [w | r g b]` and `f` with `v`, `v/vt`, `v//vn` or
// `v/vt/vn` corners (1-based, or negative = relative to the vertices read so far). Faces with more
// than three corners are ear-clipped in their best-fit plane. Texture, normal, grouping and
// material statements are skipped; other statements are counted in a note.
#include "ear_clipping.hpp"
#include "lamina/core/mesh_io.hpp"
#include "mesh_io_text.hpp"

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

Error parse_error(std::string_view name, std::size_t line, std::string message) {
  return Error{ErrorCode::parse_error, fmt::format("{}:{}: OBJ: {}", name, line, message)};
}

// Splits a line into whitespace-separated tokens, one at a time.
struct Tokens {
  const char* p;
  const char* end;
  std::string_view next() {
    while (p < end && detail::is_space(*p)) ++p;
    const char* b = p;
    while (p < end && !detail::is_space(*p)) ++p;
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

}  // namespace

std::expected<TriangleSoup, Error> parse_obj(std::string_view text, std::string_view name) {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::uint32_t> indices;  // 0-based; positive ones checked against the final count
  std::vector<Face> faces;
  vertices.reserve(text.size() / 64 + 1);
  indices.reserve(text.size() / 16 + 1);
  faces.reserve(text.size() / 64 + 1);

  std::size_t non_finite = 0;
  std::size_t unknown_statements = 0;
  std::size_t first_unknown_line = 0;
  std::string first_unknown;

  const char* p = text.data();
  const char* const text_end = text.data() + text.size();
  if (text.starts_with("\xEF\xBB\xBF")) p += 3;
  // Lines end with LF (or CRLF: the CR is whitespace); a file without any LF but with CRs uses
  // classic Mac CR line ends.
  const std::string_view body(p, static_cast<std::size_t>(text_end - p));
  const char eol_char = body.find('\n') == std::string_view::npos && body.find('\r') != std::string_view::npos ? '\r' : '\n';
  std::size_t line = 0;
  while (p < text_end) {
    ++line;
    const char* eol = static_cast<const char*>(std::memchr(p, eol_char, static_cast<std::size_t>(text_end - p)));
    if (eol == nullptr) eol = text_end;
    const char* line_end = eol;
    if (const void* hash = std::memchr(p, '#', static_cast<std::size_t>(line_end - p)))
      line_end = static_cast<const char*>(hash);
    Tokens tok{p, line_end};
    p = eol < text_end ? eol + 1 : text_end;

    const std::string_view kw = tok.next();
    if (kw.empty()) continue;

    if (kw == "v") {
      float c[3];
      for (float& value : c) {
        const std::string_view t = tok.next();
        if (t.empty())
          return std::unexpected(parse_error(name, line, "vertex with fewer than 3 coordinates"));
        const char* end = detail::parse_float(t.data(), t.data() + t.size(), value);
        if (end != t.data() + t.size())
          return std::unexpected(
              parse_error(name, line, fmt::format("expected a vertex coordinate, found {}", detail::quote_excerpt(t))));
        non_finite += !std::isfinite(value);
      }
      vertices.emplace_back(c[0], c[1], c[2]);
      continue;
    }

    if (kw == "f") {
      Face face{indices.size(), 0, line};
      for (std::string_view t = tok.next(); !t.empty(); t = tok.next()) {
        std::int64_t index = 0;
        const char* t_end = t.data() + t.size();
        const char* end = detail::parse_int(t.data(), t_end, index);
        bool well_formed = end != nullptr && (end == t_end || *end == '/');
        for (const char* q = end; well_formed && q < t_end; ++q)
          well_formed = (*q >= '0' && *q <= '9') || *q == '/' || *q == '-' || *q == '+';
        if (!well_formed)
          return std::unexpected(parse_error(
              name, line, fmt::format("expected a face corner (v, v/vt, v//vn or v/vt/vn), found {}",
                                      detail::quote_excerpt(t))));
        if (index == 0)
          return std::unexpected(parse_error(name, line, "vertex index 0 is invalid (OBJ indices start at 1)"));
        std::int64_t resolved = index > 0 ? index - 1 : static_cast<std::int64_t>(vertices.size()) + index;
        if (resolved < 0)
          return std::unexpected(parse_error(
              name, line, fmt::format("relative vertex index {} is out of range ({} vertices defined so far)", index,
                                      vertices.size())));
        if (resolved > std::int64_t{UINT32_MAX - 1})
          return std::unexpected(parse_error(name, line, fmt::format("vertex index {} is out of range", index)));
        indices.push_back(static_cast<std::uint32_t>(resolved));
        ++face.size;
      }
      if (face.size < 3)
        return std::unexpected(
            parse_error(name, line, fmt::format("face with {} vertices (at least 3 needed)", face.size)));
      faces.push_back(face);
      continue;
    }

    if (!is_skipped_statement(kw)) {
      if (unknown_statements++ == 0) {
        first_unknown = std::string(kw.substr(0, 40));
        first_unknown_line = line;
      }
    }
  }

  if (faces.empty()) {
    return std::unexpected(Error{ErrorCode::empty_mesh,
                                 fmt::format("{}: OBJ has no faces ({} vertices)", name, vertices.size())});
  }

  TriangleSoup soup;
  soup.format = "obj";
  std::size_t triangle_total = 0;
  for (const Face& f : faces) triangle_total += f.size - 2;
  soup.corners.reserve(3 * triangle_total);

  std::vector<Eigen::Vector3f> polygon;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  detail::EarClippingScratch scratch;
  std::size_t polygons = 0;
  for (const Face& f : faces) {
    for (std::uint32_t k = 0; k < f.size; ++k) {
      const std::uint32_t index = indices[f.first + k];
      if (index >= vertices.size()) {
        return std::unexpected(parse_error(
            name, f.line, fmt::format("vertex index {} is out of range (the file defines {} vertices)",
                                      std::uint64_t{index} + 1, vertices.size())));
      }
    }
    const std::uint32_t* idx = indices.data() + f.first;
    if (f.size == 3) {
      for (int k = 0; k < 3; ++k) soup.corners.push_back(vertices[idx[k]]);
      continue;
    }
    ++polygons;
    polygon.clear();
    for (std::uint32_t k = 0; k < f.size; ++k) polygon.push_back(vertices[idx[k]]);
    triangles.clear();
    detail::triangulate_polygon(polygon, triangles, scratch);
    for (const auto& t : triangles)
      for (std::uint32_t k : t) soup.corners.push_back(polygon[k]);
  }

  if (polygons > 0) {
    soup.notes.push_back({"polygons_triangulated",
                          fmt::format("{}: {} faces with more than 3 vertices were triangulated", name, polygons)});
  }
  if (unknown_statements > 0) {
    soup.notes.push_back(
        {"unknown_statements", fmt::format("{}: {} unrecognised statements ignored (first: {} on line {})", name,
                                           unknown_statements, detail::quote_excerpt(first_unknown),
                                           first_unknown_line)});
  }
  if (non_finite > 0) {
    soup.notes.push_back({"non_finite_coordinates",
                          fmt::format("{}: {} vertex coordinates are NaN or infinite (kept as read)", name,
                                      non_finite)});
  }
  return soup;
}

}  // namespace lamina
