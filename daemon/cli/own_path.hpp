#pragma once
// Where this program's file is (the kernel's link), or nothing when it cannot be read: the STEP
// module is looked for beside it, and the huge-page restart runs it again by that name.
#include <filesystem>
#include <optional>
#include <system_error>

namespace lamina::cli {

inline std::optional<std::filesystem::path> own_program_path() {
  std::error_code ec;
  std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return std::nullopt;
  return self;
}

}  // namespace lamina::cli
