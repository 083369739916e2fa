// The `lamina` program as users run it: exit codes, one diagnosis line per defect class, and the
// JSON report's shape and contents.
#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <string>

namespace {

using namespace lamina_cli_test;
using lamina_cli_test::lamina;  // the function, not namespace lamina (the files share a unity build)

TEST(Cli, CheckOnTheExampleIsUsableAndWatertight) {
  const CliRun r = lamina("check " + quoted(kKnob));
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("watertight yes"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\nusable"), std::string::npos) << r.out;
}

struct Diagnosis {
  const char* file;
  int exit_code;
  const char* line;  // a fragment of the specific diagnosis line
};

class CliDiagnosis : public ::testing::TestWithParam<Diagnosis> {};

TEST_P(CliDiagnosis, DefectiveModelGetsItsSpecificDiagnosis) {
  const Diagnosis& d = GetParam();
  const fs::path path = shared_model(d.file);
  if (!fs::exists(path)) GTEST_SKIP() << "shared model not present: " << path;
  const CliRun r = lamina("check " + quoted(path));
  EXPECT_EQ(r.exit_code, d.exit_code) << r.out;
  EXPECT_NE(r.out.find(d.line), std::string::npos) << "expected '" << d.line << "' in:\n" << r.out;
}

INSTANTIATE_TEST_SUITE_P(
    SharedModels, CliDiagnosis,
    ::testing::Values(Diagnosis{"teapot.stl", 1, "open_edges: 64 open (boundary) edges"},
                      Diagnosis{"shared.STL", 0, "nonmanifold_edges: 1 non-manifold edge"},
                      Diagnosis{"multibody.stl", 0, "inconsistent_winding:"},
                      Diagnosis{"busted.STL", 0, "stored_normals_zero:"},
                      Diagnosis{"HalfDonut_binary.stl", 0, "trailing_bytes: "},
                      Diagnosis{"featuretype.STL", 0, "welded_vertices:"}),
    [](const ::testing::TestParamInfo<Diagnosis>& info) {
      std::string n = info.param.file;
      for (char& c : n)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      return n;
    });

TEST(Cli, BrokenFilesGiveAnErrorNamingTheProblem) {
  const fs::path garbage = temp_file("garbage.stl");
  {
    std::ofstream f(garbage, std::ios::binary);
    f << "this is not a mesh at all\n\x01\x02\x03";
  }
  CliRun r = lamina("check " + quoted(garbage));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("error ["), std::string::npos) << r.out;

  const fs::path truncated = temp_file("truncated.stl");
  {
    std::ifstream in(kKnob, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    std::ofstream f(truncated, std::ios::binary);
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  }
  r = lamina("check " + quoted(truncated));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("truncated_file"), std::string::npos) << r.out;

  r = lamina("slice " + quoted(temp_file("does-not-exist.stl")) + " --step 1");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("io_error"), std::string::npos) << r.out;
  fs::remove(garbage);
  fs::remove(truncated);
}

TEST(Cli, NoQuoteInputKeepsAFilesBytesOutOfTheErrors) {
  // What laminad passes for a file its client named (issue 16, item 9): a reader error must say
  // where and what, but never show the file's bytes, here a first line and an ASCII STL token.
  const fs::path secret = temp_file("secret.stl");
  const fs::path token = temp_file("token.stl");
  {
    std::ofstream(secret, std::ios::binary) << "root:Kj7Q-secret-hash:19000:0:99999:7:::\n";
    std::ofstream(token, std::ios::binary) << "solid x\nfacet normal Kj7Q-secret-hash 0 0\n";
  }
  for (const fs::path& file : {secret, token}) {
    for (const std::string& cmd : {"check " + quoted(file), "slice " + quoted(file) + " --step 1",
                                   "plan " + quoted(file) + " --out " + quoted(temp_file("plan-out"))}) {
      const CliRun quoting = lamina(cmd);
      EXPECT_EQ(quoting.exit_code, 1) << cmd << "\n" << quoting.out;
      EXPECT_NE(quoting.out.find("Kj7Q-secret-hash"), std::string::npos) << cmd << "\n" << quoting.out;
      const CliRun neutral = lamina(cmd + " --no-quote-input");
      EXPECT_EQ(neutral.exit_code, 1) << cmd << "\n" << neutral.out;
      EXPECT_NE(neutral.out.find("error ["), std::string::npos) << cmd << "\n" << neutral.out;
      EXPECT_EQ(neutral.out.find("Kj7Q"), std::string::npos) << cmd << "\n" << neutral.out;
    }
  }
  for (const char* cmd : {"check", "slice", "plan"})
    EXPECT_NE(lamina(std::string(cmd) + " --help").out.find("--no-quote-input"), std::string::npos) << cmd;
  fs::remove(secret);
  fs::remove(token);
  fs::remove_all(temp_file("plan-out"));
}

