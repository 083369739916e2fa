// `lamina calibrate fit` (issue 20): a coupon's measurements in, the kerf model out — its
// coefficients recovered from a coupon measured with a caliper's noise, the residuals printed per
// cut, stored per material in the kerf file (another material's calibration kept), and every
// broken measurement file named by line and column, with nothing written.
#include "cli_runner.hpp"
#include "kerf_files.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <random>
#include <sstream>

namespace {

using namespace lamina_cli_test;
using lamina_cli_test::lamina;  // the function, not namespace lamina (the files share a unity build)
using lamina::KerfModel;

const KerfModel kTruth{.top_width_mm = 0.92,
                       .top_width_per_ratio_mm = -0.05,
                       .taper_per_ratio = 0.06,
                       .taper_free_ratio = 0.3,
                       .trail_back_factor = 0.1,
                       .trail_back_exponent = 2.2};

// The CSV a person fills in after cutting a coupon (columns in their own order).
std::string coupon_csv(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> caliper(0.0, 0.01), gauge(0.0, 0.03);
  std::ostringstream csv;
  csv << "# coupon, 10 mm aluminium\nfeed_ratio, label, path_mm, top_width_mm, bottom_width_mm, trail_back_mm\n";
  for (double path : {6.0, 12.0})
    for (double r : {0.2, 0.4, 0.6, 0.8, 1.0}) {
      const auto k = *lamina::kerf_at(kTruth, path, r);
      csv << r << ", cut-" << path << "-" << r << ", " << path << ", " << k.top_width_mm + caliper(rng) << ", "
          << k.bottom_width_mm + caliper(rng) << ", " << k.trail_back_mm * (1 + gauge(rng)) << "\r\n";
    }
  return csv.str();
}

TEST(CalibrateFit, RecoversTheKerfAndKeepsOtherMaterials) {
  TempDir dir("calibrate-fit", TempDir::made);
  std::ofstream(dir.path / "al.csv") << coupon_csv(7);
  std::ofstream(dir.path / "steel.csv") << coupon_csv(8);
  const std::string kerf = quoted(dir.path / "kerf.toml");
  auto r = lamina_cli_test::lamina("calibrate fit " + quoted(dir.path / "al.csv") + " --material 'aluminium 6061-T6' --kerf-file " + kerf);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("cut-6-0.2"), std::string::npos) << "a residual per cut:\n" << r.out;
  EXPECT_NE(r.out.find("rms: widths"), std::string::npos) << r.out;
  r = lamina_cli_test::lamina("calibrate fit " + quoted(dir.path / "steel.csv") + " --material 'mild steel' --kerf-file " + kerf);
  ASSERT_EQ(r.exit_code, 0) << r.out;

  std::ifstream in(dir.path / "kerf.toml");
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  auto stored = lamina::cli::parse_kerf_toml(text, "kerf.toml");
  ASSERT_TRUE(stored) << stored.error().message << "\n" << text;
  ASSERT_EQ(stored->size(), 2u) << text;
  const auto& al = stored->at("aluminium 6061-T6");
  EXPECT_EQ(al.cuts, 10);
  EXPECT_EQ(al.measurements, "al.csv");
  EXPECT_NEAR(al.model.top_width_mm, 0.92, 0.03);
  EXPECT_NEAR(al.model.taper_per_ratio, 0.06, 0.006);
  EXPECT_NEAR(al.model.taper_free_ratio, 0.3, 0.06);
  EXPECT_NEAR(al.model.trail_back_exponent, 2.2, 0.1);
  EXPECT_NEAR(al.model.trail_back_factor, 0.1, 0.012);
  EXPECT_LT(al.rms_width_mm, 0.02);
  EXPECT_FALSE(fs::exists(dir.path / "kerf.toml.new"));

  // Fitting aluminium again replaces its table and keeps steel's.
  std::ofstream(dir.path / "al2.csv") << coupon_csv(9);
  r = lamina_cli_test::lamina("calibrate fit " + quoted(dir.path / "al2.csv") + " --material 'aluminium 6061-T6' --kerf-file " + kerf);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  std::ifstream again(dir.path / "kerf.toml");
  stored = lamina::cli::parse_kerf_toml(std::string{std::istreambuf_iterator<char>(again), std::istreambuf_iterator<char>()}, "kerf.toml");
  ASSERT_TRUE(stored);
  EXPECT_EQ(stored->size(), 2u);
  EXPECT_EQ(stored->at("aluminium 6061-T6").measurements, "al2.csv");
}

