#pragma once
// Private pieces of the STL reader: the two format parsers and the stored-normal statistics
// they share. parse_stl (stl_reader.cpp) decides which parser a file goes to.
#include "lamina/core/error.hpp"
#include "lamina/core/triangle_soup.hpp"

#include <cmath>
#include <cstddef>
#include <expected>
#include <span>
#include <string_view>
#include <vector>

namespace lamina::detail {

// Stored facet normals are not used for geometry, but they say something about the exporter.
struct StlNormalStats {
  std::size_t count = 0;
  std::size_t zero = 0;      // exactly (0, 0, 0)
  std::size_t not_unit = 0;  // non-zero with | |n| − 1 | > tolerance, or not finite
  float min_length = 0.0f;   // range of the lengths counted in not_unit
  float max_length = 0.0f;

  static constexpr float unit_tolerance = 1e-3f;

  void add(float x, float y, float z) {
    ++count;
    if (x == 0.0f && y == 0.0f && z == 0.0f) {
      ++zero;
      return;
    }
    // |n|² − 1 ≈ 2(|n| − 1): compare squared lengths, take the root only for the rare outlier.
    const float len2 = x * x + y * y + z * z;
    if (!(std::fabs(len2 - 1.0f) <= 2.0f * unit_tolerance)) {
      const float len = std::sqrt(len2);
      if (not_unit++ == 0) {
        min_length = max_length = len;
      } else {
        min_length = std::fmin(min_length, len);
        max_length = std::fmax(max_length, len);
      }
    }
  }

  // Appends "stored_normals_zero" (every normal zero) or "stored_normals_not_unit" notes.
  void append_notes(std::vector<ReadNote>& notes, std::string_view name) const;
};

// Count of float coordinates that are NaN or infinite (kept as they are; noted once).
void append_non_finite_note(std::vector<ReadNote>& notes, std::string_view name, std::size_t non_finite_values,
                            std::size_t triangles_affected);

// `bytes` is known to hold at least 84 + 50·n bytes (n = the count at byte 80).
std::expected<TriangleSoup, Error> parse_stl_binary(std::span<const std::byte> bytes, std::string_view name);

// `text` starts (after optional whitespace / BOM) with the keyword "solid".
std::expected<TriangleSoup, Error> parse_stl_ascii(std::string_view text, std::string_view name);

}  // namespace lamina::detail
