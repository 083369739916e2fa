// read_mesh_file: reads the whole file with one read() loop, then picks the parser from the
// extension (.obj, .3mf) or the content (STL, binary or ASCII).
#include "lamina/core/mesh_io.hpp"
#include "mesh_io_text.hpp"

#include <fmt/format.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>
#include <string>

namespace lamina {
namespace {

struct FileBytes {
  std::unique_ptr<std::byte[]> data;
  std::size_t size = 0;
  std::span<const std::byte> span() const { return {data.get(), size}; }
};

Error io_error(const std::string& path, std::string_view what, int err) {
  return Error{ErrorCode::io_error, fmt::format("{}: {}: {}", path, what, std::strerror(err))};
}

std::expected<FileBytes, Error> read_whole_file(const std::filesystem::path& path) {
  const std::string name = path.string();
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::unexpected(io_error(name, "cannot open", errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};

  struct stat st{};
  if (::fstat(fd, &st) != 0) return std::unexpected(io_error(name, "cannot stat", errno));
  if (S_ISDIR(st.st_mode)) return std::unexpected(io_error(name, "cannot read", EISDIR));
  if (!S_ISREG(st.st_mode)) {
    return std::unexpected(Error{ErrorCode::io_error, fmt::format("{}: not a regular file", name)});
  }

  FileBytes file;
  const auto size = static_cast<std::size_t>(st.st_size);
  file.data = std::make_unique_for_overwrite<std::byte[]>(size == 0 ? 1 : size);
  while (file.size < size) {
    const ssize_t got = ::read(fd, file.data.get() + file.size, size - file.size);
    if (got < 0) {
      if (errno == EINTR) continue;
      return std::unexpected(io_error(name, "read failed", errno));
    }
    if (got == 0) break;  // the file shrank while we read it: parse what is there
    file.size += static_cast<std::size_t>(got);
  }
  return file;
}

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = detail::ascii_lower(c);
  return ext;
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
    while (i < line.size() && detail::is_space(line[i])) ++i;
    line.remove_prefix(i);
    if (line.empty() || line.front() == '#') continue;
    for (std::string_view kw : {"v ", "v\t", "vn ", "vt ", "f ", "o ", "g ", "mtllib ", "usemtl ", "s "})
      if (line.starts_with(kw)) return true;
    return false;
  }
  return false;
}

}  // namespace

std::expected<TriangleSoup, Error> read_mesh_file(const std::filesystem::path& path) {
  auto file = read_whole_file(path);
  if (!file) return std::unexpected(std::move(file.error()));
  const std::string name = path.string();
  const std::string ext = lower_extension(path);
  const std::string_view text(reinterpret_cast<const char*>(file->data.get()), file->size);

  if (ext == ".obj") return parse_obj(text, name);
  if (ext == ".3mf") {
    return std::unexpected(Error{ErrorCode::unsupported, fmt::format("{}: 3MF is not supported yet", name)});
  }

  auto stl = parse_stl(file->span(), name);
  if (!stl) {
    if (text.starts_with("PK\x03\x04")) {
      return std::unexpected(Error{ErrorCode::unknown_format,
                                   fmt::format("{}: a zip archive (a 3MF file? name it .3mf), not STL or OBJ", name)});
    }
    if (text.starts_with("ply\n") || text.starts_with("ply\r\n")) {
      return std::unexpected(Error{ErrorCode::unknown_format,
                                   fmt::format("{}: a PLY file, which is not read (convert it to STL or OBJ)", name)});
    }
    if (stl.error().code == ErrorCode::unknown_format && looks_like_obj(text.substr(0, 4096))) {
      return parse_obj(text, name);
    }
  }
  return stl;
}

}  // namespace lamina
