// Issue 17, item 6: a failed `lamina plan` left an empty --out folder (a missing, empty or folder
// model; a bad --stock; --sub-slice / --deviation-step errors) and a lone new stack.stl when
// nesting failed. Every failure must leave --out as it found it: not there when it was not,
// byte for byte the earlier run's files when it was.
#include "cli_runner.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

namespace {

using namespace lamina_cli_test;
using lamina_cli_test::lamina;  // the function, not namespace lamina (the files share a unity build)

// Every entry of a folder (hidden ones too) with its bytes; folders as "<dir>".
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string name = fs::relative(e.path(), dir).string();
    if (e.is_directory()) {
      files[name] = "<dir>";
      continue;
    }
    std::ifstream in(e.path(), std::ios::binary);
    files[name] = std::string(std::istreambuf_iterator<char>(in), {});
  }
  return files;
}

void write(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

struct Case {
  std::string what;
  std::string args;  // after "plan"; {out} is replaced by the folder
  int exit_code;
};

std::string with_out(std::string args, const fs::path& out) {
  const std::string key = "{out}";
  args.replace(args.find(key), key.size(), quoted(out));
  return args;
}

class PlanFailures : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = temp_file("plan-failures");
    fs::remove_all(root_);
    fs::create_directories(root_ / "model-folder");
    write(root_ / "empty.stl", "");
    // A rack whose sheets are far smaller than the knob: the layering finds no sheet its
    // layers fit (issue 17, item 5: before, the stack succeeded and nesting failed).
    write(root_ / "tiny-rack.toml",
          "[[sheet]]\nthickness_mm = 1.0\nwidth_mm = 20\nlength_mm = 20\ncount = 1\n"
          "[[sheet]]\nthickness_mm = 5.0\nwidth_mm = 20\nlength_mm = 20\ncount = 1\n");
  }
  void TearDown() override { fs::remove_all(root_); }

  std::vector<Case> cases() const {
    const std::string knob = quoted(kKnob);
    return {
        {"a missing model", quoted(root_ / "nope.stl") + " --out {out}", 1},
        {"an empty model", quoted(root_ / "empty.stl") + " --out {out}", 1},
        {"a folder for a model", quoted(root_ / "model-folder") + " --out {out}", 1},
        {"stock thicker than the part", knob + " --stock 1e9 --out {out}", 2},
        {"a sub-slice with too many grid lines", knob + " --sub-slice 1e-6 --stock 1 --out {out}", 2},
        {"a deviation step too fine", knob + " --deviation-step 1e-7 --out {out}", 2},
        {"a bad stock list", knob + " --stock 1,,2 --out {out}", 2},
        {"a rack no layer fits", knob + " --stock-file " + quoted(root_ / "tiny-rack.toml") + " --out {out}", 1},
        {"a missing deviation reference", knob + " --deviation-against " + quoted(root_ / "nope.step") + " --out {out}", 1},
        {"an empty deviation reference", knob + " --deviation-against " + quoted(root_ / "empty.stl") + " --out {out}", 1},
    };
  }

  fs::path root_;
};

TEST_F(PlanFailures, AFolderThatWasNotThereIsNotCreated) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.what);
    const fs::path out = root_ / "new" / "plan";
    const CliRun r = lamina("plan " + with_out(c.args, out));
    EXPECT_EQ(r.exit_code, c.exit_code) << r.out;
    EXPECT_FALSE(r.out.empty()) << "a failed run says why";
    if (c.what.find("deviation reference") != std::string::npos)
      EXPECT_NE(r.out.find("the deviation's reference"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(root_ / "new")) << "the failed run created --out or its parent:\n" << r.out;
  }
}

TEST_F(PlanFailures, AnEarlierRunsFilesAreLeftByteForByte) {
  const fs::path out = root_ / "earlier";
  fs::create_directories(out);
  write(out / "report.json", "{\"earlier\": true}\n");
  write(out / "stack.stl", std::string(84, '\0'));
  write(out / "sheet-1.nc", "G0 X0\n");
  write(out / "sheet-1.svg", "<svg/>\n");
  write(out / "notes.txt", "the operator's own file\n");
  const auto before = snapshot(out);
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.what);
    const CliRun r = lamina("plan " + with_out(c.args, out));
    EXPECT_EQ(r.exit_code, c.exit_code) << r.out;
    EXPECT_EQ(snapshot(out), before) << "the failed run changed --out:\n" << r.out;
  }
}

// The same staging on success: the new set replaces the old, the operator's own file stays and
// no staging file is left behind.
TEST_F(PlanFailures, ASuccessfulRunReplacesTheSetAndLeavesNoStagingFile) {
  const fs::path out = root_ / "again";
  fs::create_directories(out);
  write(out / "sheet-9.nc", "G0 X0\n");
  write(out / "notes.txt", "the operator's own file\n");
  const CliRun r = lamina("plan " + quoted(kKnob) + " --stock 5 --out " + quoted(out));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const auto after = snapshot(out);
  EXPECT_FALSE(after.contains("sheet-9.nc")) << "a sheet of the earlier run this one does not write";
  EXPECT_TRUE(after.contains("notes.txt"));
  EXPECT_TRUE(after.contains("report.json"));
  EXPECT_TRUE(after.contains("stack.stl"));
  for (const auto& [name, bytes] : after) EXPECT_NE(name.front(), '.') << "staging file left: " << name;
}

}  // namespace
