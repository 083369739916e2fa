#pragma once
// Helpers for the mesh reader tests: binary STL bytes built in memory (explicitly little-endian),
// temporary folders, and small geometry sums over a TriangleSoup.
#include "lamina/core/triangle_soup.hpp"

#include <Eigen/Geometry>

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace lamina::test {

// One binary STL record: stored normal, three corners.
struct StlFacet {
  std::array<float, 3> normal;
  std::array<float, 3> a, b, c;
};

inline void put_u32_le(std::vector<std::byte>& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::byte>((v >> (8 * i)) & 0xffu));
}

inline void put_f32_le(std::vector<std::byte>& out, float f) { put_u32_le(out, std::bit_cast<std::uint32_t>(f)); }

// A binary STL: `header` (cut or zero-padded to 80 bytes), the count (`declared_count` when given,
// else facets.size()), the facets, then `trailing` extra bytes of value 0xAB.
inline std::vector<std::byte> binary_stl(std::span<const StlFacet> facets, std::string_view header = "lamina test",
                                         std::size_t trailing = 0, std::int64_t declared_count = -1) {
  std::vector<std::byte> out;
  for (std::size_t i = 0; i < 80; ++i)
    out.push_back(i < header.size() ? static_cast<std::byte>(header[i]) : std::byte{0});
  put_u32_le(out, declared_count >= 0 ? static_cast<std::uint32_t>(declared_count)
                                      : static_cast<std::uint32_t>(facets.size()));
  for (const StlFacet& f : facets) {
    for (float v : f.normal) put_f32_le(out, v);
    for (const auto* corner : {&f.a, &f.b, &f.c})
      for (float v : *corner) put_f32_le(out, v);
    out.push_back(std::byte{0});
    out.push_back(std::byte{0});
  }
  for (std::size_t i = 0; i < trailing; ++i) out.push_back(std::byte{0xAB});
  return out;
}

// CRC-32 (zip, IEEE 802.3), bit by bit: slow and obviously right.
inline std::uint32_t crc32(std::string_view data) {
  std::uint32_t crc = 0xffffffffu;
  for (char ch : data) {
    crc ^= static_cast<unsigned char>(ch);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

// One zip entry: `data` is the content (method 0) or its raw deflate stream (method 8, with the
// content's crc and size given).
struct ZipItem {
  std::string name;
  std::string data;
  std::uint16_t method = 0;
  std::uint32_t crc = 0;
  std::uint32_t size = 0;
};

inline ZipItem stored(std::string name, std::string content) {
  const std::uint32_t crc = crc32(content);
  const auto size = static_cast<std::uint32_t>(content.size());
  return {std::move(name), std::move(content), 0, crc, size};
}

inline void put_u16_le(std::vector<std::byte>& out, std::uint32_t v) {
  out.push_back(static_cast<std::byte>(v & 0xffu));
  out.push_back(static_cast<std::byte>((v >> 8) & 0xffu));
}

// A plain zip archive (local headers, data, central directory, end record).
inline std::vector<std::byte> make_zip(const std::vector<ZipItem>& items) {
  std::vector<std::byte> out;
  std::vector<std::uint32_t> offsets;
  const auto put_text = [&out](std::string_view s) {
    for (char c : s) out.push_back(static_cast<std::byte>(c));
  };
  for (const ZipItem& it : items) {
    offsets.push_back(static_cast<std::uint32_t>(out.size()));
    put_u32_le(out, 0x04034b50u);
    put_u16_le(out, 20);  // version needed
    put_u16_le(out, 0);   // flags
    put_u16_le(out, it.method);
    put_u16_le(out, 0);  // time
    put_u16_le(out, 0);  // date
    put_u32_le(out, it.crc);
    put_u32_le(out, static_cast<std::uint32_t>(it.data.size()));
    put_u32_le(out, it.size);
    put_u16_le(out, static_cast<std::uint32_t>(it.name.size()));
    put_u16_le(out, 0);  // extra
    put_text(it.name);
    put_text(it.data);
  }
  const auto cd_offset = static_cast<std::uint32_t>(out.size());
  for (std::size_t i = 0; i < items.size(); ++i) {
    const ZipItem& it = items[i];
    put_u32_le(out, 0x02014b50u);
    put_u16_le(out, 20);  // made by
    put_u16_le(out, 20);  // needed
    put_u16_le(out, 0);   // flags
    put_u16_le(out, it.method);
    put_u16_le(out, 0);
    put_u16_le(out, 0);
    put_u32_le(out, it.crc);
    put_u32_le(out, static_cast<std::uint32_t>(it.data.size()));
    put_u32_le(out, it.size);
    put_u16_le(out, static_cast<std::uint32_t>(it.name.size()));
    put_u16_le(out, 0);  // extra
    put_u16_le(out, 0);  // comment
    put_u16_le(out, 0);  // disk
    put_u16_le(out, 0);  // internal attributes
    put_u32_le(out, 0);  // external attributes
    put_u32_le(out, offsets[i]);
    put_text(it.name);
  }
  const auto cd_size = static_cast<std::uint32_t>(out.size() - cd_offset);
  put_u32_le(out, 0x06054b50u);
  put_u16_le(out, 0);
  put_u16_le(out, 0);
  put_u16_le(out, static_cast<std::uint32_t>(items.size()));
  put_u16_le(out, static_cast<std::uint32_t>(items.size()));
  put_u32_le(out, cd_size);
  put_u32_le(out, cd_offset);
  put_u16_le(out, 0);  // comment
  return out;
}

// --- 3MF packages: the parts a 3MF zip holds. -------------------------------------------------

inline const std::string kContentTypes =
    R"(<?xml version="1.0" encoding="UTF-8"?>
<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">
 <Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>
 <Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>
</Types>
)";

inline std::string rels(std::string_view target) {
  return std::string(R"(<?xml version="1.0" encoding="UTF-8"?>
<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">
 <Relationship Target=")") +
         std::string(target) +
         R"(" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>
</Relationships>
)";
}

