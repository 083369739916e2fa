// Binary STL: 80-byte header, uint32 LE triangle count, then per triangle 12 float32 LE
// (normal, three corners) and a 2-byte attribute. Corners are copied as stored; normals only
// feed the notes.
#include "io/stl_detail.hpp"

#include <fmt/format.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace lamina::io_detail {
namespace {

// Twelve little-endian float32 starting at p (any alignment, any host byte order).
inline void load_floats_le(const std::byte* p, float (&out)[12]) {
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(out, p, sizeof out);
  } else {
    for (int i = 0; i < 12; ++i) {
      std::uint32_t u;
      std::memcpy(&u, p + 4 * i, 4);
      out[i] = std::bit_cast<float>(std::byteswap(u));
    }
  }
}

std::uint32_t read_count(std::span<const std::byte> bytes) {
  std::uint32_t count;
  std::memcpy(&count, bytes.data() + kStlHeaderBytes, 4);
  return std::endian::native == std::endian::little ? count : std::byteswap(count);
}

}  // namespace

StlBinaryDecoder::StlBinaryDecoder(std::uint32_t count) : count_(count) {
  soup_.format = "stl-binary";
  soup_.corners.resize(std::size_t{3} * count);  // Eigen vectors are left uninitialised here
}

void StlBinaryDecoder::decode(const std::byte* p, std::size_t n) {
  Eigen::Vector3f* out = soup_.corners.data() + 3 * done_;
  std::size_t non_finite = 0;
  std::size_t non_finite_triangles = 0;
  for (std::size_t t = 0; t < n; ++t, p += kStlTriangleBytes, out += 3) {
    float f[12];
    load_floats_le(p, f);
    normals_.add(f[0], f[1], f[2]);
    out[0] = Eigen::Vector3f(f[3], f[4], f[5]);
    out[1] = Eigen::Vector3f(f[6], f[7], f[8]);
    out[2] = Eigen::Vector3f(f[9], f[10], f[11]);
    unsigned bad = 0;
    for (int i = 3; i < 12; ++i) bad += !std::isfinite(f[i]);
    non_finite += bad;
    non_finite_triangles += bad != 0;
  }
  done_ += n;
  non_finite_ += non_finite;
  non_finite_triangles_ += non_finite_triangles;
}

TriangleSoup StlBinaryDecoder::finish(std::string_view name, std::uint64_t file_size, const FileQuote& quote) && {
  const std::uint64_t used = kStlPreambleBytes + kStlTriangleBytes * std::uint64_t{count_};
  if (file_size > used) {
    const std::uint64_t extra = file_size - used;
    soup_.notes.push_back(
        {"trailing_bytes", fmt::format("{}: {} trailing byte{} after the {} declared triangles ignored ({} bytes "
                                       "expected, {} present)",
                                       name, extra, extra == 1 ? "" : "s", count_, used, file_size)});
  }
  normals_.append_notes(soup_.notes, name, quote);
  append_non_finite_note(soup_.notes, name, non_finite_, non_finite_triangles_);
  return std::move(soup_);
}

std::expected<TriangleSoup, Error> parse_stl_binary(std::span<const std::byte> bytes, std::string_view name,
                                                    const FileQuote& quote) {
  const std::uint32_t count = read_count(bytes);
  if (count == 0) {
    return std::unexpected(Error{ErrorCode::empty_mesh,
                                 fmt::format("{}: binary STL declares 0 triangles ({} bytes after the header)", name,
                                             bytes.size() - kStlPreambleBytes)});
  }
  StlBinaryDecoder decoder(count);
  decoder.decode(bytes.data() + kStlPreambleBytes, count);
  return std::move(decoder).finish(name, bytes.size(), quote);
}

}  // namespace lamina::io_detail
