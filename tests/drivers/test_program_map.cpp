// Issue 18: the post hands each sheet's contour lines over with the program (report.json's
// contour_lines), and laminad resumes from them instead of parsing comments back. For the posts
// whose comments the marker reader knows, both maps must agree line for line: the knob planned
// through the real CLI, every sheet, every dialect.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lamina/drivers/resume_point.hpp"
#include "sim_process.hpp"

namespace lamina::drivers {
namespace {

std::vector<std::string> lines_of(const std::string& path) {
  std::vector<std::string> lines;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

class PostMap : public ::testing::TestWithParam<const char*> {};

TEST_P(PostMap, TheReportsContourLinesAreTheProgramsMarkers) {
  sim::testing::TempDir dir;
  const std::string out = dir.file("plan");
  const std::string rtcp = std::string(GetParam()) == "grblhal" ? "false" : "true";
  const std::string command = fmt::format("'{}' plan '{}/knob.stl' --stock 5 --microjoints 1 --post {} --rtcp {} --out '{}' >/dev/null",
                                          LAMINA_CLI, LAMINA_EXAMPLES_DIR, GetParam(), rtcp, out);
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  const auto report = nlohmann::json::parse(std::ifstream(out + "/report.json"));
  ASSERT_FALSE(report["sheets"].empty());
  for (const auto& sheet : report["sheets"]) {
    const auto program = lines_of(out + "/" + sheet["program"].get<std::string>());
    ASSERT_EQ(program.size(), sheet["program_lines"].get<std::size_t>());
    const ProgramMap markers = program_map_from_markers(program);
    EXPECT_EQ(markers.setup_end, sheet["setup_lines"].get<std::size_t>());
    const auto& posted = sheet["contour_lines"];
    ASSERT_EQ(markers.contours.size(), posted.size());
    ASSERT_EQ(posted.size(), sheet["contours"].get<std::size_t>());
    for (std::size_t c = 0; c < posted.size(); ++c) {
      SCOPED_TRACE(fmt::format("sheet {} contour {}", sheet["index"].get<int>(), c));
      EXPECT_EQ(markers.contours[c].contour, posted[c]["index"].get<int>());
      EXPECT_EQ(markers.contours[c].start_index + 1, posted[c]["line"].get<std::size_t>());
      ASSERT_TRUE(markers.contours[c].last_cut_index);
      EXPECT_EQ(*markers.contours[c].last_cut_index + 1, posted[c]["last_cut_line"].get<std::size_t>());
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Dialects, PostMap, ::testing::Values("grblhal", "fanuc", "linuxcnc"));

}  // namespace
}  // namespace lamina::drivers