// Line 1: declaration, line 2: <model>, line 3: <resources>, then `resources` from line 4.
inline std::string model(std::string_view resources, std::string_view build, std::string_view unit = "millimeter") {
  return std::string("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"") + std::string(unit) +
         "\" xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\">\n<resources>\n" +
         std::string(resources) + "</resources>\n<build>\n" + std::string(build) + "</build>\n</model>\n";
}

// Object 1: one triangle.
inline const std::string kTriangleObject =
    "<object id=\"1\" type=\"model\"><mesh><vertices>\n"
    "<vertex x=\"0\" y=\"0\" z=\"0\"/><vertex x=\"1\" y=\"0\" z=\"0\"/><vertex x=\"0\" y=\"1\" z=\"0\"/>\n"
    "</vertices><triangles><triangle v1=\"0\" v2=\"1\" v3=\"2\"/></triangles></mesh></object>\n";

// Content types, relationships naming `path`, and the model part there (all stored).
inline std::vector<std::byte> package(const std::string& model_xml, std::string_view path = "3D/3dmodel.model") {
  return make_zip({stored("[Content_Types].xml", kContentTypes), stored("_rels/.rels", rels("/" + std::string(path))),
                   stored(std::string(path), model_xml)});
}

inline std::span<const std::byte> as_bytes(std::string_view s) {
  return {reinterpret_cast<const std::byte*>(s.data()), s.size()};
}

// A fresh folder under the system temp dir, removed with its content on destruction.
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    for (;;) {
      path_ = std::filesystem::temp_directory_path() /
              ("lamina_io_test_" + std::to_string(rd()) + "_" + std::to_string(rd()));
      if (std::filesystem::create_directory(path_)) break;
    }
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }

  std::filesystem::path write(const std::string& name, std::span<const std::byte> bytes) const {
    const auto p = path_ / name;
    std::ofstream f(p, std::ios::binary);
    f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    return p;
  }
  std::filesystem::path write(const std::string& name, std::string_view text) const {
    return write(name, as_bytes(text));
  }

 private:
  std::filesystem::path path_;
};

inline Eigen::Vector3d triangle_cross(const TriangleSoup& soup, std::size_t t) {
  const Eigen::Vector3d a = soup.corners[3 * t].cast<double>();
  const Eigen::Vector3d b = soup.corners[3 * t + 1].cast<double>();
  const Eigen::Vector3d c = soup.corners[3 * t + 2].cast<double>();
  return (b - a).cross(c - a);
}

// Σ |triangle area|.
inline double unsigned_area(const TriangleSoup& soup) {
  double sum = 0.0;
  for (std::size_t t = 0; t < soup.triangle_count(); ++t) sum += 0.5 * triangle_cross(soup, t).norm();
  return sum;
}

// Σ v0·(v1×v2)/6, in double (divergence theorem; positive for outward winding).
inline double signed_volume(const TriangleSoup& soup) {
  double sum = 0.0;
  for (std::size_t t = 0; t < soup.triangle_count(); ++t) {
    const Eigen::Vector3d a = soup.corners[3 * t].cast<double>();
    const Eigen::Vector3d b = soup.corners[3 * t + 1].cast<double>();
    const Eigen::Vector3d c = soup.corners[3 * t + 2].cast<double>();
    sum += a.dot(b.cross(c)) / 6.0;
  }
  return sum;
}

inline const ReadNote* find_note(const TriangleSoup& soup, std::string_view code) {
  for (const ReadNote& n : soup.notes)
    if (n.code == code) return &n;
  return nullptr;
}

}  // namespace lamina::test
