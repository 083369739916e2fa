// Binary STL: 80-byte header, little-endian uint32 facet count, then per facet the unit normal
// (from the winding) and three corners as little-endian float32, and a zero attribute word.
#include "lamina/core/stack_mesh.hpp"

#include <Eigen/Geometry>

#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace lamina {

namespace {

void put_u32(std::string& out, std::uint32_t v) {
  const char b[4] = {static_cast<char>(v & 0xffu), static_cast<char>((v >> 8) & 0xffu),
                     static_cast<char>((v >> 16) & 0xffu), static_cast<char>((v >> 24) & 0xffu)};
  out.append(b, 4);
}

void put_f32(std::string& out, float f) { put_u32(out, std::bit_cast<std::uint32_t>(f)); }

}  // namespace

std::string binary_stl_bytes(const TriangleSoup& soup, const std::string& header) {
  const std::size_t n = soup.triangle_count();
  if (n > std::numeric_limits<std::uint32_t>::max())
    throw std::length_error("binary_stl_bytes: more facets than a binary STL can count");
  // Readers that sniff a leading "solid" would take the file for ASCII: never start with it.
  std::string title = header;
  auto starts_like_ascii = [](const std::string& h) {
    std::size_t i = 0;
    while (i < h.size() && (h[i] == ' ' || h[i] == '\t' || h[i] == '\r' || h[i] == '\n')) ++i;
    static constexpr char kSolid[] = "solid";
    for (std::size_t k = 0; k < 5; ++k, ++i) {
      if (i >= h.size()) return false;
      const char c = h[i] >= 'A' && h[i] <= 'Z' ? static_cast<char>(h[i] - 'A' + 'a') : h[i];
      if (c != kSolid[k]) return false;
    }
    return true;
  };
  if (starts_like_ascii(title)) title = "binary STL: " + title;
  title.resize(80, ' ');

  std::string out;
  out.reserve(84 + 50 * n);
  out.append(title, 0, 80);
  put_u32(out, static_cast<std::uint32_t>(n));
  for (std::size_t t = 0; t < n; ++t) {
    const Eigen::Vector3f& a = soup.corners[3 * t];
    const Eigen::Vector3f& b = soup.corners[3 * t + 1];
    const Eigen::Vector3f& c = soup.corners[3 * t + 2];
    Eigen::Vector3d normal = (b - a).cast<double>().cross((c - a).cast<double>());
    const double len = normal.norm();
    normal = len > 0.0 ? Eigen::Vector3d(normal / len) : Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) put_f32(out, static_cast<float>(normal[k]));
    for (const Eigen::Vector3f* p : {&a, &b, &c})
      for (int k = 0; k < 3; ++k) put_f32(out, (*p)[k]);
    out.push_back('\0');
    out.push_back('\0');
  }
  return out;
}

}  // namespace lamina
