#pragma once
// The files of `lamina plan DIR` as one change (issue 17, item 6): a run that fails leaves DIR
// as it found it — not created when it was missing, no new stack.stl beside an old report, no
// empty folder. Every file is first written and flushed beside its final name (".NAME.tmp");
// only when all are, the old set's files go and the new ones are renamed into place, report.json
// last (it names the set). A failure before that removes what was staged and the folders made.
#include "lamina/core/error.hpp"

#include <expected>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace lamina::cli {

// Can DIR be written (it exists as a folder we may write, or the nearest folder that exists
// above it can be written in)? Checked before planning; creates nothing.
std::expected<void, Error> check_out_dir(const std::string& dir);

class StagedOutput {
 public:
  // Creates DIR (and its missing parents) now; they are removed again unless publish() succeeds.
  static std::expected<StagedOutput, Error> open(const std::string& dir);
  StagedOutput(StagedOutput&& other) noexcept;
  StagedOutput& operator=(StagedOutput&&) = delete;
  ~StagedOutput();

  // Writes DIR/.NAME.tmp and flushes it to disk.
  std::expected<void, Error> stage(const std::string& name, std::string_view bytes);
  // Removes DIR's files for which is_stale(name) holds and that this set does not hold, then
  // renames the staged files into place (report.json last) and syncs DIR.
  std::expected<void, Error> publish(const std::function<bool(const std::string&)>& is_stale);

  const std::filesystem::path& dir() const { return dir_; }

 private:
  explicit StagedOutput(std::filesystem::path dir, std::vector<std::filesystem::path> created);
  void discard();

  std::filesystem::path dir_;
  std::vector<std::filesystem::path> created_;  // folders made by open(), deepest last
  std::vector<std::string> staged_;             // final names, in staging order
  bool published_ = false;
};

}  // namespace lamina::cli
