// `lamina plan` as users run it: the report's shape and its invariants, stack.stl, the stock
// file, and the errors (usage: exit 2; stock file, model, output folder: exit 1).
#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <set>
#include <string>
#include <tuple>
#include <vector>

namespace {

using namespace lamina_cli_test;
using lamina_cli_test::lamina;  // the function, not namespace lamina (the files share a unity build)
using nlohmann::json;

const fs::path kStockToml = fs::path(LAMINA_EXAMPLES_DIR).parent_path() / "config" / "stock.toml";

json read_json(const fs::path& p) {
  std::ifstream in(p);
  return json::parse(in);
}

bool has_text(const CliRun& r, const std::string& s) { return r.out.find(s) != std::string::npos; }

// A fresh, empty folder for one test's outputs; removed when the test ends.
// Every key the issue and docs/planning.md promise, and the invariants between them.
void expect_report_is_complete(const json& j, const std::set<double>& stock, double bond) {
  for (const char* k : {"model", "settings", "layers", "stack", "shortfalls", "deviation", "warnings", "timing_s"})
    ASSERT_TRUE(j.contains(k)) << k;
  for (const char* k : {"file", "triangles", "volume_mm3", "height_mm"}) EXPECT_TRUE(j["model"].contains(k)) << k;
  for (const char* k : {"stock", "bond_mm", "sub_slice_mm", "tolerance_mm", "tilt_max_deg", "side", "strategy",
                        "layering", "axis", "direction", "units"})
    EXPECT_TRUE(j["settings"].contains(k)) << k;
  for (const auto& s : j["settings"]["stock"])
    for (const char* k : {"thickness_mm", "width_mm", "length_mm", "count", "material"}) EXPECT_TRUE(s.contains(k)) << k;
  EXPECT_DOUBLE_EQ(j["settings"]["bond_mm"].get<double>(), bond);

  const json& layers = j["layers"];
  ASSERT_FALSE(layers.empty());
  EXPECT_NEAR(layers[0]["z_bottom_mm"].get<double>(), 0.0, 1e-9);
  for (std::size_t i = 0; i < layers.size(); ++i) {
    const json& l = layers[i];
    for (const char* k : {"index", "z_bottom_mm", "thickness_mm", "sub_slices", "passes", "max_deviation_mm",
                          "within_tolerance", "estimated_deviation_mm", "shapes", "stations"})
      ASSERT_TRUE(l.contains(k)) << k << " in layer " << i;
    for (const char* k : {"convex", "concave", "straight", "mixed"}) EXPECT_GE(l["shapes"][k].get<int>(), 0) << k;
    EXPECT_EQ(l["index"].get<std::size_t>(), i);
    const double t = l["thickness_mm"].get<double>();
    EXPECT_TRUE(stock.count(t)) << "layer " << i << " thickness " << t << " is not in the stock";
    EXPECT_GE(l["sub_slices"].get<int>(), 2);
    EXPECT_GE(l["passes"].get<int>(), 1);
    if (i + 1 < layers.size()) {
      EXPECT_NEAR(layers[i + 1]["z_bottom_mm"].get<double>(), l["z_bottom_mm"].get<double>() + t + bond, 1e-9)
          << "layers " << i << " and " << i + 1 << " are not contiguous";
    }
  }

  const json& st = j["stack"];
  for (const char* k : {"layers", "model_height_mm", "stack_height_mm", "height_difference_mm", "sheets_used"})
    ASSERT_TRUE(st.contains(k)) << k;
  EXPECT_EQ(st["layers"].get<std::size_t>(), layers.size());
  const json& last = layers.back();
  EXPECT_NEAR(st["stack_height_mm"].get<double>(),
              last["z_bottom_mm"].get<double>() + last["thickness_mm"].get<double>(), 1e-9);
  EXPECT_NEAR(st["model_height_mm"].get<double>(), j["model"]["height_mm"].get<double>(), 1e-9);
  EXPECT_NEAR(st["height_difference_mm"].get<double>(),
              st["stack_height_mm"].get<double>() - st["model_height_mm"].get<double>(), 1e-9);
  EXPECT_GE(st["stack_height_mm"].get<double>(), st["model_height_mm"].get<double>() - 1e-9) << "the stack covers the model";
  int used = 0;
  for (const auto& [t, n] : st["sheets_used"].items()) {
    EXPECT_TRUE(stock.count(std::stod(t))) << t;
    used += n.get<int>();
  }
  EXPECT_EQ(used, static_cast<int>(layers.size()));

  for (const auto& f : j["shortfalls"])
    for (const char* k : {"z_from_mm", "z_to_mm", "deviation_mm"}) EXPECT_TRUE(f.contains(k)) << k;

  // The chosen strategy's deviation always; the other two only with --compare-strategies true.
  const double model_volume = j["model"]["volume_mm3"].get<double>();
  const bool compared = j["settings"]["compare_strategies"].get<bool>();
  for (const char* s : {"vertical", "sloped", "curved"}) {
    const bool expected = compared || j["settings"]["strategy"] == s;
    ASSERT_EQ(j["deviation"].contains(s), expected) << s;
    if (!expected) continue;
    const json& d = j["deviation"][s];
    for (const char* k : {"volume_mm3", "volume_pct", "max_mm"}) ASSERT_TRUE(d.contains(k)) << s << "." << k;
    EXPECT_GT(d["volume_mm3"].get<double>(), 0.0) << s;
    EXPECT_NEAR(d["volume_pct"].get<double>(), 100.0 * d["volume_mm3"].get<double>() / model_volume, 1e-6) << s;
    EXPECT_GE(d["max_mm"].get<double>(), 0.0) << s;
  }
  EXPECT_TRUE(j["warnings"].is_array());
  for (const char* k : {"read", "topology", "layering", "bevel", "deviation", "write", "total"})
    EXPECT_GE(j["timing_s"][k].get<double>(), 0.0) << k;
}

TEST(CliPlan, KnobPlanWritesACompleteReportAndALoadableStack) {
  TempDir out("plan-knob");
  const CliRun r = lamina("plan " + quoted(kKnob) + " --compare-strategies true --out " + quoted(out.path));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_TRUE(has_text(r, "concave")) << "the layer table:\n" << r.out;
  EXPECT_TRUE(has_text(r, "volume mm3")) << "the deviation table:\n" << r.out;
  EXPECT_TRUE(has_text(r, "stack: ")) << r.out;
  EXPECT_TRUE(has_text(r, "timing: ")) << r.out;

  const json j = read_json(out.path / "report.json");
  expect_report_is_complete(j, {1.0, 2.5, 5.0, 10.0}, 0.0);
  EXPECT_EQ(j["model"]["triangles"].get<int>(), 14232);
  EXPECT_NEAR(j["model"]["height_mm"].get<double>(), 43.4178, 1e-3);
  EXPECT_EQ(j["settings"]["strategy"], "curved");
  EXPECT_EQ(j["settings"]["side"], "outside");
  EXPECT_EQ(j["settings"]["layering"], "optimal");
  EXPECT_DOUBLE_EQ(j["settings"]["tilt_max_deg"].get<double>(), 60.0);
  EXPECT_DOUBLE_EQ(j["settings"]["tolerance_mm"].get<double>(), 0.2);

  // The curved form is the point of the paper: on the knob it beats one chord, which beats
  // vertical edges, on the same layering.
  const json& d = j["deviation"];
  EXPECT_LE(d["curved"]["volume_mm3"].get<double>(), d["sloped"]["volume_mm3"].get<double>());
  EXPECT_LE(d["sloped"]["volume_mm3"].get<double>(), d["vertical"]["volume_mm3"].get<double>());

  ASSERT_TRUE(fs::exists(out.path / "stack.stl"));
  EXPECT_GT(fs::file_size(out.path / "stack.stl"), 84u);
  for (const auto& e : fs::directory_iterator(out.path))
    EXPECT_NE(e.path().filename().string().front(), '.') << "temporary file left: " << e.path();
  const CliRun check = lamina("check " + quoted(out.path / "stack.stl"));
  EXPECT_EQ(check.exit_code, 0) << check.out;

  // Again into the same folder: the files are replaced.
  const auto first = fs::last_write_time(out.path / "report.json");
  const CliRun again = lamina("plan " + quoted(kKnob) + " --out " + quoted(out.path) + " --strategy vertical");
  ASSERT_EQ(again.exit_code, 0) << again.out;
  EXPECT_EQ(read_json(out.path / "report.json")["settings"]["strategy"], "vertical");
  EXPECT_GE(fs::last_write_time(out.path / "report.json"), first);
}

TEST(CliPlan, JsonOnStdoutIsTheReportAndTheStockFileIsCarriedThrough) {
  TempDir out("plan-json");
  const CliRun r = lamina_stdout("plan " + quoted(kKnob) + " --out " + quoted(out.path) + " --stock-file " +
                                 quoted(kStockToml) + " --bond 0.1 --json");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const json printed = json::parse(r.out);
  const json written = read_json(out.path / "report.json");
  EXPECT_EQ(printed, written);
  expect_report_is_complete(written, {1.0, 2.5, 5.0, 10.0}, 0.1);
  const json& settings = written["settings"];
  EXPECT_EQ(settings["stock_source"], kStockToml.string());
  ASSERT_EQ(settings["stock"].size(), 5u);  // two sizes of 5 mm sheet
  EXPECT_EQ(settings["stock"][0]["material"], "aluminium 6061-T6");
  EXPECT_DOUBLE_EQ(settings["stock"][0]["width_mm"].get<double>(), 1250.0);
  EXPECT_EQ(settings["stock"][0]["count"].get<int>(), 10);
  EXPECT_EQ(settings["thicknesses_mm"], json({1.0, 2.5, 5.0, 10.0}));

  // With bonding gaps the layers do not touch: stack.stl is one closed solid per layer (the
  // knob's layers are one part each).
  const CliRun check = lamina("check " + quoted(out.path / "stack.stl"));
  EXPECT_EQ(check.exit_code, 0) << check.out;
  EXPECT_TRUE(has_text(check, "watertight yes")) << check.out;
  const std::string solids = std::to_string(written["layers"].size()) + " solids";
  EXPECT_TRUE(has_text(check, solids)) << "expected '" << solids << "' in:\n" << check.out;
}

TEST(CliPlan, StockListOverridesTheFileAndEqualThicknessesCollapse) {
  TempDir out("plan-stock");
  const CliRun r = lamina_stdout("plan " + quoted(kKnob) + " --out " + quoted(out.path) + " --stock-file " +
                                 quoted(kStockToml) + " --stock 10,5,5.0000000000001 --json");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["settings"]["stock_source"], "--stock");
  EXPECT_EQ(j["settings"]["thicknesses_mm"], json({5.0, 10.0}));
  ASSERT_EQ(j["settings"]["stock"].size(), 3u);
  EXPECT_TRUE(j["settings"]["stock"][0]["width_mm"].is_null()) << "sheets of unknown size";
  expect_report_is_complete(j, {5.0, 10.0}, 0.0);
}

