// `lamina plan` against the rack (issue 17, item 5): `lamina plan bowl.stl --stock-file
// examples/remnants.toml` failed at nesting with "not enough 5 mm sheets: 2 in stock". A plan
// fits the rack — no more layers of a thickness than its sheets hold, no layer on a sheet it does
// not fit — or one error, before anything is written, says which thickness runs out.
#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <string>

namespace {

using namespace lamina_cli_test;
using lamina_cli_test::lamina;  // the function, not namespace lamina (the files share a unity build)
using nlohmann::json;

// A truncated cone, r 40 at z 0 to r 20 at z 20 (45°: bevels follow it exactly, so thick sheets
// are the layering's first choice), as ASCII STL.
std::string cone_stl() {
  constexpr int n = 48;
  auto ring = [](double r, double z, int i) {
    const double a = 2 * std::numbers::pi * i / n;
    return std::array<double, 3>{r * std::cos(a), r * std::sin(a), z};
  };
  std::ostringstream s;
  auto facet = [&](std::array<double, 3> a, std::array<double, 3> b, std::array<double, 3> c) {
    s << "facet normal 0 0 0\nouter loop\n";
    for (const auto& v : {a, b, c}) s << "vertex " << v[0] << ' ' << v[1] << ' ' << v[2] << '\n';
    s << "endloop\nendfacet\n";
  };
  s.precision(12);
  s << "solid cone\n";
  for (int i = 0; i < n; ++i) {
    const auto b0 = ring(40, 0, i), b1 = ring(40, 0, i + 1), t0 = ring(20, 20, i), t1 = ring(20, 20, i + 1);
    facet(b0, b1, t1);
    facet(b0, t1, t0);
    facet({0, 0, 0}, b1, b0);
    facet({0, 0, 20}, t0, t1);
  }
  s << "endsolid cone\n";
  return s.str();
}

std::string sheet(double t, double size, int count) {
  return "[[sheet]]\nthickness_mm = " + std::to_string(t) + "\nwidth_mm = " + std::to_string(size) +
         "\nlength_mm = " + std::to_string(size) + "\ncount = " + std::to_string(count) + "\n";
}

json read_report(const fs::path& dir) {
  std::ifstream in(dir / "report.json");
  return json::parse(in);
}

TEST(CliPlanRack, ThePlanFitsTheRacksCounts) {
  TempDir dir("plan-rack", TempDir::made);
  std::ofstream(dir.path / "cone.stl") << cone_stl();
  // One Ø80 layer (Ø81 with the kerf) per 110 mm sheet: the rack holds one 5 mm layer, the cone alone would take four.
  std::ofstream(dir.path / "rack.toml") << sheet(1.0, 400, 2) + sheet(2.5, 400, 2) + sheet(5.0, 110, 1);
  const std::string model = quoted(dir.path / "cone.stl");
  const auto free = lamina("plan " + model + " --stock 1,2.5,5 --no-programs --json --out " + quoted(dir.path / "free"));
  ASSERT_EQ(free.exit_code, 0) << free.out;
  ASSERT_GT(read_report(dir.path / "free")["stack"]["sheets_used"].value("5", 0), 1) << "the rack must matter";

  const auto r = lamina("plan " + model + " --stock-file " + quoted(dir.path / "rack.toml") + " --out " +
                        quoted(dir.path / "out"));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("the rack's 5 mm sheets"), std::string::npos) << r.out;
  const json j = read_report(dir.path / "out");
  std::map<double, int> sheets;
  for (const json& s : j["sheets"]) ++sheets[s["thickness_mm"].get<double>()];
  EXPECT_LE(sheets[5.0], 1);
  EXPECT_LE(sheets[2.5], 2);
  EXPECT_LE(sheets[1.0], 2);
  EXPECT_LE(j["stack"]["sheets_used"].value("5", 0), 1);
  EXPECT_GE(j["stack"]["stack_height_mm"].get<double>(), 20.0 - 1e-6);
}

