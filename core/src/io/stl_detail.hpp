#pragma once
// Private pieces of the STL reader: the content probe that tells binary from ASCII, the binary
// record decoder (used whole by parse_stl, chunk by chunk by read_mesh_file), the ASCII parser,
// and the stored-normal statistics both formats note.
#include "lamina/core/error.hpp"
#include "lamina/core/triangle_soup.hpp"
#include "io/mesh_io_text.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <expected>
#include <span>
#include <string_view>
#include <vector>

namespace lamina::io_detail {

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

  // Appends "stored_normals_zero" (every normal zero) or "stored_normals_not_unit" notes (with
  // the range of lengths only when quoting: they are the file's values).
  void append_notes(std::vector<ReadNote>& notes, std::string_view name, const FileQuote& quote) const;
};

// Count of float coordinates that are NaN or infinite (kept as they are; noted once).
void append_non_finite_note(std::vector<ReadNote>& notes, std::string_view name, std::size_t non_finite_values,
                            std::size_t triangles_affected);

inline constexpr std::size_t kStlHeaderBytes = 80;
inline constexpr std::size_t kStlPreambleBytes = 84;  // header + triangle count
inline constexpr std::size_t kStlTriangleBytes = 50;  // normal, 3 corners (12 float32) + 2-byte attribute
inline constexpr std::size_t kStlTextProbeBytes = 512;

// What the first bytes and the size of a file say about it as an STL.
struct StlProbe {
  bool text_prefix = false;    // no control characters (but whitespace) in the first 512 bytes
  bool ascii_like = false;     // ... and it starts with the keyword "solid"
  std::uint64_t declared = 0;  // the count at byte 80 (0 when the file is shorter than 84 bytes)
  bool binary_fits = false;    // 84 + 50·declared ≤ size
};

// `prefix`: the first min(size, 512) bytes of the file, or more; `size`: the whole file's.
StlProbe probe_stl(std::span<const std::byte> prefix, std::uint64_t size);

// Turns binary STL triangle records into a soup, in whole records, in file order, as many
// calls as convenient (parse_stl: one call; read_mesh_file: one per chunk read).
class StlBinaryDecoder {
 public:
  explicit StlBinaryDecoder(std::uint32_t count);  // count > 0

  // Decodes n whole 50-byte records; at most count − decoded() of them.
  void decode(const std::byte* records, std::size_t n);
  std::size_t decoded() const { return done_; }

  // Notes (trailing bytes past the records, stored normals, non-finite values) and the soup.
  TriangleSoup finish(std::string_view name, std::uint64_t file_size, const FileQuote& quote) &&;

 private:
  TriangleSoup soup_;
  std::uint32_t count_;
  std::size_t done_ = 0;
  StlNormalStats normals_;
  std::size_t non_finite_ = 0;
  std::size_t non_finite_triangles_ = 0;
};

// The error for a binary STL shorter than its count says (an implausible count says "not STL").
// The count is the file's bytes 80-83: named only when quoting.
Error stl_short_binary_error(std::string_view name, std::uint64_t declared, std::uint64_t size, const FileQuote& quote);

// `bytes` holds at least 84 + 50·n bytes (n = the count at byte 80, > 0).
std::expected<TriangleSoup, Error> parse_stl_binary(std::span<const std::byte> bytes, std::string_view name,
                                                    const FileQuote& quote);

// `text` starts (after optional whitespace / BOM) with the keyword "solid".
std::expected<TriangleSoup, Error> parse_stl_ascii(std::string_view text, std::string_view name,
                                                   const FileQuote& quote);

}  // namespace lamina::io_detail
