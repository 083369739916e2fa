#pragma once
// Runs the `lamina` program as a user would (through the shell) and collects what it prints.
#include <array>
#include <cstdio>
#include <filesystem>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace lamina_cli_test {

namespace fs = std::filesystem;

struct CliRun {
  int exit_code = -1;
  std::string out;  // stdout and stderr together, or stdout only (lamina_stdout)
};

// `redirect` is appended to the command line: "2>&1" merges stderr, "2>/dev/null" drops it.
// `env`: NAME=value assignments (no spaces) put before the program, for it alone.
inline CliRun run_lamina(const std::string& args, const char* redirect, const std::string& env = "") {
  const std::string cmd = env + (env.empty() ? "" : " ") + std::string(LAMINA_CLI) + " " + args + " " + redirect;
  CliRun r;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf{};
  std::size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
  const int status = ::pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline CliRun lamina(const std::string& args) { return run_lamina(args, "2>&1"); }
inline CliRun lamina_with_env(const std::string& env, const std::string& args) { return run_lamina(args, "2>&1", env); }
inline CliRun lamina_stdout(const std::string& args) { return run_lamina(args, "2>/dev/null"); }

inline std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

inline fs::path shared_model(const char* name) { return fs::path(LAMINA_SHARED_MODELS) / name; }

// A per-process name in the temp folder (tests run in parallel under ctest).
inline fs::path temp_file(const std::string& name) {
  return fs::temp_directory_path() / ("lamina-cli-test-" + std::to_string(::getpid()) + "-" + name);
}

inline const fs::path kKnob = fs::path(LAMINA_EXAMPLES_DIR) / "knob.stl";

// A folder of the test's own, gone afterwards. `made`: created empty now; otherwise only its
// name, for a command that must create it (lamina plan --out).
struct TempDir {
  enum Make { name_only, made };
  fs::path path;
  explicit TempDir(const std::string& name, Make make = name_only) : path(temp_file(name)) {
    fs::remove_all(path);
    if (make == made) fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

}  // namespace lamina_cli_test
