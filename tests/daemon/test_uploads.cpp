// Uploads in chunks: base64, order, gaps, sizes and names refused with the parameter named.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace lamina::daemon
