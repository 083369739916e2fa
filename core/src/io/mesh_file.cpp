// read_mesh_file: opens the file, picks the parser from the extension (.obj, .3mf) or the
// content (STL binary or ASCII; failing that OBJ, or a 3MF zip under another name), and reads it.
// Binary STL is converted in 1 MiB chunks as it is read (no copy of the whole file: that costs as
// much as the conversion); everything else is read whole with one read() loop and parsed in memory.
#include "lamina/core/mesh_io.hpp"
#include "io/mesh_io_text.hpp"
#include "io/stl_detail.hpp"

#include <fmt/format.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>
#include <string>
#include <utility>

namespace lamina {
namespace {

constexpr std::size_t kChunkBytes = std::size_t{1} << 20;

Error io_error(const std::string& name, std::string_view what, int err) {
  return Error{ErrorCode::io_error, fmt::format("{}: {}: {}", name, what, std::strerror(err))};
}

class InputFile {
 public:
  static std::expected<InputFile, Error> open(const std::filesystem::path& path, const std::string& name) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return std::unexpected(io_error(name, "cannot open", errno));
    InputFile file(fd, name);
    struct stat st{};
    if (::fstat(fd, &st) != 0) return std::unexpected(io_error(name, "cannot stat", errno));
    if (S_ISDIR(st.st_mode)) return std::unexpected(io_error(name, "cannot read", EISDIR));
    if (!S_ISREG(st.st_mode)) {
      return std::unexpected(Error{ErrorCode::io_error, fmt::format("{}: not a regular file", name)});
    }
    file.size_ = static_cast<std::uint64_t>(st.st_size);
    return file;
  }

  InputFile(InputFile&& other) noexcept : fd_(std::exchange(other.fd_, -1)), size_(other.size_), name_(other.name_) {}
  InputFile& operator=(InputFile&&) = delete;
  ~InputFile() {
    if (fd_ >= 0) ::close(fd_);
  }

  std::uint64_t size() const { return size_; }

  // Reads up to n bytes (fewer only at end of file).
  std::expected<std::size_t, Error> read(std::byte* dst, std::size_t n) {
    std::size_t got = 0;
    while (got < n) {
      const ssize_t r = ::read(fd_, dst + got, n - got);
      if (r < 0) {
        if (errno == EINTR) continue;
        return std::unexpected(io_error(name_, "read failed", errno));
      }
      if (r == 0) break;
      got += static_cast<std::size_t>(r);
    }
    return got;
  }

 private:
  InputFile(int fd, const std::string& name) : fd_(fd), name_(name) {}
  int fd_;
  std::uint64_t size_ = 0;
  const std::string& name_;
};

struct Bytes {
  std::unique_ptr<std::byte[]> data;
  std::size_t size = 0;
  std::span<const std::byte> span() const { return {data.get(), size}; }
  std::string_view text() const { return {reinterpret_cast<const char*>(data.get()), size}; }
};

// The rest of the file after `head` (already read) in one buffer.
std::expected<Bytes, Error> read_whole(InputFile& file, std::span<const std::byte> head) {
  Bytes all;
  const auto capacity = static_cast<std::size_t>(std::max<std::uint64_t>(file.size(), head.size()));
  all.data = std::make_unique_for_overwrite<std::byte[]>(capacity == 0 ? 1 : capacity);
  std::copy(head.begin(), head.end(), all.data.get());
  auto got = file.read(all.data.get() + head.size(), capacity - head.size());
  if (!got) return std::unexpected(got.error());
  all.size = head.size() + *got;  // a file that shrank meanwhile is parsed as it now is
  return all;
}

// Binary STL, converted chunk by chunk. `chunk` holds the first `have` bytes of the file.
std::expected<TriangleSoup, Error> stream_binary_stl(InputFile& file, std::byte* chunk, std::size_t have,
                                                     std::uint32_t count, const std::string& name,
                                                     const io_detail::FileQuote& quote) {
  using io_detail::kStlPreambleBytes;
  using io_detail::kStlTriangleBytes;
  io_detail::StlBinaryDecoder decoder(count);
  std::size_t offset = kStlPreambleBytes;
  for (;;) {
    const std::size_t records = std::min((have - offset) / kStlTriangleBytes, count - decoder.decoded());
    decoder.decode(chunk + offset, records);
    if (decoder.decoded() == count) break;
    const std::size_t leftover = have - offset - records * kStlTriangleBytes;
    std::memmove(chunk, chunk + offset + records * kStlTriangleBytes, leftover);
    auto got = file.read(chunk + leftover, kChunkBytes - leftover);
    if (!got) return std::unexpected(got.error());
    if (*got == 0) {  // the file shrank after fstat
      return std::unexpected(io_detail::stl_short_binary_error(
          name, count, kStlPreambleBytes + kStlTriangleBytes * decoder.decoded() + leftover, quote));
    }
    have = leftover + *got;
    offset = 0;
  }
  return std::move(decoder).finish(name, file.size(), quote);
}

// OBJ statements a file typically starts with (after comments and blank lines).
bool looks_like_obj(std::string_view text) {
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t eol = text.find('\n', pos);
    if (eol == std::string_view::npos) eol = text.size();
    std::string_view line = text.substr(pos, eol - pos);
    pos = eol + 1;
    std::size_t i = 0;
    while (i < line.size() && io_detail::is_space(line[i])) ++i;
    line.remove_prefix(i);
    if (line.empty() || line.front() == '#') continue;
    for (std::string_view kw : {"v ", "v\t", "vn ", "vt ", "f ", "o ", "g ", "mtllib ", "usemtl ", "s "})
      if (line.starts_with(kw)) return true;
    return false;
  }
  return false;
}

