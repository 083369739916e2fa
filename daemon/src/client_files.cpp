#include "client_files.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <utility>

#include <fmt/format.h>

namespace lamina::daemon {
namespace fs = std::filesystem;

namespace {

JobError storage(std::string message) { return JobError{JobErrorKind::storage, std::move(message)}; }

struct Fd {
  int fd = -1;
  explicit Fd(int f) : fd(f) {}
  Fd(Fd&& o) noexcept : fd(std::exchange(o.fd, -1)) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  Fd& operator=(Fd&&) = delete;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

bool inside(const fs::path& path, const fs::path& root) {
  const fs::path rel = path.lexically_normal().lexically_relative((root / "").lexically_normal());
  return !rel.empty() && *rel.begin() != ".." && rel != ".";
}

std::string list_roots(const std::vector<fs::path>& roots) {
  std::string out;
  for (const auto& r : roots) out += (out.empty() ? "" : ", ") + r.string();
  return out;
}

// Where the descriptor really points: symlinks and ".." resolved by the kernel, for the file
// that was opened (a path resolved before the open could be swapped under it).
std::expected<fs::path, std::string> opened_path(int fd) {
  std::array<char, 4096> buf{};
  const std::string link = fmt::format("/proc/self/fd/{}", fd);
  const ssize_t n = ::readlink(link.c_str(), buf.data(), buf.size() - 1);
  if (n <= 0) return std::unexpected(fmt::format("cannot resolve the opened file ({})", std::strerror(errno)));
  return fs::path(std::string(buf.data(), static_cast<std::size_t>(n)));
}

bool inside_canonical_roots(const fs::path& real, const std::vector<fs::path>& roots) {
  for (const auto& root : roots) {
    std::error_code ec;
    const fs::path canonical = fs::weakly_canonical(root, ec);
    if (!ec && inside(real, canonical)) return true;
  }
  return false;
}

// `size` bytes from `in` to `out`, in the kernel where it can.
bool copy_bytes(int in, int out, std::uint64_t size) {
  std::uint64_t done = 0;
  while (done < size) {
    const ssize_t n = ::copy_file_range(in, nullptr, out, nullptr, size - done, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EXDEV || errno == ENOSYS || errno == EINVAL || errno == EOPNOTSUPP)) break;
    if (n <= 0) return false;  // n == 0: the file shrank under us
    done += static_cast<std::uint64_t>(n);
  }
  std::array<char, 1 << 16> buf;
  while (done < size) {  // the plain path (another filesystem, an old kernel)
    const ssize_t n = ::read(in, buf.data(), std::min<std::uint64_t>(buf.size(), size - done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    for (ssize_t w = 0; w < n;) {
      const ssize_t m = ::write(out, buf.data() + w, static_cast<std::size_t>(n - w));
      if (m < 0 && errno == EINTR) continue;
      if (m <= 0) return false;
      w += m;
    }
    done += static_cast<std::uint64_t>(n);
  }
  return true;
}

// The opened, checked file: a regular file within the size limit, read through its own
// descriptor (O_PATH first, so that opening a device or FIFO for reading never happens).
std::expected<Fd, JobError> open_checked(const std::string& path, std::string_view param, const ClientFileRules& rules,
                                         struct stat& st) {
  Fd handle(::open(path.c_str(), O_PATH | O_CLOEXEC));
  if (handle.fd < 0)
    return std::unexpected(bad_request(fmt::format("{}: {}: {}", param, path,
                                               errno == ENOENT ? "no such file" : std::strerror(errno))));
  auto real = opened_path(handle.fd);
  if (!real) return std::unexpected(bad_request(fmt::format("{}: {}: {}", param, path, real.error())));
  if (!inside_canonical_roots(*real, rules.roots))
    return std::unexpected(bad_request(fmt::format("{}: {} leads outside the folders jobs may read ({})", param, path,
                                               list_roots(rules.roots))));
  if (::fstat(handle.fd, &st) != 0 || !S_ISREG(st.st_mode))
    return std::unexpected(bad_request(fmt::format("{}: {} is not a regular file", param, path)));
  if (st.st_size == 0) return std::unexpected(bad_request(fmt::format("{}: {} is empty", param, path)));
  if (static_cast<std::uint64_t>(st.st_size) > rules.max_bytes)
    return std::unexpected(bad_request(fmt::format("{}: {} is {} bytes, more than the {} allowed", param, path, st.st_size,
                                               rules.max_bytes)));
  Fd file(::open(fmt::format("/proc/self/fd/{}", handle.fd).c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY));
  if (file.fd < 0)
    return std::unexpected(bad_request(fmt::format("{}: cannot read {}: {}", param, path, std::strerror(errno))));
  struct stat again {};
  if (::fstat(file.fd, &again) != 0 || again.st_ino != st.st_ino || again.st_dev != st.st_dev)
    return std::unexpected(bad_request(fmt::format("{}: {} changed while it was opened", param, path)));
  return file;
}

}  // namespace

bool inside_roots(const fs::path& path, const std::vector<fs::path>& roots) {
  for (const auto& root : roots)
    if (inside(path, root)) return true;
  return false;
}

std::expected<fs::path, JobError> import_client_file(const std::string& path, std::string_view param,
                                                     const ClientFileRules& rules, const fs::path& target_dir) {
  if (path.empty() || path.front() != '/')
    return std::unexpected(bad_request(fmt::format("{}: expected an absolute path on the cell PC", param)));
  if (path.find('\0') != std::string::npos)
    return std::unexpected(bad_request(fmt::format("{}: the path holds a NUL character", param)));
  if (!inside_roots(path, rules.roots))
    return std::unexpected(bad_request(fmt::format("{}: {} is outside the folders jobs may read ({}); copy the file there "
                                               "or upload it",
                                               param, path, list_roots(rules.roots))));
  struct stat st {};
  auto file = open_checked(path, param, rules, st);
  if (!file) return std::unexpected(file.error());

  std::error_code ec;
  fs::create_directories(target_dir, ec);
  const fs::path target = target_dir / fs::path(path).filename();
  Fd out(::open(target.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0640));
  if (out.fd < 0) return std::unexpected(storage(fmt::format("{}: {}", target.string(), std::strerror(errno))));
  // Durable before the job that names it is: a job in the database always has its file.
  errno = 0;
  if (!copy_bytes(file->fd, out.fd, static_cast<std::uint64_t>(st.st_size)) || ::fdatasync(out.fd) != 0) {
    const std::string why = errno ? std::strerror(errno) : "the file changed while it was copied";
    fs::remove(target, ec);
    return std::unexpected(storage(fmt::format("{}: copying {} failed: {}", param, path, why)));
  }
  return target;
}

}  // namespace lamina::daemon