TEST(Cli, UsageErrorsAreRejected) {
  EXPECT_NE(lamina("slice " + quoted(kKnob)).exit_code, 0) << "a height option is required";
  EXPECT_NE(lamina("slice " + quoted(kKnob) + " --step 1 --at 2").exit_code, 0) << "options exclude each other";
  EXPECT_NE(lamina("check " + quoted(kKnob) + " --units cm").exit_code, 0);
  EXPECT_NE(lamina("slice " + quoted(kKnob) + " --at-fraction 1.5").exit_code, 0);
}

// Issue 17, item 7: `--step 1e-9` asked for 3·10^10 planes and died in std::bad_alloc. A step the
// model makes absurd is a usage error (exit 2) naming the smallest step that works.
TEST(Cli, SliceStepTooFineForTheModelIsAUsageError) {
  for (const char* step : {"1e-9", "1e-4"}) {
    const CliRun r = lamina("slice " + quoted(kKnob) + " --step " + step);
    EXPECT_EQ(r.exit_code, 2) << step << ":\n" << r.out;
    EXPECT_NE(r.out.find("planes over the model's"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("give --step"), std::string::npos) << r.out;
  }
  EXPECT_EQ(lamina("slice " + quoted(kKnob) + " --step 0.01").exit_code, 0) << "a fine step within bounds still slices";
}

TEST(Cli, SliceJsonHoldsMeshSlicesVectorsAndTimings) {
  const fs::path json_path = temp_file("knob.json");
  const CliRun r = lamina("slice " + quoted(kKnob) + " --at-fraction 0.25,0.5,0.75 --json " + quoted(json_path));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  fs::remove(json_path);

  const auto& mesh = j.at("mesh");
  EXPECT_EQ(mesh.at("triangles").get<int>(), 14232);
  EXPECT_TRUE(mesh.at("watertight").get<bool>());
  EXPECT_NEAR(mesh.at("volume_mm3").get<double>(), 103392.2, 1.0);  // examples/README.md
  EXPECT_EQ(mesh.at("bbox_min_mm").size(), 3u);
  EXPECT_NEAR(mesh.at("bbox_max_mm")[2].get<double>(), 43.4178, 1e-3);
  EXPECT_EQ(mesh.at("shells").get<int>(), 1);
  EXPECT_GT(mesh.at("surfaces").get<int>(), 3);
  EXPECT_TRUE(mesh.at("defects").is_array());

  const auto& slices = j.at("slices");
  ASSERT_EQ(slices.size(), 3u);
  // examples/README.md: 1 outer + 7 holes (bore and six bolt holes), then 1 + 1, 1 + 1.
  const int holes[3] = {7, 1, 1};
  const double area[3] = {4286.18, 1190.94, 2741.31};
  for (std::size_t k = 0; k < 3; ++k) {
    const auto& s = slices[k];
    EXPECT_EQ(s.at("outer").get<int>(), 1);
    EXPECT_EQ(s.at("holes").get<int>(), holes[k]);
    EXPECT_NEAR(s.at("net_area_mm2").get<double>(), area[k], 0.01);
    double sum = 0;
    for (const auto& loop : s.at("loops")) {
      const double a = loop.at("area_mm2").get<double>();
      sum += a;
      EXPECT_EQ(loop.at("orientation").get<std::string>(), a > 0 ? "ccw" : "cw");
      ASSERT_GE(loop.at("vectors").size(), 3u);
      for (const auto& v : loop.at("vectors")) {
        const auto& n = v.at("normal");
        const double len = std::hypot(n[0].get<double>(), n[1].get<double>(), n[2].get<double>());
        EXPECT_NEAR(len, 1.0, 1e-9);
        EXPECT_GE(v.at("facet").get<int>(), 0);
        EXPECT_GE(v.at("surface").get<int>(), 0);
        EXPECT_EQ(v.at("start").size(), 2u);
        EXPECT_EQ(v.at("end").size(), 2u);
      }
    }
    EXPECT_NEAR(sum, s.at("net_area_mm2").get<double>(), 1e-6);
  }
  for (const char* phase : {"read", "topology", "slice"}) EXPECT_GE(j.at("timing_s").at(phase).get<double>(), 0.0);
}

TEST(Cli, InchFilesAreScaledOnce) {
  const fs::path path = shared_model("featuretype.STL");
  if (!fs::exists(path)) GTEST_SKIP() << "shared model not present: " << path;
  const fs::path json_path = temp_file("ft.json");
  const CliRun r = lamina("slice " + quoted(path) + " --units in --at-fraction 0.5 --json " + quoted(json_path));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  fs::remove(json_path);
  EXPECT_NEAR(j["mesh"]["bbox_max_mm"][0].get<double>() - j["mesh"]["bbox_min_mm"][0].get<double>(), 5.0 * 25.4, 1e-6);
  // README: 10.76 in² at 50 %.
  EXPECT_NEAR(j["slices"][0]["net_area_mm2"].get<double>(), 10.76 * 25.4 * 25.4, 1e-3 * 10.76 * 25.4 * 25.4);
}

}  // namespace
