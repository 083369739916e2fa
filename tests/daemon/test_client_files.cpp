// Files a client names by path (issue 16, item 9): `job.submit {"model": "/etc/shadow"}` used to
// hand the file to the planner and its first bytes back in job.error. Only files inside the
// configured roots, regular, bounded; messages name the path, never the file's bytes.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include "client_files.hpp"
#include "sim_process.hpp"

namespace lamina::daemon {
namespace {

namespace fs = std::filesystem;

constexpr const char* kSecret = "solid TOP-SECRET-BYTES\n";

struct Folders {
  sim::testing::TempDir dir;
  fs::path parts = dir.file("parts"), outside = dir.file("outside"), job = dir.file("job");
  ClientFileRules rules;
  Folders() {
    fs::create_directories(parts);
    fs::create_directories(outside);
    std::ofstream(outside / "secret.stl") << kSecret;
    std::ofstream(parts / "part.stl") << "solid part\nendsolid part\n";
    rules.roots = {parts};
    rules.max_bytes = 1000;
  }
  std::expected<fs::path, JobError> import(const std::string& path) const {
    return import_client_file(path, "model", rules, job);
  }
};

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(ClientFiles, APartInsideARootIsCopiedIntoTheJob) {
  Folders f;
  auto copy = f.import((f.parts / "part.stl").string());
  ASSERT_TRUE(copy) << copy.error().message;
  EXPECT_EQ(*copy, f.job / "part.stl");
  EXPECT_EQ(read_all(*copy), read_all(f.parts / "part.stl"));
  // A symlink that stays inside the roots is fine (shops link part revisions).
  fs::create_symlink(f.parts / "part.stl", f.parts / "current.stl");
  auto linked = import_client_file((f.parts / "current.stl").string(), "model", f.rules, f.dir.file("job2"));
  ASSERT_TRUE(linked) << linked.error().message;
  EXPECT_EQ(read_all(*linked), read_all(f.parts / "part.stl"));
}

// Refused before the filesystem is asked: the answer is the same whether the file exists.
TEST(ClientFiles, APathOutsideTheRootsIsRefusedWithoutTellingWhetherItExists) {
  Folders f;
  const std::string secret = (f.outside / "secret.stl").string(), missing = (f.outside / "missing.stl").string();
  auto a = f.import(secret), b = f.import(missing), shadow = f.import("/etc/shadow");
  ASSERT_FALSE(a);
  ASSERT_FALSE(b);
  ASSERT_FALSE(shadow);
  EXPECT_EQ(a.error().kind, JobErrorKind::bad_request);
  EXPECT_NE(a.error().message.find("outside the folders"), std::string::npos) << a.error().message;
  std::string b_as_a = b.error().message;
  b_as_a.replace(b_as_a.find(missing), missing.size(), secret);
  EXPECT_EQ(a.error().message, b_as_a) << "an existing file and a missing one read alike";
  EXPECT_EQ(a.error().message.find("TOP-SECRET"), std::string::npos);
  EXPECT_EQ(shadow.error().message.find("root:"), std::string::npos) << shadow.error().message;
  EXPECT_FALSE(fs::exists(f.job)) << "nothing was created for a refused file";
  // ".." does not climb out of a root.
  auto climbed = f.import((f.parts / ".." / "outside" / "secret.stl").string());
  ASSERT_FALSE(climbed);
  EXPECT_NE(climbed.error().message.find("outside the folders"), std::string::npos) << climbed.error().message;
  auto relative = f.import("parts/part.stl");
  ASSERT_FALSE(relative);
  EXPECT_NE(relative.error().message.find("absolute"), std::string::npos);
}

TEST(ClientFiles, ASymlinkOutOfARootIsRefused) {
  Folders f;
  fs::create_symlink(f.outside / "secret.stl", f.parts / "innocent.stl");
  fs::create_directory_symlink(f.outside, f.parts / "shared");
  for (const fs::path& p : {f.parts / "innocent.stl", f.parts / "shared" / "secret.stl"}) {
    auto r = f.import(p.string());
    ASSERT_FALSE(r) << p;
    EXPECT_NE(r.error().message.find("leads outside"), std::string::npos) << r.error().message;
    EXPECT_EQ(r.error().message.find("TOP-SECRET"), std::string::npos);
  }
}

// A FIFO used to block the planner forever; /dev/zero grows without end. Neither is opened for
// reading (a hang here is the failure).
TEST(ClientFiles, OnlyRegularFilesWithinTheSizeLimit) {
  Folders f;
  ASSERT_EQ(::mkfifo((f.parts / "fifo.stl").c_str(), 0600), 0);
  fs::create_directory(f.parts / "folder.stl");
  for (const char* name : {"fifo.stl", "folder.stl"}) {
    auto r = f.import((f.parts / name).string());
    ASSERT_FALSE(r) << name;
    EXPECT_NE(r.error().message.find("not a regular file"), std::string::npos) << r.error().message;
  }
  fs::create_symlink("/dev/zero", f.parts / "zero.stl");
  auto zero = f.import((f.parts / "zero.stl").string());
  ASSERT_FALSE(zero);
  EXPECT_NE(zero.error().message.find("leads outside"), std::string::npos) << zero.error().message;

  std::ofstream(f.parts / "empty.stl").flush();
  auto empty = f.import((f.parts / "empty.stl").string());
  ASSERT_FALSE(empty);
  EXPECT_NE(empty.error().message.find("empty"), std::string::npos);
  std::ofstream(f.parts / "big.stl") << std::string(1001, 'x');
  auto big = f.import((f.parts / "big.stl").string());
  ASSERT_FALSE(big);
  EXPECT_NE(big.error().message.find("1001 bytes, more than the 1000 allowed"), std::string::npos) << big.error().message;
  auto missing = f.import((f.parts / "missing.stl").string());
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("no such file"), std::string::npos) << missing.error().message;
}

}  // namespace
}  // namespace lamina::daemon
