// `lamina plan` cut programs as users get them: DIR/sheet-<n>.nc and .svg, report.json's sheets[],
// the machine file's and the stock's errors.
#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>
#include <map>
#include <string>
#include <vector>

namespace {

using namespace lamina_cli_test;
using lamina_cli_test::lamina;  // the function, not namespace lamina (the files share a unity build)
using nlohmann::json;

const fs::path kConfig = fs::path(LAMINA_EXAMPLES_DIR).parent_path() / "config";

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

bool sheets_have_text(const CliRun& r, const std::string& s) { return r.out.find(s) != std::string::npos; }

TEST(CliSheets, PlanWritesOneProgramAndOneDrawingPerSheetAndReportsThem) {
  TempDir out("sheets");
  fs::create_directories(out.path);
  // A stale sheet file from an earlier, larger run must disappear.
  std::ofstream(out.path / "sheet-99.nc") << "G0X0\n";
  const auto r = lamina("plan " + quoted(kKnob) + " --stock-file " + quoted(kConfig / "stock.toml") +
                        " --nest matrix --post fanuc --rtcp true --microjoints 2 --out " + quoted(out.path));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_FALSE(fs::exists(out.path / "sheet-99.nc"));
  const json j = json::parse(slurp(out.path / "report.json"));
  ASSERT_TRUE(j.contains("sheets"));
  ASSERT_TRUE(j.contains("cam"));
  EXPECT_EQ(j["cam"]["post"], "fanuc");
  EXPECT_EQ(j["cam"]["nest"], "matrix");
  std::set<std::pair<int, int>> numbered;
  double last_t = 0.0;
  int index = 0;
  for (const json& s : j["sheets"]) {
    for (const char* k : {"index", "thickness_mm", "width_mm", "length_mm", "program", "svg", "estimated_time_s",
                          "utilisation", "parts"})
      ASSERT_TRUE(s.contains(k)) << k;
    EXPECT_EQ(s["index"].get<int>(), ++index);
    EXPECT_GE(s["thickness_mm"].get<double>(), last_t) << "thin sheets before thick";
    last_t = s["thickness_mm"].get<double>();
    EXPECT_GT(s["estimated_time_s"].get<double>(), 0.0);
    EXPECT_GT(s["utilisation"].get<double>(), 0.0);
    EXPECT_LE(s["utilisation"].get<double>(), 1.0);
    EXPECT_EQ(s["material"], "aluminium 6061-T6");  // from config/stock.toml
    const std::string nc = slurp(out.path / s["program"].get<std::string>());
    const std::string svg = slurp(out.path / s["svg"].get<std::string>());
    // Fanuc framing and RTCP; the jet's M-codes; contour markers.
    EXPECT_EQ(nc.rfind("%\n", 0), 0u);
    EXPECT_NE(nc.find("G43.4"), std::string::npos);
    EXPECT_NE(nc.find("M30"), std::string::npos);
    EXPECT_NE(nc.find("(CONTOUR 0 "), std::string::npos);
    EXPECT_EQ(nc.substr(nc.size() - 2), "%\n");
    EXPECT_NE(svg.find("<svg"), std::string::npos);
    for (const json& p : s["parts"]) {
      for (const char* k : {"layer", "island", "x_mm", "y_mm", "rotation_deg"}) ASSERT_TRUE(p.contains(k)) << k;
      EXPECT_TRUE(numbered.insert({p["layer"].get<int>(), p["island"].get<int>()}).second) << "part placed twice";
      EXPECT_NE(svg.find(p["label"].get<std::string>()), std::string::npos) << "label missing from the drawing";
    }
  }
  // Every part of every layer is on a sheet: the knob has one part per layer.
  EXPECT_EQ(numbered.size(), j["layers"].size());
  EXPECT_TRUE(sheets_have_text(r, "sheet-1.nc") || sheets_have_text(r, "sheet-<n>.nc"));
}

TEST(CliSheets, NotEnoughSheetsIsAClearError) {
  TempDir out("too-few");
  const fs::path stock = temp_file("one-sheet.toml");
  std::ofstream(stock) << "[[sheet]]\nthickness_mm = 2.5\nwidth_mm = 100\nlength_mm = 100\ncount = 1\n"
                          "material = \"aluminium 6061-T6\"\n";
  const auto r = lamina("plan " + quoted(kKnob) + " --stock-file " + quoted(stock) + " --out " + quoted(out.path));
  fs::remove(stock);
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(sheets_have_text(r, "2.5")) << r.out;
  EXPECT_TRUE(sheets_have_text(r, "sheet")) << r.out;
  EXPECT_FALSE(fs::exists(out.path / "report.json"));
}

TEST(CliSheets, MachineFileErrorsNameTheLineAndKey) {
  TempDir out("bad-machine");
  const fs::path machine = temp_file("machine.toml");
  std::ofstream(machine) << "[head]\npivot_mm = 150\n\n[cutting]\nkerf_mn = 0.9\n";
  auto r = lamina("plan " + quoted(kKnob) + " --machine " + quoted(machine) + " --out " + quoted(out.path));
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(sheets_have_text(r, ":5:")) << r.out;
  EXPECT_TRUE(sheets_have_text(r, "kerf_mn")) << r.out;
  std::ofstream(machine) << "[post]\ndialect = \"heidenhain\"\n";
  r = lamina("plan " + quoted(kKnob) + " --machine " + quoted(machine) + " --out " + quoted(out.path));
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(sheets_have_text(r, "heidenhain")) << r.out;
  fs::remove(machine);
  EXPECT_FALSE(fs::exists(out.path / "report.json"));
}

TEST(CliSheets, GrblhalWithRtcpAndUnknownMaterialAreRefused) {
  TempDir out("refused");
  auto r = lamina("plan " + quoted(kKnob) + " --post grblhal --rtcp true --out " + quoted(out.path));
  EXPECT_NE(r.exit_code, 0) << r.out;
  EXPECT_TRUE(sheets_have_text(r, "RTCP") || sheets_have_text(r, "rtcp") || sheets_have_text(r, "G43.4")) << r.out;
  r = lamina("plan " + quoted(kKnob) + " --material unobtainium --out " + quoted(out.path));
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_TRUE(sheets_have_text(r, "unobtainium")) << r.out;
  EXPECT_TRUE(sheets_have_text(r, "aluminium 6061-T6")) << r.out;  // the known names are listed
}

// laminad reads these lines from a pipe to show planning as steps.
std::vector<json> progress_lines(const fs::path& file) {
  std::vector<json> lines;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) lines.push_back(json::parse(line));
  return lines;
}

