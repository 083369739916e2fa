// The whole of issue 20 on machines whose jet the planner does not know: lamina-sim's physics
// (jet_physics.hpp) → Lamina's coupon cut and measured on it → `lamina calibrate fit` → the knob
// planned with and without jet compensation → every sheet cut on the simulator
// (`lamina-sim --as-cut`) → `lamina plan --as-cut` measures the part as cut beside the plan.
// With compensation the part as cut is within 25 % of the plan's own volume deviation at
// qualities 1, 3 and 5, and at quality 5 the deviation the jet adds (as cut − planned) is at
// least 3x smaller than without. A second machine (a soft material's jet: reversed taper up to a
// faster speed, less trail-back) is held to the same. Quality 1 met the 25 % only once the corners
// had the trail-back's speeds and the feeds the head's rotary rates (docs/jet.md). The numbers
// are printed for docs/jet.md.
#include "coupon_loop.hpp"

#include <fmt/format.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;
using coupon_loop::run;

const std::string kMaterial = "'aluminium 6061-T6'";

struct AsCutFigures {
  double planned_pct = 0.0, as_cut_pct = 0.0, planned_max_mm = 0.0, as_cut_max_mm = 0.0;
  int parts = 0, freed = 0;
};

nlohmann::json read_json(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in, nullptr, false);
}

// Plans examples/<model> (`plan_args`), cuts every sheet on `machine`, and measures it as cut.
AsCutFigures cut_the_model(const std::string& model, const fs::path& dir, const fs::path& machine, const std::string& plan_args) {
  const std::string cli = LAMINA_CLI, sim = LAMINA_SIM;
  const std::string plan = cli + " plan " + std::string(LAMINA_EXAMPLES_DIR) + "/" + model + " --material " + kMaterial +
                           " --dowels 0 " + plan_args;
  std::string out = run(plan + " --out " + (dir / "plan").string() + " > /dev/null");
  const nlohmann::json report = read_json(dir / "plan" / "report.json");
  EXPECT_TRUE(report.contains("sheets")) << out;
  if (!report.contains("sheets")) return {};
  for (const auto& sheet : report["sheets"]) {
    const fs::path program = dir / "plan" / sheet["program"].get<std::string>();
    const fs::path as_cut = dir / "plan" / fmt::format("sheet-{}.ascut.json", sheet["index"].get<int>());
    out = run(sim + " --machine " + machine.string() + " --as-cut " + program.string() + " --sheet-thickness " +
              fmt::format("{}", sheet["thickness_mm"].get<double>()) + " --as-cut-out " + as_cut.string());
    EXPECT_TRUE(out.empty()) << out;
  }
  out = run(plan + " --out " + (dir / "measured").string() + " --as-cut " + (dir / "plan").string() + " > /dev/null");
  const nlohmann::json measured = read_json(dir / "measured" / "report.json");
  EXPECT_TRUE(measured.contains("as_cut")) << out;
  EXPECT_GT(fs::exists(dir / "measured" / "as-cut.stl") ? fs::file_size(dir / "measured" / "as-cut.stl") : 0u, 84u)
      << "the parts as cut, as a mesh";
  if (!measured.contains("as_cut")) return {};
  const auto& a = measured["as_cut"];
  return {a["planned"]["volume_pct"], a["as_cut"]["volume_pct"], a["planned"]["max_mm"], a["as_cut"]["max_mm"],
          a["parts"], a["parts_freed"]};
}

struct Machine {
  std::string name, jet_keys;
};

// The qualities to run: 1, 3 and 5, or LAMINA_JET_LOOP_QUALITIES ("3").
std::vector<int> qualities() {
  const char* env = std::getenv("LAMINA_JET_LOOP_QUALITIES");
  std::vector<int> out;
  std::stringstream list(env ? env : "1,3,5");
  for (std::string q; std::getline(list, q, ',');) out.push_back(std::stoi(q));
  return out;
}

// A fresh folder with the machine's file (machine.toml) and the kerf Lamina fitted from a
// coupon cut on it (kerf.toml); false (and a failure) when the fit wrote nothing.
bool calibrated_folder(const Machine& m, const fs::path& dir) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto [kerf, fit_out] = coupon_loop::calibrate_on(m.name, m.jet_keys);
  EXPECT_NE(fit_out.find("wrote the kerf"), std::string::npos) << fit_out;
  std::ofstream(dir / "kerf.toml") << kerf;
  std::ofstream(dir / "machine.toml") << "head_pivot_mm = 150\n" << m.jet_keys;
  return fit_out.find("wrote the kerf") != std::string::npos;
}

