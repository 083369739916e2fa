#pragma once
// Files a client names by path (job.submit's model, settings.stock_file). laminad can read more
// than the client should: the path must lie inside one of the configured roots ([jobs] roots),
// as the file actually opened (a symlink out of a root is refused), be a regular file (a FIFO
// would block the planner, /dev/zero would never end) and within a size limit. The file is
// copied into the job's folder at once, so the job plans what was checked — and keeps the model
// it was planned from, whatever happens to the shop's copy later.
//
// Messages name the path and what is wrong, never the file's bytes; a path outside the roots is
// refused before the filesystem is asked, so the answer does not tell whether it exists.
#include <cstdint>
#include <expected>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "job_error.hpp"

namespace lamina::daemon {

struct ClientFileRules {
  std::vector<std::filesystem::path> roots;  // absolute folders
  std::uint64_t max_bytes = 0;
};

// `param` names the parameter in messages ("model", "settings.stock_file"). Blocking file I/O.
// Returns the copy's path: target_dir / the file's name.
std::expected<std::filesystem::path, JobError> import_client_file(const std::string& path, std::string_view param,
                                                                  const ClientFileRules& rules,
                                                                  const std::filesystem::path& target_dir);

// Lexically inside one of the roots (no "..", no filesystem access).
bool inside_roots(const std::filesystem::path& path, const std::vector<std::filesystem::path>& roots);

}  // namespace lamina::daemon
