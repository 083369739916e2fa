// Binary STL: 80-byte header, uint32 LE triangle count, then per triangle 12 float32 LE
// (normal, three corners) and a 2-byte attribute. Corners are copied as stored; normals only
// feed the notes.
#include "stl_detail.hpp"

#include <fmt/format.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace lamina::detail {
namespace {

constexpr std::size_t kPreambleBytes = 84;
constexpr std::size_t kTriangleBytes = 50;

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

}  // namespace

std::expected<TriangleSoup, Error> parse_stl_binary(std::span<const std::byte> bytes, std::string_view name) {
  std::uint32_t count_le;
  std::memcpy(&count_le, bytes.data() + 80, 4);
  const std::uint32_t count =
      std::endian::native == std::endian::little ? count_le : std::byteswap(count_le);
  if (count == 0) {
    return std::unexpected(Error{
        ErrorCode::empty_mesh,
        fmt::format("{}: binary STL declares 0 triangles ({} bytes after the header)", name, bytes.size() - 84)});
  }

  TriangleSoup soup;
  soup.format = "stl-binary";
  soup.corners.resize(std::size_t{3} * count);  // Eigen vectors are left uninitialised here

  StlNormalStats normals;
  std::size_t non_finite = 0;
  std::size_t non_finite_triangles = 0;
  const std::byte* p = bytes.data() + kPreambleBytes;
  Eigen::Vector3f* out = soup.corners.data();
  for (std::uint32_t t = 0; t < count; ++t, p += kTriangleBytes, out += 3) {
    float f[12];
    load_floats_le(p, f);
    normals.add(f[0], f[1], f[2]);
    out[0] = Eigen::Vector3f(f[3], f[4], f[5]);
    out[1] = Eigen::Vector3f(f[6], f[7], f[8]);
    out[2] = Eigen::Vector3f(f[9], f[10], f[11]);
    unsigned bad = 0;
    for (int i = 3; i < 12; ++i) bad += !std::isfinite(f[i]);
    non_finite += bad;
    non_finite_triangles += bad != 0;
  }

  const std::size_t used = kPreambleBytes + kTriangleBytes * std::size_t{count};
  if (bytes.size() > used) {
    const std::size_t extra = bytes.size() - used;
    soup.notes.push_back(
        {"trailing_bytes", fmt::format("{}: {} trailing byte{} after the {} declared triangles ignored ({} bytes "
                                       "expected, {} present)",
                                       name, extra, extra == 1 ? "" : "s", count, used, bytes.size())});
  }
  normals.append_notes(soup.notes, name);
  append_non_finite_note(soup.notes, name, non_finite, non_finite_triangles);
  return soup;
}

}  // namespace lamina::detail
