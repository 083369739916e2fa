// parse_stl: decides between binary and ASCII STL from the content, then hands over.
//
// Binary is recognised by its size (84 + 50·n ≤ file size, n = the 32-bit count at byte 80), not
// by the first word: several real binary files start their 80-byte header with "solid".
#include "lamina/core/mesh_io.hpp"
#include "io/mesh_io_text.hpp"
#include "io/stl_detail.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>

namespace lamina {
namespace {

// A count above this (a 5 GB file) in a file too short for it says "some other binary format"
// rather than "a truncated STL".
constexpr std::uint64_t kImplausibleTriangles = 100'000'000;

std::uint32_t read_u32_le(const std::byte* p) {
  const auto b = [p](int i) { return static_cast<std::uint32_t>(std::to_integer<unsigned char>(p[i])); };
  return b(0) | (b(1) << 8) | (b(2) << 16) | (b(3) << 24);
}

// True when the first bytes contain no control character other than whitespace (bytes ≥ 0x80 are
// allowed: names may be UTF-8). Binary STL data almost always has 0x00 bytes within them.
bool prefix_is_text(std::string_view text) {
  const std::size_t n = std::min(text.size(), io_detail::kStlTextProbeBytes);
  for (std::size_t i = 0; i < n; ++i) {
    auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 && !io_detail::is_space(static_cast<char>(c))) return false;
    if (c == 0x7f) return false;
  }
  return true;
}

std::string_view skip_bom_and_space(std::string_view text) {
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  std::size_t i = 0;
  while (i < text.size() && io_detail::is_space(text[i])) ++i;
  return text.substr(i);
}

bool starts_with_solid_keyword(std::string_view text) {
  std::string_view t = skip_bom_and_space(text);
  return io_detail::istarts_with(t, "solid") && (t.size() == 5 || io_detail::is_space(t[5]));
}

}  // namespace

namespace io_detail {

void StlNormalStats::append_notes(std::vector<ReadNote>& notes, std::string_view name,
                                  const FileQuote& quote) const {
  if (count == 0) return;
  if (zero == count) {
    notes.push_back({"stored_normals_zero",
                     fmt::format("{}: all {} stored facet normals are (0, 0, 0); normals come from the winding",
                                 name, count)});
    return;
  }
  if (not_unit > 0 || zero > 0) {
    const std::string lengths = not_unit > 0 && quote.quoting()
                                    ? fmt::format(", lengths {:.3g} to {:.3g}", min_length, max_length)
                                    : std::string();
    notes.push_back({"stored_normals_not_unit",
                     fmt::format("{}: {} of {} stored facet normals are not unit length ({} zero{}); normals come "
                                 "from the winding",
                                 name, not_unit + zero, count, zero, lengths)});
  }
}

StlProbe probe_stl(std::span<const std::byte> prefix, std::uint64_t size) {
  StlProbe probe;
  const std::string_view text(reinterpret_cast<const char*>(prefix.data()), prefix.size());
  probe.text_prefix = prefix_is_text(text);
  probe.ascii_like = probe.text_prefix && starts_with_solid_keyword(text.substr(0, kStlTextProbeBytes));
  if (size >= kStlPreambleBytes && prefix.size() >= kStlPreambleBytes) {
    probe.declared = read_u32_le(prefix.data() + kStlHeaderBytes);
    probe.binary_fits = kStlPreambleBytes + kStlTriangleBytes * probe.declared <= size;
  }
  return probe;
}

Error stl_short_binary_error(std::string_view name, std::uint64_t declared, std::uint64_t size,
                             const FileQuote& quote) {
  const std::uint64_t needed = kStlPreambleBytes + kStlTriangleBytes * declared;
  // The count is bytes 80-83 of the file: without quoting, only that it is too large.
  const std::string count = quote.either(fmt::format("{} triangles ({} bytes)", declared, needed),
                                         "more triangles (its count at byte 80)");
  const std::string in_file = quote.either(fmt::format("in a file of {} bytes", size),
                                           fmt::format("than a file of {} bytes holds", size));
  if (declared > kImplausibleTriangles) {
    return Error{ErrorCode::unknown_format,
                 fmt::format("{}: not an STL file: not text, and read as binary STL it would declare {} {}", name,
                             count, in_file)};
  }
  const std::uint64_t complete = size < kStlPreambleBytes ? 0 : (size - kStlPreambleBytes) / kStlTriangleBytes;
  const std::string has = quote.either(fmt::format("but the file has {} bytes", size),
                                       fmt::format("than the file's {} bytes hold", size));
  return Error{ErrorCode::truncated_file,
               fmt::format("{}: binary STL declares {} {}: {} complete triangles present (truncated, or not an STL "
                           "file)",
                           name, count, has, complete)};
}

void append_non_finite_note(std::vector<ReadNote>& notes, std::string_view name, std::size_t non_finite_values,
                            std::size_t triangles_affected) {
  if (non_finite_values == 0) return;
  notes.push_back({"non_finite_coordinates",
                   fmt::format("{}: {} corner coordinates in {} triangles are NaN or infinite (kept as read)", name,
                               non_finite_values, triangles_affected)});
}

}  // namespace detail

std::expected<TriangleSoup, Error> parse_stl(std::span<const std::byte> bytes, std::string_view name,
                                             const MeshReadOptions& options) {
  const io_detail::FileQuote quote(options.quote_file_text);
  const std::size_t size = bytes.size();
  if (size == 0) return std::unexpected(Error{ErrorCode::empty_mesh, fmt::format("{}: the file is empty", name)});

  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), size);
  const io_detail::StlProbe probe = io_detail::probe_stl(bytes, size);
  if (probe.ascii_like) {
    auto ascii = io_detail::parse_stl_ascii(text, name, quote);
    // A text-looking header whose size still matches a binary layout: trust the size.
    if (ascii || !probe.binary_fits) return ascii;
    return io_detail::parse_stl_binary(bytes, name, quote);
  }
  if (probe.binary_fits) return io_detail::parse_stl_binary(bytes, name, quote);

  if (probe.text_prefix) {
    const std::string start =
        quote.either(fmt::format(" (starts with {})", io_detail::quote_excerpt(skip_bom_and_space(text).substr(0, 24))), "");
    return std::unexpected(Error{
        ErrorCode::unknown_format, fmt::format("{}: not an STL file: text that does not start with 'solid'{}", name, start)});
  }
  if (size < io_detail::kStlPreambleBytes) {
    return std::unexpected(
        Error{ErrorCode::unknown_format,
              fmt::format("{}: not an STL file: {} bytes is shorter than a binary STL's 84-byte header and count, "
                          "and it is not ASCII STL",
                          name, size)});
  }
  return std::unexpected(io_detail::stl_short_binary_error(name, probe.declared, size, quote));
}

}  // namespace lamina