// Content that is not STL: say what it is when we can tell.
std::expected<TriangleSoup, Error> not_stl(const Bytes& all, Error stl_error, const std::string& name,
                                           const MeshReadOptions& options) {
  const std::string_view text = all.text();
  if (text.starts_with("PK\x03\x04")) {  // a zip: perhaps a 3MF under another name
    auto three_mf = parse_3mf(all.span(), name, options);
    if (three_mf || three_mf.error().code != ErrorCode::unknown_format) return three_mf;
    return std::unexpected(Error{ErrorCode::unknown_format,
                                 fmt::format("{} (a zip archive, but not STL, OBJ or 3MF)", three_mf.error().message)});
  }
  if (text.starts_with("ply\n") || text.starts_with("ply\r\n")) {
    return std::unexpected(Error{ErrorCode::unknown_format,
                                 fmt::format("{}: a PLY file, which is not read (convert it to STL or OBJ)", name)});
  }
  if (stl_error.code == ErrorCode::unknown_format && looks_like_obj(text.substr(0, 4096))) {
    return parse_obj(text, name, options);
  }
  return std::unexpected(std::move(stl_error));
}

}  // namespace

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = io_detail::ascii_lower(c);
  return ext;
}

bool is_cad_path(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  return ext == ".step" || ext == ".stp" || ext == ".iges" || ext == ".igs";
}

std::expected<TriangleSoup, Error> read_mesh_file(const std::filesystem::path& path, const MeshReadOptions& options) {
  const std::string name = path.string();
  auto file = InputFile::open(path, name);
  if (!file) return std::unexpected(std::move(file.error()));
  const std::string ext = lower_extension(path);

  if (ext == ".obj" || ext == ".3mf") {
    auto all = read_whole(*file, {});
    if (!all) return std::unexpected(std::move(all.error()));
    return ext == ".obj" ? parse_obj(all->text(), name, options) : parse_3mf(all->span(), name, options);
  }

  // STL by content: the first chunk and the size tell binary from ASCII.
  auto chunk = std::make_unique_for_overwrite<std::byte[]>(kChunkBytes);
  auto first = file->read(chunk.get(), static_cast<std::size_t>(std::min<std::uint64_t>(file->size(), kChunkBytes)));
  if (!first) return std::unexpected(std::move(first.error()));
  const io_detail::StlProbe probe = io_detail::probe_stl({chunk.get(), *first}, file->size());
  if (!probe.ascii_like && probe.binary_fits && probe.declared > 0) {
    return stream_binary_stl(*file, chunk.get(), *first, static_cast<std::uint32_t>(probe.declared), name,
                             io_detail::FileQuote(options.quote_file_text));
  }

  auto all = read_whole(*file, {chunk.get(), *first});
  if (!all) return std::unexpected(std::move(all.error()));
  chunk.reset();
  auto stl = parse_stl(all->span(), name, options);
  if (stl) return stl;
  return not_stl(*all, std::move(stl.error()), name, options);
}

}  // namespace lamina