TEST(CalibrateFit, ABrokenMeasurementFileIsNamedByLineAndNothingIsWritten) {
  TempDir dir("calibrate-bad", TempDir::made);
  const std::string header = "label,path_mm,feed_ratio,top_width_mm,bottom_width_mm,trail_back_mm\n";
  const std::vector<std::pair<std::string, std::string>> cases{
      {header + "a,10,0.5,0.9,0.85,0.3\nb,10,0.8,0.9,abc,0.5\n", "m.csv:3: bottom_width_mm: 'abc' is not a number"},
      {header + "a,10,0.5,0.9,0.85\n", "m.csv:2: 5 values; the header has 6 columns"},
      {"label,path_mm,feed_ratio,top_width_mm,bottom_width_mm\n", "m.csv:1: no column 'trail_back_mm' in the header"},
      {"label,path,feed_ratio,top_width_mm,bottom_width_mm,trail_back_mm\n", "m.csv:1: unknown column 'path'"},
      {header, "m.csv: a header and no measurements"},
      {header + "a,10,0.5,0.9,0.85,0.3\nb,10,0.8,0.9,0.8,0\n", "cut 'b': trail-back 0 mm"},
      {header + "a,10,0.5,0.9,0.85,0.3\nb,5,0.5,0.9,0.88,0.15\n", "needs cuts at two speeds at least"}};
  for (const auto& [csv, message] : cases) {
    std::ofstream(dir.path / "m.csv") << csv;
    const auto r = lamina_cli_test::lamina("calibrate fit " + quoted(dir.path / "m.csv") + " --material brass --kerf-file " + quoted(dir.path / "kerf.toml"));
    EXPECT_EQ(r.exit_code, 1) << csv << r.out;
    EXPECT_NE(r.out.find(message), std::string::npos) << "wanted: " << message << "\n" << r.out;
    EXPECT_FALSE(fs::exists(dir.path / "kerf.toml")) << csv;
  }
  // A name `lamina plan` would never look up.
  std::ofstream(dir.path / "m.csv") << coupon_csv(1);
  const auto unknown = lamina_cli_test::lamina("calibrate fit " + quoted(dir.path / "m.csv") + " --material alu --kerf-file " + quoted(dir.path / "kerf.toml"));
  EXPECT_EQ(unknown.exit_code, 1) << unknown.out;
  EXPECT_NE(unknown.out.find("alu"), std::string::npos) << unknown.out;
  EXPECT_NE(unknown.out.find("aluminium 6061-T6"), std::string::npos) << "the known names:\n" << unknown.out;
  EXPECT_FALSE(fs::exists(dir.path / "kerf.toml"));
  const auto usage = lamina_cli_test::lamina("calibrate fit " + quoted(dir.path / "m.csv"));
  EXPECT_EQ(usage.exit_code, 2) << usage.out;
  EXPECT_NE(usage.out.find("--material"), std::string::npos) << usage.out;
}

