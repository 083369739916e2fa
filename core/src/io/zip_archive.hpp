#pragma once
// Private: the entries of a zip archive held in memory (what 3MF files are), and the bytes of
// one entry (stored or deflated). Inflating needs zlib: without LAMINA_HAVE_ZLIB (see
// core/CMakeLists.txt) zip_support_compiled() is false and read_zip_entry fails with unsupported.
#include "lamina/core/error.hpp"
#include "lamina/core/mesh_io.hpp"
#include "io/mesh_io_text.hpp"

#include <cstddef>
#include <cstdint>
#include <expected>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace lamina::io_detail {

struct ZipEntry {
  std::string name;
  std::uint16_t flags = 0;
  std::uint16_t method = 0;  // 0 stored, 8 deflate
  std::uint32_t crc32 = 0;
  std::uint64_t compressed_size = 0;
  std::uint64_t size = 0;
  std::uint64_t local_header_offset = 0;
  std::size_t index = 0;  // its place in the central directory, from 0
};

// How messages name an entry: 'its name', or (quoting off) "number 3 (a name of 16 bytes)".
std::string entry_label(const ZipEntry& entry, const FileQuote& quote);

// The most bytes an entry of `compressed_size` bytes may inflate to under the options.
std::uint64_t inflate_bound(std::uint64_t compressed_size, const MeshReadOptions& options);

bool zip_support_compiled();

// The central directory. unknown_format when there is none (not a zip), truncated_file when it
// points outside the bytes, unsupported for multi-disk archives.
std::expected<std::vector<ZipEntry>, Error> list_zip(std::span<const std::byte> zip, std::string_view name,
                                                    const FileQuote& quote);

// One entry's content, checked against its CRC-32. An entry declaring more than inflate_bound is
// refused (limit_exceeded) before anything is inflated; the output then grows as it inflates and
// inflation stops one byte past the declared size, so a lying entry costs no more than an honest one.
std::expected<std::string, Error> read_zip_entry(std::span<const std::byte> zip, const ZipEntry& entry,
                                                 std::string_view name, const MeshReadOptions& options);

}  // namespace lamina::io_detail
