// `lamina check|plan FILE.step` as a user runs it: every shared STEP model planned end to end
// (programs, drawings, stack), its report naming the B-rep's faces; a build without OpenCASCADE
// (the sanitizer pass) says so and exits as for any unreadable model.
#include <gtest/gtest.h>

#include "cli_runner.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <vector>

namespace lamina_cli_test {
namespace {

using json = nlohmann::json;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A build without OpenCASCADE answers any .step so, before it looks for the file.
bool reads_step() { return lamina("check /nonexistent.step").out.find("without STEP support") == std::string::npos; }

class CliStepModels : public ::testing::TestWithParam<const char*> {};

TEST_P(CliStepModels, PlansEndToEnd) {
  const fs::path model = shared_model(GetParam());
  if (!fs::exists(model)) GTEST_SKIP() << model << " is not here";
  if (!reads_step()) GTEST_SKIP() << "built without STEP support (covered by CliStep.WithoutSupportSaysSo)";
  TempDir out("step");
  const auto r = lamina("plan " + quoted(model) + " --out " + quoted(out.path));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const json j = json::parse(slurp(out.path / "report.json"));
  EXPECT_EQ(j["model"]["format"], "step");
  ASSERT_FALSE(j["sheets"].empty());
  for (const json& s : j["sheets"]) {
    EXPECT_TRUE(fs::exists(out.path / s["program"].get<std::string>())) << s["program"];
    EXPECT_TRUE(fs::exists(out.path / s["svg"].get<std::string>())) << s["svg"];
  }
  EXPECT_TRUE(fs::exists(out.path / "stack.stl"));
  EXPECT_EQ(r.out.find("ISO-10303"), std::string::npos) << "OCCT printed nothing of its own";
  // What the file told the plan: tessellated to a tenth of the tolerance, exact normals, and as
  // many faces by kind as by solid.
  const json& cad = j["model"]["cad"];
  EXPECT_DOUBLE_EQ(cad["chord_tolerance_mm"].get<double>(), j["settings"]["tolerance_mm"].get<double>() / 10);
  EXPECT_EQ(cad["surface_normals"], "exact");
  std::int64_t by_kind = 0, by_solid = 0;
  for (const auto& [kind, faces] : cad["surface_kinds"].items()) by_kind += faces.get<std::int64_t>();
  for (const json& s : cad["solids"]) by_solid += s["faces"].get<std::int64_t>();
  EXPECT_EQ(by_kind, by_solid);
  EXPECT_GT(by_kind, 0);
  // The deviation is measured against the same file ten times finer: the CAD surface to 1/100 of
  // the tolerance.
  const json& reference = j["model"]["deviation_reference"];
  EXPECT_EQ(reference["file"], model.string());
  EXPECT_DOUBLE_EQ(reference["chord_tolerance_mm"].get<double>(), cad["chord_tolerance_mm"].get<double>() / 10);
  EXPECT_GT(reference["triangles"].get<std::int64_t>(), j["model"]["triangles"].get<std::int64_t>());
}

// The metre-sized elbow (1016 mm high) is left out: see docs/step.md.
INSTANTIATE_TEST_SUITE_P(Shared, CliStepModels,
                         ::testing::Values("step_cube_cylinder.step", "step_featuretype.step",
                                           "step_base_interface_ap203.step", "step_leg_fork.step", "step_m6_screw.step"),
                         [](const auto& info) {
                           std::string n = info.param;
                           return n.substr(5, n.find('.') - 5);
                         });

TEST(CliStep, CheckJsonIsCleanAndNamesTheUnit) {
  const fs::path model = shared_model("step_featuretype.step");
  if (!fs::exists(model) || !reads_step()) GTEST_SKIP();
  TempDir out("step-check");
  fs::create_directories(out.path);
  const auto r = lamina_stdout("check --json " + quoted(out.path / "check.json") + " " + quoted(model));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_EQ(r.out.find("****"), std::string::npos) << "nothing of OCCT's own on stdout: " << r.out;
  const json j = json::parse(slurp(out.path / "check.json"));
  // The shared models' README: inch, one solid of 96 faces (49 plane, 46 cylinder, 1 B-spline).
  EXPECT_EQ(j["cad"]["length_unit"], "INCH") << j.dump();
  EXPECT_EQ(j["cad"]["surface_kinds"], (json{{"plane", 49}, {"cylinder", 46}, {"bspline", 1}}));
  ASSERT_EQ(j["cad"]["solids"].size(), 1u);
  EXPECT_EQ(j["cad"]["solids"][0]["faces"], 96);
  EXPECT_EQ(j["cad"]["chord_tolerance_mm"], 0.02) << "check's default chord";
  EXPECT_NE(r.out.find("B-rep      1 solid, 96 faces (plane 49, cylinder 46, bspline 1); unit INCH"), std::string::npos) << r.out;
  EXPECT_EQ(lamina("check --units in " + quoted(model)).exit_code != 0, true) << "--units is for meshes";
}

// The check on the demo knob: the part as STEP (examples/knob.step, exact) and as its
// 96-segment STL plan to the same layers, and measured against one reference — the STEP
// tessellated to 0.002 mm, which the STL plan is measured against with --deviation-against —
// the STEP plan's deviation is not worse (0.535 % against 0.561 %, 2026-12-06).
TEST(CliStep, TheKnobAsStepPlansTheSameLayersAsItsStlAndNoWorse) {
  if (!reads_step()) GTEST_SKIP() << "built without STEP support";
  const fs::path step = fs::path(kKnob).parent_path() / "knob.step";
  TempDir a("knob-step"), b("knob-stl");
  ASSERT_EQ(lamina("plan " + quoted(step) + " --no-programs --out " + quoted(a.path)).exit_code, 0);
  const auto stl_run = lamina("plan " + quoted(kKnob) + " --deviation-against " + quoted(step) +
                              " --deviation-chord-tolerance 0.002 --no-programs --out " + quoted(b.path));
  ASSERT_EQ(stl_run.exit_code, 0) << stl_run.out;
  const json from_step = json::parse(slurp(a.path / "report.json")), from_stl = json::parse(slurp(b.path / "report.json"));
  auto thicknesses = [](const json& r) {
    std::vector<double> t;
    for (const json& l : r["layers"]) t.push_back(l["thickness_mm"]);
    std::sort(t.begin(), t.end());  // the flange's three sheets tie in any order
    return t;
  };
  EXPECT_EQ(thicknesses(from_step), thicknesses(from_stl));
  const json& ref_a = from_step["model"]["deviation_reference"];
  const json& ref_b = from_stl["model"]["deviation_reference"];
  EXPECT_EQ(ref_a["triangles"], ref_b["triangles"]) << "one reference for both";
  EXPECT_EQ(ref_a["chord_tolerance_mm"], 0.002);
  const double step_pct = from_step["deviation"]["curved"]["volume_pct"], stl_pct = from_stl["deviation"]["curved"]["volume_pct"];
  EXPECT_LE(step_pct, stl_pct);
}

#ifdef LAMINA_STEP_MODULE
// OpenCASCADE is opened only for a CAD file: `lamina` itself needs none of its libraries (its
// 80 libraries cost 0.1 s at every start when they were linked in), the module does.
std::string needed_libraries(const std::string& elf) {
  std::string out;
  FILE* p = ::popen(("readelf -d " + quoted(fs::path(elf)) + " 2>&1").c_str(), "r");
  if (!p) return out;
  std::array<char, 4096> buf{};
  std::size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  ::pclose(p);
  return out;
}

TEST(CliStep, TheProgramLoadsOpenCascadeOnlyThroughItsStepModule) {
  const std::string program = needed_libraries(LAMINA_CLI), module = needed_libraries(LAMINA_STEP_MODULE);
  ASSERT_NE(program.find("NEEDED"), std::string::npos) << program;
  EXPECT_EQ(program.find("libTK"), std::string::npos) << program;
  EXPECT_NE(module.find("libTKXDESTEP"), std::string::npos) << module;
  // Where the program looks for it is where the build put it.
  const auto r = lamina("check " + quoted(fs::path(LAMINA_EXAMPLES_DIR) / "knob.step"));
  EXPECT_EQ(r.exit_code, 0) << r.out;
}

TEST(CliStep, AMissingStepModuleIsNamed) {
  const auto r = lamina_with_env("LAMINA_STEP_PLUGIN=/nonexistent/liblamina_step.so",
                                 "check " + quoted(fs::path(LAMINA_EXAMPLES_DIR) / "knob.step"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.out.find("the STEP/IGES reader /nonexistent/liblamina_step.so cannot be loaded"), std::string::npos) << r.out;
  const auto stl = lamina_with_env("LAMINA_STEP_PLUGIN=/nonexistent/liblamina_step.so",
                                   "check " + quoted(fs::path(LAMINA_EXAMPLES_DIR) / "knob.stl"));
  EXPECT_EQ(stl.exit_code, 0) << "an STL never needs it: " << stl.out;
}

TEST(CliStep, AModuleFromAnotherBuildIsRefused) {
  const auto r = lamina_with_env(std::string("LAMINA_STEP_PLUGIN=") + LAMINA_OTHER_BUILD_STEP_MODULE,
                                 "check " + quoted(fs::path(LAMINA_EXAMPLES_DIR) / "knob.step"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.out.find("is from another build ('lamina-step 0.0.0"), std::string::npos) << r.out;
}
#endif

TEST(CliStep, WithoutSupportSaysSo) {
  if (reads_step()) GTEST_SKIP() << "this build reads STEP (covered by CliStepModels)";
  const auto r = lamina("check " + quoted(shared_model("step_cube_cylinder.step")));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.out.find("built without STEP support"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace lamina_cli_test