// The loop a shop runs: the coupon's program and its CSV, the cuts "measured" (here: the truth
// plus a caliper's noise, at the paths and ratios the CSV lists), the fit.
TEST(CalibrateCoupon, ItsSheetFilledInFitsBackTheKerf) {
  TempDir dir("calibrate-coupon", TempDir::made);
  auto r = lamina_cli_test::lamina("calibrate coupon --material 'aluminium 6061-T6' --thickness 10 --out " + quoted(dir.path));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  ASSERT_TRUE(fs::exists(dir.path / "coupon.nc"));
  std::ifstream program(dir.path / "coupon.nc");
  const std::string nc{std::istreambuf_iterator<char>(program), std::istreambuf_iterator<char>()};
  EXPECT_NE(nc.find("(CONTOUR 0 T0-R0.15 TEST CUT OPEN)"), std::string::npos) << nc.substr(0, 400);

  std::ifstream sheet(dir.path / "coupon.csv");
  std::ostringstream filled;
  std::mt19937 rng(11);
  std::normal_distribution<double> caliper(0.0, 0.01);
  int rows = 0;
  for (std::string line; std::getline(sheet, line);) {
    if (line.empty() || line[0] == '#' || line.starts_with("label,")) {
      filled << line << "\n";
      continue;
    }
    ASSERT_TRUE(line.ends_with(",,,")) << "measurements left to fill in: " << line;
    std::istringstream cells(line);
    std::string label, path, ratio;
    std::getline(cells, label, ',');
    std::getline(cells, path, ',');
    std::getline(cells, ratio, ',');
    const auto k = *lamina::kerf_at(kTruth, std::stod(path), std::stod(ratio));
    filled << label << "," << path << "," << ratio << "," << k.top_width_mm + caliper(rng) << ","
           << k.bottom_width_mm + caliper(rng) << "," << k.trail_back_mm * (1 + caliper(rng)) << "\n";
    ++rows;
  }
  EXPECT_EQ(rows, 10);
  // Unfilled, the sheet says what is missing.
  r = lamina_cli_test::lamina("calibrate fit " + quoted(dir.path / "coupon.csv") + " --material 'aluminium 6061-T6' --kerf-file " +
                              quoted(dir.path / "kerf.toml"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("coupon.csv:4: top_width_mm: empty (measure the cut and fill it in)"), std::string::npos) << r.out;
  std::ofstream(dir.path / "measured.csv") << filled.str();
  r = lamina_cli_test::lamina("calibrate fit " + quoted(dir.path / "measured.csv") + " --material 'aluminium 6061-T6' --kerf-file " +
                              quoted(dir.path / "kerf.toml"));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  std::ifstream in(dir.path / "kerf.toml");
  auto stored = lamina::cli::parse_kerf_toml(std::string{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()}, "kerf.toml");
  ASSERT_TRUE(stored) << stored.error().message;
  const KerfModel& m = stored->at("aluminium 6061-T6").model;
  EXPECT_NEAR(m.taper_per_ratio, 0.06, 0.006);
  EXPECT_NEAR(m.taper_free_ratio, 0.3, 0.06);
  EXPECT_NEAR(m.trail_back_exponent, 2.2, 0.1);
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// `lamina plan` with a calibration: auto compensates the calibrated material, off and an
// uncalibrated shop keep today's programs byte for byte, and asking for compensation without a
// calibration is an error that says what to do.
TEST(PlanJetCompensation, ACalibratedMaterialIsCompensatedAndOffChangesNothing) {
  TempDir dir("plan-jet", TempDir::made);
  std::ofstream(dir.path / "kerf.toml") << lamina::cli::kerf_toml({{"aluminium 6061-T6", {kTruth, 10, 0.01, 0.02, "al.csv"}}});
  const std::string knob = quoted(fs::path(LAMINA_EXAMPLES_DIR) / "knob.stl") + " --stock 5";
  const auto plan = [&](const std::string& name, const std::string& extra) {
    return lamina_cli_test::lamina("plan " + knob + " --out " + quoted(dir.path / name) + " " + extra);
  };
  auto r = plan("off", "--jet-compensation off");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  r = plan("uncalibrated", "");  // auto, and no kerf.toml beside config/materials.toml
  ASSERT_EQ(r.exit_code, 0) << r.out;
  r = plan("auto", "--kerf-file " + quoted(dir.path / "kerf.toml"));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_EQ(read_text(dir.path / "off/sheet-1.nc"), read_text(dir.path / "uncalibrated/sheet-1.nc"));
  EXPECT_NE(read_text(dir.path / "off/sheet-1.nc"), read_text(dir.path / "auto/sheet-1.nc"));
  const auto report = nlohmann::json::parse(read_text(dir.path / "auto/report.json"));
  EXPECT_EQ(report["cam"]["jet_compensation"], "auto");
  EXPECT_EQ(report["cam"]["kerf_file"], (dir.path / "kerf.toml").string());
  for (const auto& sheet : report["sheets"]) {
    EXPECT_EQ(sheet["jet_compensation"], "full") << sheet.dump();
    // The knob's grooves are bevelled at the 60° limit already: those lines cannot lean further.
    EXPECT_GT(sheet["jet_tilt_limited"].get<int>(), 0) << sheet.dump();
  }
  const auto plain = nlohmann::json::parse(read_text(dir.path / "uncalibrated/report.json"));
  EXPECT_EQ(plain["sheets"][0]["jet_compensation"], "off");
  EXPECT_FALSE(plain["cam"].contains("kerf_file"));

  r = plan("missing", "--jet-compensation taper --kerf-file " + quoted(dir.path / "nothing.toml"));
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("--jet-compensation taper: no kerf calibrations in"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("lamina calibrate coupon"), std::string::npos) << r.out;
  // A material the file does not know: named, when compensation is asked for outright.
  std::ofstream(dir.path / "steel.toml") << lamina::cli::kerf_toml({{"mild steel", {kTruth, 10, 0.01, 0.02, "s.csv"}}});
  r = plan("steel", "--jet-compensation full --kerf-file " + quoted(dir.path / "steel.toml"));
  EXPECT_NE(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("no kerf calibration for 'aluminium 6061-T6'"), std::string::npos) << r.out;
}

// The corner flags reach the planner (jet_corners.hpp): the cross's corners at a tight
// allowance take longer than with an allowance no corner needs, keeping the inside corners'
// feed saves time again, and a strategy that is not one is refused naming the choices.
TEST(PlanJetCorners, TheAllowanceAndTheInsideCornerStrategyReachThePlan) {
  TempDir dir("plan-corners", TempDir::made);
  std::ofstream(dir.path / "kerf.toml") << lamina::cli::kerf_toml({{"aluminium 6061-T6", {kTruth, 10, 0.01, 0.02, "al.csv"}}});
  const std::string cross = quoted(fs::path(LAMINA_EXAMPLES_DIR) / "cross.stl") +
                            " --stock 10 --dowels 0 --material 'aluminium 6061-T6' --kerf-file " + quoted(dir.path / "kerf.toml");
  const auto time_s = [&](const std::string& name, const std::string& extra) {
    const auto r = lamina_cli_test::lamina("plan " + cross + " --out " + quoted(dir.path / name) + " " + extra);
    EXPECT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(read_text(dir.path / name / "report.json"));
    return report["sheets"][0]["estimated_time_s"].get<double>();
  };
  // kTruth's lag is 0.06 mm at the default quality: 0.01 mm is an allowance its corners slow for.
  const double slowed = time_s("slowed", "--corner-error 0.01"), kept = time_s("kept", "--corner-error 0.01 --inside-corners keep"),
               loose = time_s("loose", "--corner-error 10");
  EXPECT_LT(kept, slowed) << "the four inside corners at the feed";
  // The report says what the corners were cut with, and the head's rates (config/machine.toml).
  const auto report = nlohmann::json::parse(read_text(dir.path / "kept" / "report.json"));
  EXPECT_EQ(report["cam"]["corner_error_mm"], 0.01);
  EXPECT_EQ(report["cam"]["inside_corners"], "keep");
  EXPECT_NEAR(report["cam"]["c_max_deg_per_min"].get<double>(), 7200.0, 1e-6);
  EXPECT_LT(loose, kept) << "no corner slowed at all";
  const auto bad = lamina_cli_test::lamina("plan " + cross + " --out " + quoted(dir.path / "bad") + " --inside-corners round");
  EXPECT_EQ(bad.exit_code, 2) << bad.out;
  EXPECT_NE(bad.out.find("--inside-corners"), std::string::npos) << bad.out;
  EXPECT_FALSE(fs::exists(dir.path / "bad"));
}

TEST(KerfFile, AHandEditedFileIsCheckedKeyByKey) {
  const std::string good = lamina::cli::kerf_toml({{"brass", {kTruth, 12, 0.01, 0.02, "b.csv"}}});
  auto back = lamina::cli::parse_kerf_toml(good, "kerf.toml");
  ASSERT_TRUE(back) << back.error().message << "\n" << good;
  EXPECT_NEAR(back->at("brass").model.trail_back_exponent, 2.2, 1e-9);
  auto typo = lamina::cli::parse_kerf_toml("[[kerf]]\nmaterial = \"a\"\ntaper_ratio = 1\n", "kerf.toml");
  ASSERT_FALSE(typo);
  EXPECT_NE(typo.error().message.find("kerf.toml:3: unknown key 'taper_ratio' in [[kerf]]"), std::string::npos) << typo.error().message;
  auto partial = lamina::cli::parse_kerf_toml("[[kerf]]\nmaterial = \"a\"\ntop_width_mm = 1\n", "kerf.toml");
  ASSERT_FALSE(partial);
  EXPECT_NE(partial.error().message.find("lacks some of its 6 coefficients"), std::string::npos) << partial.error().message;
}

}  // namespace
