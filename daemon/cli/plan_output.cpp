#include "plan_output.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <unistd.h>

namespace lamina::cli {
namespace {

namespace fs = std::filesystem;

std::unexpected<Error> io_error(std::string message) { return std::unexpected(Error{ErrorCode::io_error, std::move(message)}); }

fs::path tmp_path(const fs::path& dir, const std::string& name) { return dir / ("." + name + ".tmp"); }

void sync_dir(const fs::path& dir) {
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

// The nearest existing ancestor of p (p itself when it exists), and the missing folders below it.
fs::path existing_ancestor(const fs::path& p, std::vector<fs::path>* missing) {
  fs::path cur = fs::absolute(p).lexically_normal();
  std::error_code ec;
  while (!fs::exists(cur, ec) && cur.has_relative_path()) {
    if (missing) missing->push_back(cur);
    cur = cur.parent_path();
  }
  if (missing) std::reverse(missing->begin(), missing->end());
  return cur;
}

}  // namespace

std::expected<void, Error> check_out_dir(const std::string& dir) {
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) return io_error(fmt::format("--out {}: exists and is not a folder", dir));
  const fs::path base = existing_ancestor(dir, nullptr);
  if (!fs::is_directory(base, ec))
    return io_error(fmt::format("--out {}: cannot create the folder: {} is not a folder", dir, base.string()));
  if (::access(base.c_str(), W_OK | X_OK) != 0)
    return io_error(fmt::format("--out {}: {} is not writable: {}", dir, base.string(), std::strerror(errno)));
  return {};
}

std::expected<StagedOutput, Error> StagedOutput::open(const std::string& dir) {
  if (auto ok = check_out_dir(dir); !ok) return std::unexpected(ok.error());
  std::vector<fs::path> missing;
  existing_ancestor(dir, &missing);
  std::vector<fs::path> created;
  for (const fs::path& d : missing) {
    std::error_code ec;
    if (!fs::create_directory(d, ec) && ec) {
      StagedOutput undo(fs::path(dir), std::move(created));
      return io_error(fmt::format("--out {}: cannot create {}: {}", dir, d.string(), ec.message()));
    }
    created.push_back(d);
  }
  return StagedOutput(fs::path(dir), std::move(created));
}

StagedOutput::StagedOutput(fs::path dir, std::vector<fs::path> created) : dir_(std::move(dir)), created_(std::move(created)) {}

StagedOutput::StagedOutput(StagedOutput&& other) noexcept
    : dir_(std::move(other.dir_)), created_(std::move(other.created_)), staged_(std::move(other.staged_)),
      published_(other.published_) {
  other.created_.clear();
  other.staged_.clear();
  other.published_ = true;  // nothing left for the moved-from object to undo
}

StagedOutput::~StagedOutput() {
  if (!published_) discard();
}

void StagedOutput::discard() {
  for (const std::string& name : staged_) ::unlink(tmp_path(dir_, name).c_str());
  staged_.clear();
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) {
    std::error_code ec;
    fs::remove(*it, ec);  // only if empty: a folder someone else wrote into stays
  }
  created_.clear();
}

std::expected<void, Error> StagedOutput::stage(const std::string& name, std::string_view bytes) {
  const fs::path tmp = tmp_path(dir_, name);
  const std::string final_name = (dir_ / name).string();
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return io_error(fmt::format("cannot write {}: {}", final_name, std::strerror(errno)));
  staged_.push_back(name);
  auto fail = [&](const char* what) {
    const int err = errno;
    ::close(fd);
    return io_error(fmt::format("cannot write {}: {} ({})", final_name, std::strerror(err), what));
  };
  for (std::size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return fail("write");
    if (n == 0) {
      errno = ENOSPC;
      return fail("write");
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) return fail("fsync");
  if (::close(fd) != 0) return io_error(fmt::format("cannot write {}: {} (close)", final_name, std::strerror(errno)));
  return {};
}

std::expected<void, Error> StagedOutput::publish(const std::function<bool(const std::string&)>& is_stale) {
  std::error_code ec;
  // report.json first out and last in: a folder without one holds no finished set.
  fs::remove(dir_ / "report.json", ec);
  for (const auto& entry : fs::directory_iterator(dir_, ec)) {
    const std::string name = entry.path().filename().string();
    if (is_stale(name) && std::find(staged_.begin(), staged_.end(), name) == staged_.end()) fs::remove(entry.path(), ec);
  }
  std::stable_partition(staged_.begin(), staged_.end(), [](const std::string& n) { return n != "report.json"; });
  for (const std::string& name : staged_) {
    if (::rename(tmp_path(dir_, name).c_str(), (dir_ / name).c_str()) != 0)
      return io_error(fmt::format("cannot write {}: {} (rename)", (dir_ / name).string(), std::strerror(errno)));
  }
  sync_dir(dir_);
  published_ = true;
  staged_.clear();
  created_.clear();
  return {};
}

}  // namespace lamina::cli
