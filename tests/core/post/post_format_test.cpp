// Compact lines and framing: number text, modal words, dialect framing, markers, comments.
#include "post_toolpaths.hpp"

#include "lamina/core/post.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

using lamina::HeadKinematics;
using lamina::PostDialect;
using lamina::PostParams;

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

std::string strip_comments(const std::string& line) { return std::regex_replace(line, std::regex(R"(\([^)]*\))"), ""); }

lamina::PostedProgram post(PostDialect d, bool rtcp, const std::string& title = "sheet 1") {
  HeadKinematics head;
  head.rtcp = rtcp;
  PostParams params;
  params.dialect = d;
  params.title = title;
  // Values that print as -0, whole numbers and trailing zeros: a vertical square at the origin.
  auto posted = lamina::post_program(
      post_test::make_toolpath({post_test::vertical_rectangle({-0.0001, 0}, 10, 2.5, 2),
                                post_test::cone({50, 50}, 10, 30 * kRadPerDeg, 1.0, 12)}),
      head, params);
  EXPECT_TRUE(posted) << (posted ? "" : posted.error().message);
  return posted ? *posted : lamina::PostedProgram{};
}

TEST(PostFormat, NumbersAreStrippedAndFanucKeepsItsPoint) {
  const std::regex word(R"(([XYZACF])(-?[0-9]*\.?[0-9]*))");
  for (PostDialect d : {PostDialect::grblhal, PostDialect::fanuc, PostDialect::linuxcnc}) {
    const lamina::PostedProgram p = post(d, false);
    int words = 0;
    for (const std::string& line : lines_of(p.text)) {
      const std::string code = strip_comments(line);
      EXPECT_EQ(code.find(' '), std::string::npos) << line;
      EXPECT_LT(line.size(), 70u) << line;
      for (std::sregex_iterator it(code.begin(), code.end(), word), end; it != end; ++it) {
        const std::string n = (*it)[2];
        ++words;
        EXPECT_NE(n, "-0") << line;
        EXPECT_NE(n, "-0.") << line;
        const auto point = n.find('.');
        if (d == PostDialect::fanuc) {
          EXPECT_NE(point, std::string::npos) << "fanuc number without a point: " << line;
        } else {
          EXPECT_NE(n.back(), '.') << line;
        }
        if (point != std::string::npos && point + 1 < n.size()) {
          EXPECT_NE(n.back(), '0') << "trailing zero: " << line;
        }
      }
    }
    EXPECT_GT(words, 20);
    EXPECT_NE(p.text.find(d == PostDialect::fanuc ? "X0.Y0." : "X0Y0"), std::string::npos) << p.text;
  }
}

TEST(PostFormat, Framing) {
  const auto fanuc = lines_of(post(PostDialect::fanuc, true, "Job 7 (AlMg3)").text);
  ASSERT_GT(fanuc.size(), 6u);
  EXPECT_EQ(fanuc.front(), "%");
  EXPECT_EQ(fanuc[1], "O1000(JOB 7 ALMG3)");
  EXPECT_EQ(fanuc[2], "G21G90G94G17");
  EXPECT_EQ(fanuc[3], "G43.4H1");
  EXPECT_EQ(fanuc.back(), "%");
  EXPECT_EQ(fanuc[fanuc.size() - 2], "M30");
  EXPECT_EQ(fanuc[fanuc.size() - 3], "G49");

  const auto linuxcnc = lines_of(post(PostDialect::linuxcnc, false, "msg, do not show").text);
  EXPECT_EQ(linuxcnc[0], "(JOB MSG DO NOT SHOW)");  // not a LinuxCNC (MSG,...) comment
  EXPECT_EQ(linuxcnc[1], "G21G90G94G17G40G49");
  EXPECT_EQ(linuxcnc.back(), "M2");

  const auto grbl = lines_of(post(PostDialect::grblhal, false).text);
  EXPECT_EQ(grbl[0], "(SHEET 1)");
  EXPECT_EQ(grbl[1], "G21G90G94G17");
  EXPECT_EQ(grbl.back(), "M2");
}

TEST(PostFormat, PierceIsJetOnThenDwellInTheDialectsUnit) {
  const auto grbl = post(PostDialect::grblhal, false).text;
  EXPECT_NE(grbl.find("\nM3\nG4P1.25\n"), std::string::npos) << grbl;
  const auto fanuc = post(PostDialect::fanuc, false).text;
  EXPECT_NE(fanuc.find("\nM3\nG4P1250\n"), std::string::npos) << fanuc;  // milliseconds
  EXPECT_NE(fanuc.find("\nM5\n"), std::string::npos);
}

TEST(PostFormat, ContourMarkerRestatesModalWords) {
  const lamina::PostedProgram p = post(PostDialect::linuxcnc, false);
  const auto lines = lines_of(p.text);
  ASSERT_EQ(p.contour_lines.size(), 2u);
  for (std::size_t n : p.contour_lines) {
    ASSERT_LT(n, lines.size());
    EXPECT_EQ(lines[n - 1].rfind("(CONTOUR ", 0), 0u);
    // The first line after the marker is a full G0 with every axis.
    EXPECT_TRUE(std::regex_match(lines[n], std::regex(R"((G94)?G0X[-0-9.]+Y[-0-9.]+Z[-0-9.]+A[-0-9.]+C[-0-9.]+)")))
        << lines[n];
  }
}

}  // namespace