TEST(CliPlanRack, ARackThatCannotMakeTheStackSaysWhichThicknessRunsOut) {
  TempDir dir("plan-rack-short", TempDir::made);
  std::ofstream(dir.path / "cone.stl") << cone_stl();
  // 5 mm sheets only, two of them holding one layer each: 10 mm of the cone's 20.
  std::ofstream(dir.path / "rack.toml") << sheet(5.0, 110, 2);
  const auto r = lamina("plan " + quoted(dir.path / "cone.stl") + " --stock-file " + quoted(dir.path / "rack.toml") +
                        " --out " + quoted(dir.path / "out"));
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find("stock_exhausted"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("5 mm: at most 2 layer(s)"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir.path / "out")) << "nothing is written";

  // A sheet no layer fits: said by the layering, not by a nesting failure after the stack.
  std::ofstream(dir.path / "small.toml") << sheet(5.0, 50, 10);
  const auto small = lamina("plan " + quoted(dir.path / "cone.stl") + " --stock-file " +
                            quoted(dir.path / "small.toml") + " --out " + quoted(dir.path / "out"));
  EXPECT_EQ(small.exit_code, 1) << small.out;
  EXPECT_NE(small.out.find("no larger than 29 x 29 mm"), std::string::npos) << small.out;
}

// Where each sheet lies on the rack (issue 19: the operator's prompt names the slot): a stock
// entry's `slot` goes to every sheet cut from it, in the report and the sheet table.
TEST(CliPlanRack, EverySheetSaysWhichRackSlotItComesFrom) {
  TempDir dir("plan-rack-slots", TempDir::made);
  std::ofstream(dir.path / "cone.stl") << cone_stl();
  // One 5 mm sheet that holds one layer (as above): the rest of the cone comes from the 2.5 mm entry.
  std::ofstream(dir.path / "rack.toml") << sheet(2.5, 400, 4) + "slot = \"R2 left\"\n" + sheet(5.0, 110, 1) + "slot = \"R7\"\n";
  const auto r = lamina("plan " + quoted(dir.path / "cone.stl") + " --stock-file " + quoted(dir.path / "rack.toml") +
                        " --out " + quoted(dir.path / "out"));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const json j = read_report(dir.path / "out");
  ASSERT_EQ(j["settings"]["stock"].size(), 2u);
  EXPECT_EQ(j["settings"]["stock"][0]["slot"], "R2 left");
  EXPECT_EQ(j["settings"]["stock"][1]["slot"], "R7");
  std::map<double, int> sheets;
  for (const json& s : j["sheets"]) {
    ++sheets[s["thickness_mm"].get<double>()];
    EXPECT_EQ(s.value("slot", ""), s["thickness_mm"].get<double>() == 5.0 ? "R7" : "R2 left") << s.dump();
  }
  EXPECT_GT(sheets.size(), 1u) << "both entries must be cut from: " << j["sheets"].dump();
  EXPECT_NE(r.out.find("(slot R7)"), std::string::npos) << r.out;

  // No slot given: no key in the report (and reports without one still read: PlanReportJson).
  const auto plain = lamina("plan " + quoted(dir.path / "cone.stl") + " --stock 5 --out " + quoted(dir.path / "plain"));
  ASSERT_EQ(plain.exit_code, 0) << plain.out;
  const json unslotted = read_report(dir.path / "plain");
  for (const json& s : unslotted["sheets"]) EXPECT_FALSE(s.contains("slot")) << s.dump();
}

TEST(CliPlanRack, ASlotThatIsNoLabelIsRefusedWithItsLine) {
  TempDir dir("plan-rack-bad-slot", TempDir::made);
  std::ofstream(dir.path / "cone.stl") << cone_stl();
  for (const std::string& bad : {std::string("slot = \"\""), std::string("slot = 3"), std::string("slot = \"") + std::string(41, 'x') + "\"",
                                 std::string("slot = \"R1\\u0007\"")}) {
    std::ofstream(dir.path / "rack.toml") << sheet(5.0, 400, 4) + bad + "\n";
    const auto r = lamina("plan " + quoted(dir.path / "cone.stl") + " --stock-file " + quoted(dir.path / "rack.toml") +
                          " --out " + quoted(dir.path / "out"));
    EXPECT_EQ(r.exit_code, 1) << bad << "\n" << r.out;
    EXPECT_NE(r.out.find("rack.toml:6"), std::string::npos) << bad << "\n" << r.out;
    EXPECT_NE(r.out.find("slot must be a rack label of 1 … 40 printable characters"), std::string::npos) << bad << "\n" << r.out;
    EXPECT_FALSE(fs::exists(dir.path / "out"));
  }
}

}  // namespace