TEST(CliSheets, ProgressFdGetsOneLinePerPhaseInOrder) {
  TempDir out("progress");
  fs::create_directories(out.path);
  const fs::path file = out.path / "progress.jsonl";
  // --compare-strategies: the deviation phase has three steps to show.
  const auto r = lamina("plan " + quoted(kKnob) + " --stock 5 --compare-strategies true --out " + quoted(out.path / "plan") +
                        " --progress-fd 3 3>" + quoted(file));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  std::vector<json> lines, within;  // phases as they start; steps inside a phase (issue 18)
  for (const json& l : progress_lines(file)) (l.contains("total") ? within : lines).push_back(l);
  const std::vector<std::string> phases{"reading the model", "choosing layers", "planning bevels", "nesting and programs",
                                        "measuring deviation", "writing the stack", "writing sheets", "done"};
  ASSERT_EQ(lines.size(), phases.size()) << slurp(file);
  for (std::size_t i = 0; i < phases.size(); ++i) {
    EXPECT_EQ(lines[i]["phase"], phases[i]);
    EXPECT_EQ(lines[i]["step"], std::min<int>(static_cast<int>(i) + 1, 7));
    EXPECT_EQ(lines[i]["steps"], 7);
  }
  // The long phases move a bar inside themselves: each part the nesting places and each sheet,
  // each strategy's deviation.
  const json report = json::parse(slurp(out.path / "plan" / "report.json"));
  std::size_t parts = 0;
  for (const json& sheet : report["sheets"]) parts += sheet["parts"].size();
  std::map<std::string, int> count;
  for (const json& l : within) {
    const std::string phase = l["phase"];
    ++count[phase];
    const auto at = std::find(phases.begin(), phases.end(), phase);
    ASSERT_NE(at, phases.end()) << l;
    EXPECT_EQ(l["step"], at - phases.begin() + 1) << "a step belongs to its phase: " << l;
    EXPECT_GE(l["done"].get<int>(), 1) << l;
    EXPECT_LE(l["done"].get<int>(), l["total"].get<int>()) << l;
  }
  EXPECT_EQ(count["measuring deviation"], 3) << slurp(file);
  EXPECT_EQ(count["nesting and programs"], static_cast<int>(parts + report["sheets"].size())) << slurp(file);
  // Without programs there are five phases; a failed plan stops before "done".
  const auto stack_only = lamina("plan " + quoted(kKnob) + " --no-programs --out " + quoted(out.path / "stack") +
                                 " --progress-fd 3 3>" + quoted(file));
  ASSERT_EQ(stack_only.exit_code, 0) << stack_only.out;
  int starts = 0;
  for (const json& l : progress_lines(file)) starts += !l.contains("total");
  EXPECT_EQ(starts, 6);
  EXPECT_EQ(progress_lines(file).back()["steps"], 5);
  const auto broken = lamina("plan " + quoted(out.path / "missing.stl") + " --out " + quoted(out.path / "x") +
                             " --progress-fd 3 3>" + quoted(file));
  EXPECT_NE(broken.exit_code, 0);
  const auto failed = progress_lines(file);
  ASSERT_FALSE(failed.empty());
  EXPECT_NE(failed.back()["phase"], "done");
}

TEST(CliSheets, NoProgramsStopsAfterTheStack) {
  TempDir out("no-programs");
  const auto r = lamina("plan " + quoted(kKnob) + " --no-programs --out " + quoted(out.path));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_TRUE(fs::exists(out.path / "stack.stl"));
  EXPECT_FALSE(fs::exists(out.path / "sheet-1.nc"));
  const json j = json::parse(slurp(out.path / "report.json"));
  EXPECT_FALSE(j.contains("sheets"));
}

}  // namespace