TEST(CliPlan, BadStockListsNameTheValue) {
  TempDir out("plan-bad-stock");
  const std::string base = "plan " + quoted(kKnob) + " --out " + quoted(out.path) + " ";
  for (const auto& [arg, fragment] : std::vector<std::pair<std::string, std::string>>{{"--stock 1,x", "'x'"},
                                                                                      {"--stock=-1", "'-1'"},
                                                                                      {"--stock ''", "empty"},
                                                                                      {"--stock 1,,2", "empty"},
                                                                                      {"--stock 0", "'0'"},
                                                                                      {"--stock nan", "'nan'"}}) {
    const CliRun r = lamina(base + arg);
    EXPECT_EQ(r.exit_code, 2) << arg << ":\n" << r.out;
    EXPECT_TRUE(has_text(r, "--stock")) << arg << ":\n" << r.out;
    EXPECT_TRUE(has_text(r, fragment)) << arg << ": expected " << fragment << " in:\n" << r.out;
  }
  EXPECT_FALSE(fs::exists(out.path / "report.json"));
}

TEST(CliPlan, StockFileErrorsNameTheKeyAndLine) {
  TempDir out("plan-bad-toml");
  const fs::path toml = temp_file("stock.toml");
  const auto run_with = [&](const std::string& text) {
    std::ofstream(toml) << text;
    return lamina("plan " + quoted(kKnob) + " --out " + quoted(out.path) + " --stock-file " + quoted(toml));
  };
  CliRun r = run_with("[[sheet]]\nthickness_mm = 2.5\nthikness_mm = 5\n");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(has_text(r, "unknown key 'thikness_mm'")) << r.out;
  EXPECT_TRUE(has_text(r, toml.string() + ":3:")) << r.out;

  r = run_with("[[sheet]]\nthickness_mm = 2.5\n\n[[sheet]]\nwidth_mm = 1000\n");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(has_text(r, "without thickness_mm")) << r.out;
  EXPECT_TRUE(has_text(r, ":4:")) << r.out;

  r = run_with("[[sheet]]\nthickness_mm = -2\n");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(has_text(r, "thickness_mm = -2")) << r.out;

  r = run_with("[[sheet]]\nthickness_mm = 2\ncount = 2.5\n");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(has_text(r, "count")) << r.out;

  r = run_with("[[sheet]]\nthickness_mm = 2\nmaterial = \"unterminated\n");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(has_text(r, toml.string() + ":3:")) << r.out;

  r = run_with("[stock]\nthickness_mm = 2\n");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(has_text(r, "unknown key 'stock'")) << r.out;

  r = run_with("# nothing on the rack\n");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(has_text(r, "no [[sheet]]")) << r.out;

  fs::remove(toml);
  r = lamina("plan " + quoted(kKnob) + " --out " + quoted(out.path) + " --stock-file " + quoted(toml));
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(has_text(r, "cannot read stock file " + toml.string())) << r.out;
}