void check_machine(const Machine& m, const std::vector<int>& qualities) {
  const fs::path dir = fs::temp_directory_path() / ("lamina-jet-loop-" + m.name);
  ASSERT_TRUE(calibrated_folder(m, dir));
  for (const int q : qualities) {
    std::map<std::string, AsCutFigures> by_mode;
    for (const std::string mode : {"off", "full"}) {
      const fs::path case_dir = dir / fmt::format("q{}-{}", q, mode);
      by_mode[mode] = cut_the_model("knob.stl", case_dir, dir / "machine.toml",
                                   fmt::format("--quality {} --jet-compensation {} --kerf-file {}", q, mode, (dir / "kerf.toml").string()));
      const AsCutFigures& f = by_mode[mode];
      std::printf("%s q%d %-4s: planned %.3f %% / %.3f mm, as cut %.3f %% / %.3f mm, %d of %d parts freed\n", m.name.c_str(), q,
                  mode.c_str(), f.planned_pct, f.planned_max_mm, f.as_cut_pct, f.as_cut_max_mm, f.freed, f.parts);
      // Uncompensated at quality 1 the hard machine's lag leaves the 10 mm flange held by its bottom.
      if (q > 1 || mode == "full") EXPECT_EQ(f.freed, f.parts) << m.name << " q" << q << " " << mode << ": every part comes out of its sheet";
      EXPECT_GT(f.parts, 0);
    }
    const AsCutFigures &off = by_mode["off"], &full = by_mode["full"];
    EXPECT_NEAR(full.planned_pct, off.planned_pct, 1e-9) << "the same plan, cut two ways";
    EXPECT_LE(std::abs(full.as_cut_pct - full.planned_pct), 0.25 * full.planned_pct)
        << m.name << " q" << q << ": compensated, as cut within 25 % of the plan";
    if (q == 5)
      EXPECT_LE(std::abs(full.as_cut_pct - full.planned_pct), (off.as_cut_pct - off.planned_pct) / 3.0)
          << m.name << ": at quality 5, the jet's share 3x smaller than without";
  }
  fs::remove_all(dir);
}

const Machine kHard{"hard", "jet_separation_mm_per_s_at_10mm = 30\njet_taper_gain = 0.04\njet_taper_offset = 0.002\n"};

TEST(JetLoop, TheKnobAsCutFollowsItsPlanWithCompensation) { check_machine(kHard, qualities()); }

TEST(JetLoop, OnASecondMachineToo) {
  check_machine({"soft", "jet_separation_mm_per_s_at_10mm = 36\njet_taper_gain = 0.05\njet_taper_offset = 0.012\n"
                         "jet_lag_max_deg = 18\njet_slow_widening = 0.3\n"},
                qualities());
}

// examples/cross.stl: one 10 mm layer (the plan is exact: 0 %), four sharp inside corners and
// eight outside ones. Compensated, the corners are cut at the trail-back's corner speeds
// (jet_corners.hpp) and the feeds within the head's rotary rates. With the angle heuristic before
// them, full compensation left 0.803 % / 1.505 mm at quality 1 and 0.311 % / 0.521 mm at quality 3
// (0.60 and 0.54 of the uncompensated volume error; docs/jet.md).
TEST(JetLoop, TheCrossesCornersAsCutFollowTheTrailBacksCornerSpeeds) {
  const fs::path dir = fs::temp_directory_path() / "lamina-jet-loop-cross";
  ASSERT_TRUE(calibrated_folder(kHard, dir));
  for (const int q : {1, 3}) {
    std::map<std::string, AsCutFigures> by_mode;
    for (const std::string mode : {"off", "taper", "full"}) {
      by_mode[mode] = cut_the_model("cross.stl", dir / fmt::format("q{}-{}", q, mode), dir / "machine.toml",
                                    fmt::format("--stock 10 --quality {} --jet-compensation {} --kerf-file {}", q, mode,
                                                (dir / "kerf.toml").string()));
      const AsCutFigures& f = by_mode[mode];
      std::printf("cross q%d %-5s: as cut %.3f %% / %.3f mm, %d of %d parts freed\n", q, mode.c_str(), f.as_cut_pct,
                  f.as_cut_max_mm, f.freed, f.parts);
      EXPECT_EQ(f.freed, f.parts);
      EXPECT_EQ(f.parts, 1);
    }
    const AsCutFigures &off = by_mode["off"], &taper = by_mode["taper"], &full = by_mode["full"];
    EXPECT_LE(full.as_cut_pct, (q == 1 ? 0.45 : 0.4) * off.as_cut_pct) << "q" << q << ": full, the corners' volume error";
    EXPECT_LE(taper.as_cut_pct, 0.4 * off.as_cut_pct) << "q" << q << ": taper, the corners' volume error";
    EXPECT_LE(full.as_cut_max_mm, q == 1 ? 0.6 : 0.3) << "q" << q << ": the lower jet no longer cuts across a corner";
    EXPECT_LE(taper.as_cut_max_mm, 0.3) << "q" << q;
  }
  fs::remove_all(dir);
}

}  // namespace
