#pragma once
// Private: the entries of a zip archive held in memory (what 3MF files are), and the bytes of
// one entry (stored or deflated). Inflating needs zlib: without LAMINA_HAVE_ZLIB (see
// core/CMakeLists.txt) zip_support_compiled() is false and read_zip_entry fails with unsupported.
#include "lamina/core/error.hpp"

#include <cstddef>
#include <cstdint>
#include <expected>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace lamina::detail {

struct ZipEntry {
  std::string name;
  std::uint16_t flags = 0;
  std::uint16_t method = 0;  // 0 stored, 8 deflate
  std::uint32_t crc32 = 0;
  std::uint64_t compressed_size = 0;
  std::uint64_t size = 0;
  std::uint64_t local_header_offset = 0;
};

bool zip_support_compiled();

// The central directory. unknown_format when there is none (not a zip), truncated_file when it
// points outside the bytes, unsupported for multi-disk archives.
std::expected<std::vector<ZipEntry>, Error> list_zip(std::span<const std::byte> zip, std::string_view name);

// One entry's content, checked against its CRC-32.
std::expected<std::string, Error> read_zip_entry(std::span<const std::byte> zip, const ZipEntry& entry,
                                                 std::string_view name);

}  // namespace lamina::detail