// Issue 16, item 11: `--stock 1e10` crashed the planner (SIGSEGV), `--stock 0.001` took 2.6 GB,
// `--stock-file /dev/zero` grew without end. Each is a clear error before any work: a value the
// model makes absurd is a usage error (exit 2, issue 17 item 7), an unreadable file exit 1.
TEST(CliPlan, StockTheModelCannotUseIsAClearErrorNotACrash) {
  TempDir out("plan-absurd-stock");
  const std::string base = "plan " + quoted(kKnob) + " --out " + quoted(out.path) + " ";
  for (const auto& [arg, fragment, code] : std::vector<std::tuple<std::string, std::string, int>>{
           {"--stock 1e10", "every stock sheet is thicker than the part", 2},
           {"--stock 1e9", "every stock sheet is thicker than the part", 2},
           {"--stock 1000", "every stock sheet is thicker than the part", 2},
           {"--stock 0.001", "thinner than half the sub-slice spacing", 2},
           {"--sub-slice 1e-6 --stock 1", "grid lines", 2},
           {"--deviation-step 1e-9", "--deviation-step 1e-09 mm gives", 2},
           {"--stock-file /dev/zero", "stock file /dev/zero is not a regular file", 1}}) {
    const CliRun r = lamina(base + arg);
    EXPECT_EQ(r.exit_code, code) << arg << ":\n" << r.out;
    EXPECT_TRUE(has_text(r, fragment)) << arg << ": expected " << fragment << " in:\n" << r.out;
  }
  EXPECT_FALSE(fs::exists(out.path / "report.json"));
}

