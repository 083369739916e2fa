// Hostile input: random bytes, random text, every prefix of valid files, and random byte
// mutations. The readers must return an error (or, for mutations, a consistent result) and never crash.
#include "io_test_util.hpp"
#include "lamina/core/mesh_io.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>

namespace lamina {
namespace {

using test::as_bytes;
using test::binary_stl;
using test::find_note;
using test::StlFacet;

std::vector<StlFacet> some_facets(int n) {
  std::vector<StlFacet> out;
  for (int i = 0; i < n; ++i) {
    const float f = static_cast<float>(i);
    out.push_back({{0, 0, 1}, {f, 0, 0}, {f + 1, 0, 0}, {f, 1, 0.5f * f}});
  }
  return out;
}

TEST(Garbage, RandomBytesAreRejected) {
  std::mt19937 rng(12345);
  for (int round = 0; round < 3000; ++round) {
    std::uniform_int_distribution<std::size_t> len_dist(0, round < 2000 ? 300 : 5000);
    std::vector<std::byte> bytes(len_dist(rng));
    for (auto& b : bytes) b = static_cast<std::byte>(rng() & 0xff);
    auto stl = parse_stl(bytes, "random.bin");
    ASSERT_FALSE(stl) << "round " << round << ": random bytes accepted as " << stl->format;
    const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    auto obj = parse_obj(text, "random.obj");
    ASSERT_FALSE(obj) << "round " << round << ": random bytes accepted as OBJ";
  }
}

TEST(Garbage, RandomKeywordTextIsRejected) {
  // Plausible tokens in implausible order: exercises every error branch of both text parsers.
  const std::vector<std::string> words = {"solid", "facet", "normal", "outer", "loop", "vertex", "endloop",
                                          "endfacet", "endsolid", "1.5", "-2", "1e5", "nan", "x", "v", "f",
                                          "1/2/3", "-1", "0", "//", "\n", "\r\n", "\t", "#", "+", "1e"};
  std::mt19937 rng(777);
  int stl_errors = 0, obj_errors = 0;
  for (int round = 0; round < 3000; ++round) {
    std::string text = round % 2 == 0 ? "solid " : "";
    std::uniform_int_distribution<std::size_t> n_dist(0, 60), w_dist(0, words.size() - 1);
    for (std::size_t n = n_dist(rng); n > 0; --n) text += words[w_dist(rng)] + " ";
    auto stl = parse_stl(as_bytes(text), "words.stl");
    ASSERT_FALSE(stl) << text;
    stl_errors += stl.error().code == ErrorCode::parse_error;
    auto obj = parse_obj(text, "words.obj");
    if (!obj) ++obj_errors;
  }
  EXPECT_GT(stl_errors, 1000);  // the "solid" half reaches the ASCII parser and fails there
  EXPECT_GT(obj_errors, 2900);
}

TEST(Garbage, EveryPrefixOfABinaryStlIsAnError) {
  const auto full = binary_stl(some_facets(3), "prefix test");
  ASSERT_TRUE(parse_stl(full, "full.stl"));
  for (std::size_t n = 0; n < full.size(); ++n) {
    auto r = parse_stl(std::span(full).first(n), "prefix.stl");
    ASSERT_FALSE(r) << n;
    const ErrorCode expected =
        n == 0 ? ErrorCode::empty_mesh : (n < 84 ? ErrorCode::unknown_format : ErrorCode::truncated_file);
    EXPECT_EQ(r.error().code, expected) << n << ": " << r.error().message;
    if (n >= 84) {
      const std::string complete = std::to_string((n - 84) / 50) + " complete triangles";
      EXPECT_NE(r.error().message.find(complete), std::string::npos) << r.error().message;
    }
  }
}

TEST(Garbage, PrefixesOfAnAsciiStlFailOrAreNotedAsCut) {
  std::string full = "solid cut\n";
  for (int i = 0; i < 3; ++i) {
    full += "facet normal 0 0 1\n outer loop\n  vertex " + std::to_string(i) +
            " 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\nendfacet\n";
  }
  full += "endsolid cut\n";
  const std::size_t endsolid_at = full.find("endsolid");
  for (std::size_t n = 0; n <= full.size(); ++n) {
    auto r = parse_stl(as_bytes(std::string_view(full).substr(0, n)), "ascii_prefix.stl");
    if (!r) continue;
    EXPECT_LE(r->triangle_count(), 3u);
    // Accepted only when the cut falls after a whole facet: either at/after "endsolid" or noted.
    if (n < endsolid_at + 8) {
      EXPECT_NE(find_note(*r, "missing_endsolid"), nullptr) << n;
    } else {
      EXPECT_EQ(r->triangle_count(), 3u) << n;
    }
  }
}

TEST(Garbage, MutatedFilesNeverCrashAndStayConsistent) {
  const auto binary = binary_stl(some_facets(20), "mutation");
  std::string ascii = "solid m\n";
  for (int i = 0; i < 10; ++i)
    ascii += "facet normal 0 0 1 outer loop vertex 1 2 3 vertex 4 5 6 vertex 7 8 9 endloop endfacet\n";
  ascii += "endsolid m\n";
  std::string obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nf 1 2 3 4\nf 1 2 5\nf 2 3 5\nf -1 -2 -3\n";

  std::mt19937 rng(4242);
  std::size_t accepted = 0;
  for (int round = 0; round < 4000; ++round) {
    std::vector<std::byte> b = binary;
    std::string a = ascii, o = obj;
    std::uniform_int_distribution<int> flips(1, 4);
    for (int k = flips(rng); k > 0; --k) {
      b[rng() % b.size()] = static_cast<std::byte>(rng() & 0xff);
      a[rng() % a.size()] = static_cast<char>(rng() & 0xff);
      o[rng() % o.size()] = static_cast<char>(rng() & 0xff);
    }
    if (auto r = parse_stl(b, "m.stl")) {
      ++accepted;
      EXPECT_EQ(r->format, "stl-binary");
      EXPECT_LE(84 + 50 * r->triangle_count(), b.size());
      // Fewer triangles than the original only through a smaller count field, leaving trailing bytes.
      if (r->triangle_count() < 20) {
        EXPECT_NE(find_note(*r, "trailing_bytes"), nullptr);
      }
    }
    if (std::equal(b.begin() + 80, b.begin() + 84, binary.begin() + 80)) {
      auto r = parse_stl(b, "m.stl");
      ASSERT_TRUE(r) << r.error().message;  // the count still fits: only values changed
      EXPECT_EQ(r->triangle_count(), 20u);
    }
    if (auto r = parse_stl(as_bytes(a), "m.stl")) {
      EXPECT_LE(r->triangle_count(), 10u);
    }
    if (auto r = parse_obj(o, "m.obj")) {
      EXPECT_LE(r->triangle_count(), 10u);
    }
  }
  EXPECT_GT(accepted, 100u);  // most flips hit coordinates, not the count
}

}  // namespace
}  // namespace lamina
