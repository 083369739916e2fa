// Minimal zip reading for 3MF: central directory (ZIP64 too: lib3mf writes it), stored and
// deflated entries (zlib raw inflate), CRC-32 check. No encryption or multi-disk archives.
#include "io/zip_archive.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <climits>
#include <optional>

#if defined(LAMINA_HAVE_ZLIB) && __has_include(<zlib.h>)
#include <zlib.h>
#define LAMINA_ZIP_INFLATE 1
#endif

namespace lamina::io_detail {
namespace {

constexpr std::uint32_t kEndOfCentralDirectory = 0x06054b50;
constexpr std::uint32_t kCentralHeader = 0x02014b50;
constexpr std::uint32_t kLocalHeader = 0x04034b50;
constexpr std::size_t kEndRecordBytes = 22;
constexpr std::size_t kCentralHeaderBytes = 46;
constexpr std::size_t kLocalHeaderBytes = 30;
// Deflate cannot expand data more than 1032:1; a larger declared size is a corrupt (or hostile) entry.
constexpr std::uint64_t kMaxDeflateRatio = 1032;

std::uint16_t u16(std::span<const std::byte> b, std::size_t at) {
  return static_cast<std::uint16_t>(std::to_integer<unsigned>(b[at]) | (std::to_integer<unsigned>(b[at + 1]) << 8));
}
std::uint32_t u32(std::span<const std::byte> b, std::size_t at) {
  return static_cast<std::uint32_t>(u16(b, at)) | (static_cast<std::uint32_t>(u16(b, at + 2)) << 16);
}
std::uint64_t u64(std::span<const std::byte> b, std::size_t at) {
  return static_cast<std::uint64_t>(u32(b, at)) | (static_cast<std::uint64_t>(u32(b, at + 4)) << 32);
}

constexpr std::uint32_t kZip64EndLocator = 0x07064b50;
constexpr std::uint32_t kZip64EndRecord = 0x06064b50;
constexpr std::size_t kZip64LocatorBytes = 20;
constexpr std::size_t kZip64EndRecordBytes = 56;
constexpr std::uint16_t kZip64ExtraId = 0x0001;

// Replaces the 0xFFFFFFFF fields of an entry from its ZIP64 extra field (in the order
// size, compressed size, local header offset). False when a needed value is missing.
bool apply_zip64_extra(std::span<const std::byte> extra, ZipEntry& e) {
  std::size_t at = 0;
  while (at + 4 <= extra.size()) {
    const std::uint16_t id = u16(extra, at), len = u16(extra, at + 2);
    if (at + 4 + len > extra.size()) return false;
    if (id == kZip64ExtraId) {
      std::size_t field = at + 4;
      const std::size_t field_end = at + 4 + len;
      for (std::uint64_t* value : {&e.size, &e.compressed_size, &e.local_header_offset}) {
        if (*value != 0xffffffffu) continue;
        if (field + 8 > field_end) return false;
        *value = u64(extra, field);
        field += 8;
      }
      return true;
    }
    at += 4 + len;
  }
  return e.size != 0xffffffffu && e.compressed_size != 0xffffffffu && e.local_header_offset != 0xffffffffu;
}

Error zip_error(ErrorCode code, std::string_view name, std::string message) {
  return Error{code, fmt::format("{}: {}", name, message)};
}

}  // namespace

std::string entry_label(const ZipEntry& e, const FileQuote& quote) {
  if (quote.quoting()) return fmt::format("'{}'", e.name);
  return fmt::format("number {} ({})", e.index + 1, quote.text(e.name, "a name"));
}

std::uint64_t inflate_bound(std::uint64_t compressed_size, const MeshReadOptions& o) {
  const std::uint64_t ratio = o.max_inflate_ratio;
  const std::uint64_t by_ratio =
      ratio != 0 && compressed_size > UINT64_MAX / ratio ? UINT64_MAX : compressed_size * ratio;
  return std::min(o.max_inflated_bytes, std::max(o.inflate_ratio_from_bytes, by_ratio));
}

bool zip_support_compiled() {
#ifdef LAMINA_ZIP_INFLATE
  return true;
#else
  return false;
#endif
}

// The end of central directory record: in the last 22 + 65535 (comment) bytes, the last one.
// The caller has checked that the archive holds at least one record's bytes.
static std::optional<std::size_t> find_end_record(std::span<const std::byte> zip) {
  const std::size_t lowest = zip.size() > kEndRecordBytes + 0xffff ? zip.size() - kEndRecordBytes - 0xffff : 0;
  std::size_t end = zip.size() - kEndRecordBytes + 1;
  while (end-- > lowest)
    if (u32(zip, end) == kEndOfCentralDirectory) return end;
  return std::nullopt;
}

std::expected<std::vector<ZipEntry>, Error> list_zip(std::span<const std::byte> zip, std::string_view name,
                                                    const FileQuote& quote) {
  if (zip.size() < kEndRecordBytes) {
    return std::unexpected(zip_error(ErrorCode::unknown_format, name, "not a zip archive (too short)"));
  }
  const std::optional<std::size_t> end_record = find_end_record(zip);
  if (!end_record) {
    return std::unexpected(zip_error(ErrorCode::unknown_format, name, "not a zip archive (no central directory)"));
  }
  const std::size_t end = *end_record;
  std::uint32_t disk = u16(zip, end + 4), cd_disk = u16(zip, end + 6);
  std::uint64_t entries = u16(zip, end + 10);
  std::uint64_t cd_size = u32(zip, end + 12), cd_offset = u32(zip, end + 16);
  std::size_t cd_end = end;  // the central directory ends where the (ZIP64) end records start
  if (entries == 0xffff || cd_size == 0xffffffffu || cd_offset == 0xffffffffu) {
    // ZIP64: a locator just before the end record points at the 64-bit end record.
    if (end < kZip64LocatorBytes || u32(zip, end - kZip64LocatorBytes) != kZip64EndLocator) {
      return std::unexpected(zip_error(ErrorCode::parse_error, name, "ZIP64 end record locator missing"));
    }
    const std::uint64_t record = u64(zip, end - kZip64LocatorBytes + 8);
    if (end < kZip64LocatorBytes + kZip64EndRecordBytes ||
        record > end - kZip64LocatorBytes - kZip64EndRecordBytes || u32(zip, record) != kZip64EndRecord) {
      return std::unexpected(zip_error(ErrorCode::parse_error, name, "ZIP64 end record missing"));
    }
    disk = u32(zip, record + 16);
    cd_disk = u32(zip, record + 20);
    entries = u64(zip, record + 32);
    cd_size = u64(zip, record + 40);
    cd_offset = u64(zip, record + 48);
    cd_end = static_cast<std::size_t>(record);
  }
  if (disk != 0 || cd_disk != 0) {
    return std::unexpected(zip_error(ErrorCode::unsupported, name, "multi-disk zip archives are not supported"));
  }
  if (cd_offset > cd_end || cd_size > cd_end - cd_offset || entries > cd_size / kCentralHeaderBytes) {
    return std::unexpected(zip_error(
        ErrorCode::truncated_file, name,
        fmt::format("zip central directory{} does not fit in the file",
                    quote.either(fmt::format(" ({} entries, {} bytes at {})", entries, cd_size, cd_offset), ""))));
  }

  std::vector<ZipEntry> out;
  out.reserve(entries);
  std::size_t at = static_cast<std::size_t>(cd_offset);
  for (std::uint64_t i = 0; i < entries; ++i) {
    if (at + kCentralHeaderBytes > cd_end || u32(zip, at) != kCentralHeader) {
      return std::unexpected(
          zip_error(ErrorCode::parse_error, name, fmt::format("zip central directory entry {} is malformed", i)));
    }
    ZipEntry e;
    e.index = static_cast<std::size_t>(i);
    e.flags = u16(zip, at + 8);
    e.method = u16(zip, at + 10);
    e.crc32 = u32(zip, at + 16);
    e.compressed_size = u32(zip, at + 20);
    e.size = u32(zip, at + 24);
    const std::size_t name_len = u16(zip, at + 28), extra_len = u16(zip, at + 30), comment_len = u16(zip, at + 32);
    e.local_header_offset = u32(zip, at + 42);
    if (at + kCentralHeaderBytes + name_len + extra_len + comment_len > cd_end) {
      return std::unexpected(
          zip_error(ErrorCode::parse_error, name, fmt::format("zip central directory entry {} is malformed", i)));
    }
    e.name.assign(reinterpret_cast<const char*>(zip.data() + at + kCentralHeaderBytes), name_len);
    if (!apply_zip64_extra(zip.subspan(at + kCentralHeaderBytes + name_len, extra_len), e)) {
      return std::unexpected(
          zip_error(ErrorCode::parse_error, name,
                    fmt::format("zip entry {}: malformed ZIP64 extra field", entry_label(e, quote))));
    }
    at += kCentralHeaderBytes + name_len + extra_len + comment_len;
    out.push_back(std::move(e));
  }
  return out;
}

namespace {

// Where the entry's data starts, once its flags, method and local header allow reading it.
std::expected<std::uint64_t, Error> entry_data(std::span<const std::byte> zip, const ZipEntry& e,
                                               std::string_view name, const FileQuote& quote) {
  const std::string label = entry_label(e, quote);
  if (e.flags & 1u) {
    return std::unexpected(zip_error(ErrorCode::unsupported, name, fmt::format("zip entry {} is encrypted", label)));
  }
  if (e.method != 0 && e.method != 8) {
    return std::unexpected(zip_error(ErrorCode::unsupported, name,
                                     fmt::format("zip entry {} uses compression method{} (only stored and deflate "
                                                 "are read)",
                                                 label, quote.either(fmt::format(" {}", e.method), " 'other'"))));
  }
  const std::uint64_t local = e.local_header_offset;
  if (zip.size() < kLocalHeaderBytes || local > zip.size() - kLocalHeaderBytes || u32(zip, local) != kLocalHeader) {
    return std::unexpected(
        zip_error(ErrorCode::truncated_file, name, fmt::format("zip entry {}: local header missing", label)));
  }
  const std::uint64_t data = local + kLocalHeaderBytes + u16(zip, local + 26) + u16(zip, local + 28);
  if (data > zip.size() || e.compressed_size > zip.size() - data) {
    return std::unexpected(zip_error(
        ErrorCode::truncated_file, name,
        fmt::format("zip entry {}{} runs past the end of the file", label,
                    quote.either(fmt::format(" ({} bytes at {})", e.compressed_size, data), ""))));
  }
  return data;
}

// Sizes that cannot be right (stored sizes differ, more than deflate can make), and sizes over
// the options' bound (a zip bomb, or a model no shop makes).
std::expected<void, Error> check_sizes(const ZipEntry& e, std::string_view name, const MeshReadOptions& options) {
  const FileQuote quote(options.quote_file_text);
  const std::string label = entry_label(e, quote);
  if (e.method == 0 && e.compressed_size != e.size) {
    return std::unexpected(
        zip_error(ErrorCode::parse_error, name, fmt::format("stored zip entry {} has inconsistent sizes", label)));
  }
  if (e.size > e.compressed_size * kMaxDeflateRatio + 1024) {
    return std::unexpected(zip_error(
        ErrorCode::parse_error, name,
        fmt::format("zip entry {} declares {} than deflate can make from {}", label,
                    quote.either(fmt::format("{} bytes, more", e.size), "more bytes"),
                    quote.either(fmt::format("{} compressed", e.compressed_size), "its compressed size"))));
  }
  const std::uint64_t bound = inflate_bound(e.compressed_size, options);
  if (e.size <= bound) return {};
  const std::string declared =
      quote.either(fmt::format("{} bytes inflated from {} compressed ({}:1)", e.size, e.compressed_size,
                               e.size / std::max<std::uint64_t>(e.compressed_size, 1)),
                   "an inflated size");
  return std::unexpected(zip_error(
      ErrorCode::limit_exceeded, name,
      fmt::format("zip entry {} declares {}, over the limit of {} bytes ({}:1 of its compressed size above {} "
                  "bytes, {} at most; MeshReadOptions::max_inflate_ratio, max_inflated_bytes)",
                  label, declared, bound, options.max_inflate_ratio, options.inflate_ratio_from_bytes,
                  options.max_inflated_bytes)));
}

}  // namespace

#ifdef LAMINA_ZIP_INFLATE
namespace {

// Raw inflate of [src, src + compressed) into a buffer that grows as output comes (from at most
// 4 bytes per compressed byte, doubling), never past declared + 1 bytes: the declared size has
// been bounded, the content has not.
std::expected<std::string, Error> inflate_entry(const std::byte* src, const ZipEntry& e, std::string_view name,
                                                const FileQuote& quote) {
  z_stream zs{};
  if (inflateInit2(&zs, -MAX_WBITS) != Z_OK) {
    return std::unexpected(zip_error(ErrorCode::io_error, name, "zlib inflateInit2 failed"));
  }
  const std::uint64_t cap = e.size + 1;
  std::string out(static_cast<std::size_t>(std::min<std::uint64_t>(cap, std::max<std::uint64_t>(65536, 4 * e.compressed_size))), '\0');
  std::uint64_t fed = 0, produced = 0;
  int rc = Z_OK;
  while (rc == Z_OK && produced < cap) {
    if (zs.avail_in == 0 && fed < e.compressed_size) {
      zs.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(src + fed));
      zs.avail_in = static_cast<uInt>(std::min<std::uint64_t>(e.compressed_size - fed, UINT_MAX));
      fed += zs.avail_in;
    }
    if (produced == out.size()) out.resize(static_cast<std::size_t>(std::min<std::uint64_t>(cap, 2 * out.size())));
    zs.next_out = reinterpret_cast<Bytef*>(out.data() + produced);
    zs.avail_out = static_cast<uInt>(std::min<std::uint64_t>(out.size() - produced, UINT_MAX));
    const uInt room = zs.avail_out;
    rc = inflate(&zs, Z_NO_FLUSH);
    produced += room - zs.avail_out;
    if (rc == Z_BUF_ERROR && zs.avail_in == 0 && fed == e.compressed_size) break;  // input ran out early
    if (rc == Z_BUF_ERROR) rc = Z_OK;
  }
  inflateEnd(&zs);
  if (produced > e.size) {
    return std::unexpected(zip_error(ErrorCode::parse_error, name,
                                     fmt::format("zip entry {} inflates past its declared {} (stopped there)",
                                                 entry_label(e, quote),
                                                 quote.either(fmt::format("{} bytes", e.size), "size"))));
  }
  if (rc != Z_STREAM_END || produced != e.size) {
    return std::unexpected(zip_error(
        ErrorCode::parse_error, name,
        fmt::format("zip entry {} does not inflate to its declared {} ({})", entry_label(e, quote),
                    quote.either(fmt::format("{} bytes", e.size), "size"), rc == Z_STREAM_END ? "size differs" : "corrupt")));
  }
  out.resize(static_cast<std::size_t>(produced));
  return out;
}

std::uint32_t crc_of(std::string_view data) {
  uLong crc = ::crc32(0L, Z_NULL, 0);
  for (std::size_t at = 0; at < data.size();) {
    const auto n = static_cast<uInt>(std::min<std::size_t>(data.size() - at, std::size_t{1} << 30));
    crc = ::crc32(crc, reinterpret_cast<const Bytef*>(data.data() + at), n);
    at += n;
  }
  return static_cast<std::uint32_t>(crc);
}

}  // namespace
#endif