TEST(CliPlan, UnwritableOutputFolderIsAClearError) {
  const fs::path file = temp_file("not-a-folder");
  std::ofstream(file) << "x";
  CliRun r = lamina("plan " + quoted(kKnob) + " --out " + quoted(file / "plan"));
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(has_text(r, "--out " + (file / "plan").string() + ": cannot create the folder")) << r.out;
  r = lamina("plan " + quoted(kKnob) + " --out " + quoted(file));
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(has_text(r, "not a folder")) << r.out;
  fs::remove(file);
}

TEST(CliPlan, UsageErrorsExitTwo) {
  TempDir out("plan-usage");
  const std::string base = "plan " + quoted(kKnob) + " --out " + quoted(out.path) + " ";
  for (const std::string args : {"--side sideways", "--strategy bogus", "--layering best", "--tilt-max 95",
                                  "--tolerance 0", "--sub-slice -1", "--bond -0.5", "--deviation-step 0"}) {
    const CliRun r = lamina(base + args);
    EXPECT_EQ(r.exit_code, 2) << args << ":\n" << r.out;
    EXPECT_TRUE(has_text(r, args.substr(0, args.find(' ')))) << args << ": the message names the option:\n" << r.out;
  }
  EXPECT_EQ(lamina("plan " + quoted(kKnob)).exit_code, 2) << "--out is required";
  EXPECT_EQ(lamina("check " + quoted(kKnob) + " --units cm").exit_code, 2) << "same exit code for every command";
  EXPECT_EQ(lamina("plan --help").exit_code, 0);
  EXPECT_TRUE(has_text(lamina("plan --help"), "in mm")) << "help says plan lengths are millimetres";
  EXPECT_FALSE(fs::exists(out.path / "report.json"));
}

TEST(CliPlan, OpenMeshIsRefused) {
  const fs::path teapot = shared_model("teapot.stl");
  if (!fs::exists(teapot)) GTEST_SKIP() << "shared model not present: " << teapot;
  TempDir out("plan-open");
  const CliRun r = lamina("plan " + quoted(teapot) + " --out " + quoted(out.path));
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(has_text(r, "not usable as a solid")) << r.out;
  EXPECT_FALSE(fs::exists(out.path / "stack.stl"));
}

