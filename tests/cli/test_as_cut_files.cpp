// The sheets as cut, read at the CLI's edge (as_cut_files.hpp, `lamina plan --as-cut DIR`): a
// record is lamina-sim's format, cut from this plan's own program (its fingerprint), and every
// broken part of it is named by file and key; a missing sheet says how to make it. Nothing is
// written when the as-cut cannot be read.
#include "as_cut_files.hpp"
#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>

namespace {

using namespace lamina_cli_test;
using lamina_cli_test::lamina;  // the function, not namespace lamina (the files share a unity build)
using lamina::cli::parse_cut_sheet;
using lamina::cli::program_fingerprint;

const std::string kProgram = "G21\nG1X10F100\n";

nlohmann::json record() {
  return {{"format", "lamina-sim as-cut 1"},
          {"program", "sheet-2.nc"},
          {"program_fnv1a64", program_fingerprint(kProgram)},
          {"sheet_thickness_mm", 5.0},
          {"cut_blocks", 3},
          {"sections", {{{"depth_mm", 2.5}, {"pieces", {{{0, 0, 10, 0, 10, 10, 0, 10}, {2, 2, 2, 4, 4, 4, 4, 2}}}}}}}};
}

std::string error_of(const nlohmann::json& j) {
  auto r = parse_cut_sheet(j.dump(), "sheet-2.ascut.json", 2, kProgram);
  return r ? std::string("(read)") : r.error().message;
}

TEST(AsCutFiles, ARecordReadsIntoPiecesWithTheirHoles) {
  auto r = parse_cut_sheet(record().dump(), "sheet-2.ascut.json", 2, kProgram);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->sheet, 2);
  EXPECT_EQ(r->thickness_mm, 5.0);
  ASSERT_EQ(r->sections.size(), 1u);
  ASSERT_EQ(r->sections[0].pieces.size(), 1u);
  ASSERT_EQ(r->sections[0].pieces[0].rings.size(), 2u);
  EXPECT_EQ(r->sections[0].pieces[0].rings[1][2], Eigen::Vector2d(4, 4));
  EXPECT_EQ(program_fingerprint("a"), "af63dc4c8601ec8c") << "FNV-1a 64, as lamina-sim writes it";
}

TEST(AsCutFiles, EveryBrokenPartIsNamedByFileAndKey) {
  EXPECT_EQ(error_of(nlohmann::json::array()), "sheet-2.ascut.json: not a JSON object");
  auto j = record();
  j["format"] = "something else";
  EXPECT_NE(error_of(j).find("sheet-2.ascut.json: format"), std::string::npos) << error_of(j);
  j = record();
  j["program_fnv1a64"] = "0000000000000000";
  EXPECT_NE(error_of(j).find("cut from another program (fingerprint 0000000000000000, this plan's is " +
                             program_fingerprint(kProgram)),
            std::string::npos)
      << error_of(j);
  j = record();
  j.erase("sheet_thickness_mm");
  EXPECT_NE(error_of(j).find("sheet_thickness_mm: missing"), std::string::npos) << error_of(j);
  j = record();
  j["sections"][0]["pieces"][0][1] = {1, 2, 3};
  EXPECT_NE(error_of(j).find("sections[0]: pieces[0][1]: a ring is [x, y, x, y, …] of 3 points or more"), std::string::npos)
      << error_of(j);
  j = record();
  j["sections"][0]["pieces"][0][0][3] = "ten";
  EXPECT_NE(error_of(j).find("sections[0]: pieces[0][0][2]: not a number"), std::string::npos) << error_of(j);
  j = record();
  j["sections"][0].erase("depth_mm");
  EXPECT_NE(error_of(j).find("sections[0]: a section is"), std::string::npos) << error_of(j);
}

TEST(AsCutFiles, AMissingSheetSaysHowToCutItAndNothingIsWritten) {
  TempDir cut("as-cut-missing", TempDir::made);
  TempDir out("as-cut-out");
  const CliRun r = lamina_cli_test::lamina("plan " + quoted(kKnob) + " --stock 5 --dowels 0 --out " + quoted(out.path) + " --as-cut " + quoted(cut.path));
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find("sheet-1.ascut.json is missing (cut sheet-1.nc on the machine: lamina-sim --as-cut"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out.path)) << "no plan written when the as-cut cannot be read";
}

}  // namespace
