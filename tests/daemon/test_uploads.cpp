// Uploads in chunks: base64, order, gaps, sizes and names refused with the parameter named.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "sim_process.hpp"
#include "uploads.hpp"

namespace lamina::daemon {
namespace {

std::string read_all(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(Base64, DecodesTheRfcVectorsAndRefusesNonsense) {
  EXPECT_EQ(decode_base64(""), "");
  EXPECT_EQ(decode_base64("Zg=="), "f");
  EXPECT_EQ(decode_base64("Zm8="), "fo");
  EXPECT_EQ(decode_base64("Zm9v"), "foo");
  EXPECT_EQ(decode_base64("Zm9vYmFy"), "foobar");
  EXPECT_EQ(decode_base64("AP8A"), std::string("\0\xff\0", 3));
  EXPECT_FALSE(decode_base64("Zm9"));      // not a multiple of 4
  EXPECT_FALSE(decode_base64("Zm=v"));     // padding inside
  EXPECT_FALSE(decode_base64("Zm9v!A=="));  // outside the alphabet
  EXPECT_FALSE(decode_base64("Z==="));
}

TEST(Uploads, ChunksInOrderMakeTheFile) {
  sim::testing::TempDir dir;
  Uploads uploads(dir.file("uploads"));
  auto id = uploads.begin("part.stl", 6);
  ASSERT_TRUE(id) << id.error().message;
  EXPECT_FALSE(uploads.take(*id)) << "not complete yet";
  auto r = uploads.chunk(*id, 0, "Zm9v");
  ASSERT_TRUE(r);
  EXPECT_EQ(*r, 3u);
  EXPECT_TRUE(uploads.chunk(*id, 0, "Zm9v")) << "the same chunk again (a retry) is fine";
  auto gap = uploads.chunk(*id, 4, "YmFy");
  ASSERT_FALSE(gap);
  EXPECT_NE(gap.error().message.find("offset"), std::string::npos);
  ASSERT_TRUE(uploads.chunk(*id, 3, "YmFy"));
  auto past = uploads.chunk(*id, 6, "YQ==");
  ASSERT_FALSE(past) << "beyond the announced size";
  auto file = uploads.take(*id);
  ASSERT_TRUE(file);
  EXPECT_EQ(read_all(*file), "foobar");
  EXPECT_FALSE(uploads.take(*id)) << "taken once";
}

TEST(Uploads, NamesSizesAndDataAreChecked) {
  sim::testing::TempDir dir;
  UploadLimits limits;
  limits.max_file_bytes = 100;
  limits.max_open = 2;
  Uploads uploads(dir.file("uploads"), limits);
  for (const char* bad : {"../etc/passwd.stl", "a/b.stl", ".hidden.stl", "notes.txt", ""}) {
    auto r = uploads.begin(bad, 10);
    ASSERT_FALSE(r) << bad;
    EXPECT_NE(r.error().message.find("params.name"), std::string::npos) << r.error().message;
  }
  // A NUL (or any control character) would cut the name on disk short of the one checked.
  for (const std::string& bad : {std::string("part\0.txt.stl", 13), std::string("part\n.stl")}) {
    auto r = uploads.begin(bad, 10);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("control characters"), std::string::npos) << r.error().message;
  }
  EXPECT_FALSE(uploads.begin("big.stl", 101));
  EXPECT_FALSE(uploads.begin("empty.stl", 0));
  auto a = uploads.begin("a.STL", 10);
  ASSERT_TRUE(a);
  EXPECT_TRUE(uploads.begin("b.obj", 10));
  EXPECT_FALSE(uploads.begin("c.3mf", 10)) << "at most 2 unfinished";
  auto bad = uploads.chunk(*a, 0, "not base64!");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("params.data"), std::string::npos);
  EXPECT_FALSE(uploads.chunk("u999", 0, "Zm9v"));
}

// The id is the upload's only key: another client must not be able to guess it (it was "u1",
// "u2"…, so anyone could append to, or take, another client's upload).
TEST(Uploads, IdsAreUnguessable) {
  sim::testing::TempDir dir;
  Uploads uploads(dir.file("uploads"));
  auto a = uploads.begin("a.stl", 3), b = uploads.begin("b.stl", 3);
  ASSERT_TRUE(a && b);
  EXPECT_NE(*a, *b);
  EXPECT_EQ(a->size(), 33u) << *a << ": 'u' and 128 bits in hex";
  EXPECT_EQ(a->find_first_not_of("0123456789abcdef", 1), std::string::npos) << *a;
  EXPECT_FALSE(uploads.chunk("u1", 0, "Zm9v"));
  EXPECT_FALSE(uploads.take("u2"));
}

// 16 unfinished uploads used to block every upload until a restart: an upload with no chunk
// for idle_s is dropped, with its file; cancel frees a slot at once.
TEST(Uploads, IdleUploadsExpireAndCancelFreesTheSlot) {
  sim::testing::TempDir dir;
  UploadLimits limits;
  limits.max_open = 2;
  limits.idle_s = 60;
  Uploads uploads(dir.file("uploads"), limits);
  const auto t0 = Uploads::Clock::time_point{} + std::chrono::hours(1);
  using std::chrono::seconds;
  auto a = uploads.begin("a.stl", 6, t0), b = uploads.begin("b.stl", 6, t0);
  ASSERT_TRUE(a && b);
  EXPECT_FALSE(uploads.begin("c.stl", 6, t0 + seconds(59))) << "both slots in use";
  ASSERT_TRUE(uploads.chunk(*a, 0, "Zm9v", t0 + seconds(50))) << "a chunk keeps an upload alive";
  auto c = uploads.begin("c.stl", 6, t0 + seconds(61));
  ASSERT_TRUE(c) << "b had no chunk for 61 s: " << c.error().message;
  EXPECT_EQ(uploads.open_count(), 2u);
  auto gone = uploads.chunk(*b, 0, "Zm9v", t0 + seconds(62));
  ASSERT_FALSE(gone);
  EXPECT_NE(gone.error().message.find("expired"), std::string::npos) << gone.error().message;
  std::size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.file("uploads"))) files += e.is_regular_file();
  EXPECT_EQ(files, 2u) << "the expired upload's file is deleted";

  ASSERT_TRUE(uploads.cancel(*c));
  EXPECT_FALSE(uploads.cancel(*c)) << "once";
  EXPECT_FALSE(uploads.take(*c));
  EXPECT_TRUE(uploads.begin("d.stl", 6, t0 + seconds(63))) << "the cancelled upload's slot is free";
}

}  // namespace
}  // namespace lamina::daemon