std::expected<std::string, Error> read_zip_entry(std::span<const std::byte> zip, const ZipEntry& e,
                                                 std::string_view name, const MeshReadOptions& options) {
  const FileQuote quote(options.quote_file_text);
  const auto data = entry_data(zip, e, name, quote);
  if (!data) return std::unexpected(data.error());
#ifdef LAMINA_ZIP_INFLATE
  if (auto sizes = check_sizes(e, name, options); !sizes) return std::unexpected(sizes.error());
  const std::byte* src = zip.data() + *data;
  std::string out;
  if (e.method == 0) {
    out.assign(reinterpret_cast<const char*>(src), static_cast<std::size_t>(e.size));
  } else {
    auto inflated = inflate_entry(src, e, name, quote);
    if (!inflated) return std::unexpected(inflated.error());
    out = std::move(*inflated);
  }
  if (const std::uint32_t crc = crc_of(out); crc != e.crc32) {
    return std::unexpected(zip_error(
        ErrorCode::parse_error, name,
        fmt::format("zip entry {} fails its CRC-32 check{}", entry_label(e, quote),
                    quote.either(fmt::format(" ({:08x}, stored {:08x})", crc, e.crc32), ""))));
  }
  return out;
#else
  (void)check_sizes;
  return std::unexpected(
      zip_error(ErrorCode::unsupported, name, "3MF is not supported yet (this build has no zlib to inflate it)"));
#endif
}

}  // namespace lamina::io_detail