TEST(CliPlan, MissingModelIsAnIoError) {
  TempDir out("plan-missing");
  const CliRun r = lamina("plan " + quoted(temp_file("nope.stl")) + " --out " + quoted(out.path));
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(has_text(r, "io_error")) << r.out;
}

}  // namespace

namespace {

// An ASCII STL of the box [ox, ox + x] × [0, y] × [0, z], outward facets; `append` adds a
// second solid to the file (a second shell).
void write_box_stl(const fs::path& path, double x, double y, double z, double ox = 0, bool append = false) {
  const double x0 = ox, x1 = ox + x;
  const double c[8][3] = {{x0, 0, 0}, {x1, 0, 0}, {x1, y, 0}, {x0, y, 0}, {x0, 0, z}, {x1, 0, z}, {x1, y, z}, {x0, y, z}};
  const int quads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  std::ofstream out(path, append ? std::ios::app : std::ios::trunc);
  out << "solid box\n";
  for (const auto& q : quads)
    for (const auto& tri : {std::array{q[0], q[1], q[2]}, std::array{q[0], q[2], q[3]}}) {
      out << "facet normal 0 0 0\nouter loop\n";
      for (int v : tri) out << "vertex " << c[v][0] << ' ' << c[v][1] << ' ' << c[v][2] << '\n';
      out << "endloop\nendfacet\n";
    }
  out << "endsolid box\n";
}

}  // namespace

// Issue 17, item 8: an inch file read as mm planned a 2.7 mm part without a word, and a mm file
// given --units in a part larger than the sheet. Both are said (not refused: both can be meant).
TEST(CliPlan, ASizeThatSuggestsTheWrongUnitsIsSaid) {
  TempDir out("plan-units");
  const fs::path tiny = temp_file("tiny-inch-part.stl"), plate = temp_file("mm-plate.stl");
  write_box_stl(tiny, 2.7, 2.0, 2.5);
  write_box_stl(plate, 120, 60, 1);
  CliRun r = lamina_cli_test::lamina("plan " + quoted(tiny) + " --stock 0.5,1 --sub-slice 0.25 --no-programs --out " + quoted(out.path));
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_TRUE(has_text(r, "2.70 mm at its largest): if the file is in inches, give --units in (it would be 68.6 mm)"))
      << r.out;
  // A 100 mm bar read as inches is 2540 mm long (a bar, not the 120 mm plate: a 3 m plate's
  // deviation alone took 2 s, 20 s under the sanitizers).
  const fs::path bar = temp_file("mm-bar.stl");
  write_box_stl(bar, 100, 1, 1);
  r = lamina_cli_test::lamina("plan " + quoted(bar) + " --units in --stock 10 --no-programs --out " + quoted(out.path));
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_TRUE(has_text(r, "larger than the 2500 mm sheet: if the file is in mm, give --units mm (it would be 100.0 mm"))
      << r.out;
  fs::remove(bar);
  r = lamina_cli_test::lamina("plan " + quoted(plate) + " --stock 0.5,1 --no-programs --out " + quoted(out.path));
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_FALSE(has_text(r, "--units")) << "a 120 mm plate in mm is plausible:\n" << r.out;
  fs::remove(tiny);
  fs::remove(plate);
}

// Issue 17, item 8: overlapping shells were not mentioned, and the volume is their sum. Two
// 20 × 20 × 10 boxes, the second 10 mm along x: they share half their volume.
TEST(CliPlan, OverlappingShellsAreSaidByCheckAndPlan) {
  TempDir out("plan-shells");
  const fs::path two = temp_file("two-boxes.stl"), apart = temp_file("two-boxes-apart.stl");
  write_box_stl(two, 20, 20, 10);
  write_box_stl(two, 20, 20, 10, 10, true);
  write_box_stl(apart, 20, 20, 10);
  write_box_stl(apart, 20, 20, 10, 30, true);
  CliRun r = lamina_cli_test::lamina("check " + quoted(two));
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_TRUE(has_text(r, "overlapping_shells: 2 shells overlap in 64 of 64 sections")) << r.out;
  r = lamina_cli_test::lamina("plan " + quoted(two) + " --stock 5,10 --no-programs --out " + quoted(out.path));
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_TRUE(has_text(r, "overlapping_shells")) << r.out;
  r = lamina_cli_test::lamina("check " + quoted(apart));
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_FALSE(has_text(r, "overlapping_shells")) << "two shells side by side do not overlap:\n" << r.out;
  fs::remove(two);
  fs::remove(apart);
}
