// plan_job (issue 18): one entry point for every front end, one typed report that report.json
// serialises and reads back with the same tables. A small sphere is planned whole (layers,
// bevels, nesting, programs, deviation, stack), its report must read back to the same text, and
// reports that do not match the schema are refused naming the key.
#include "lamina/core/plan_job.hpp"
#include "lamina/core/plan_report.hpp"
#include "lamina/core/stack_mesh.hpp"

#include "mesh_soups.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <string>
#include <vector>

namespace lamina {
namespace {

const Mesh& ball() {
  static const Mesh mesh = [] {
    auto m = build_mesh(mesh_test::uv_sphere(20.0, 64, 32, Eigen::Vector3d(0, 0, 20)), MeshParams{});
    return std::move(*m);
  }();
  return mesh;
}

PlanJobRequest request(bool with_programs) {
  PlanJobRequest q;
  q.settings.stock.sheets = {{2.5, 300, 300, 4, "", ""}, {5.0, 300, 300, 8, "", "B4"}};
  q.settings.stock_source = "test";
  q.settings.thicknesses_mm = {2.5, 5.0};
  q.settings.tolerance_mm = 0.3;
  q.settings.tilt_max_deg = 60.0;
  q.settings.tilt_max_rad = 60.0 * 3.14159265358979 / 180.0;
  q.settings.deviation_step_mm = 0.25;
  q.model = {"ball.stl", "stl-binary", "mm", "z", {}, 0.0, 0.0, std::nullopt, std::nullopt};
  if (with_programs) {
    CamSettings cam;
    cam.materials.materials.emplace("aluminium 6061-T6", Material{"aluminium 6061-T6", 2700, 0.0, 213});
    cam.machine.head.rtcp = false;  // the default post is grblHAL's: pivot coordinates and G93
    cam.machine.head.pivot_mm = 120.0;
    cam.machine.head.c_sign = -1;
    cam.machine.head.c_offset_rad = 90.0 * 3.14159265358979 / 180.0;
    cam.parts.kerf_mm = cam.machine.cutting.kerf_mm;
    cam.machine_source = "machine.toml";
    cam.materials_source = "materials.toml";
    q.cam = cam;
  }
  return q;
}

const PlanJobResult& planned() {
  static const PlanJobResult r = [] {
    PlanJobRequest q = request(true);
    q.settings.compare_strategies = true;
    auto p = plan_job(ball(), q);
    if (p) return std::move(*p);
    ADD_FAILURE() << plan_phase_name(p.error().phase) << ": " << p.error().error.message;
    return PlanJobResult{};
  }();
  return r;
}

TEST(PlanJob, TheReportDescribesTheResult) {
  const PlanJobResult& r = planned();
  const PlanReport& report = r.report;
  ASSERT_EQ(report.layers.size(), r.plan.layers.size());
  EXPECT_GE(report.layers.size(), 8u);
  EXPECT_NEAR(report.stack.stack_height_mm, r.layering.stack_height_mm, 0.0);
  ASSERT_TRUE(r.cam && report.sheets && report.cam);
  ASSERT_EQ(report.sheets->size(), r.cam->sheets.size());
  for (std::size_t i = 0; i < r.cam->sheets.size(); ++i) {
    EXPECT_EQ((*report.sheets)[i].program, r.cam->sheets[i].program_name);
    EXPECT_EQ((*report.sheets)[i].program_bytes, static_cast<std::int64_t>(r.cam->sheets[i].program.text.size()));
  }
  ASSERT_EQ(report.deviation.size(), 3u);
  EXPECT_EQ(report.deviation[2].first, "curved");
  EXPECT_LT(report.deviation[2].second.volume_pct, report.deviation[0].second.volume_pct) << "curved beats vertical";
  EXPECT_EQ(r.stack_stl.size(), 84u + 50u * ((r.stack_stl.size() - 84u) / 50u)) << "a whole binary STL";
  EXPECT_GT(report.timing_s.total, 0.0);
}

TEST(PlanJob, ReportJsonReadsBackToTheSameText) {
  const std::string text = plan_report_json(planned().report);
  auto back = parse_plan_report(text);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(plan_report_json(*back), text);
  EXPECT_EQ(back->sheets->front().parts.size(), planned().report.sheets->front().parts.size());
}

// `lamina plan --as-cut` adds the part as cut beside the plan; it reads back, and without it the
// key is left out of the file (reports without it read as they did).
TEST(PlanJob, TheAsCutFiguresReadBackAndAreLeftOutWithoutThem) {
  PlanReport report = planned().report;
  EXPECT_EQ(plan_report_json(report).find("\"as_cut\""), std::string::npos);
  ReportAsCut a;
  a.dir = "cut";
  a.model_volume_mm3 = 1000.0;
  a.planned = {5.0, 0.5, 0.6, {1.0, 2.0, 3.0}};
  a.as_cut = {7.5, 0.75, 0.9, {4.0, 5.0, 6.0}};
  a.parts = 3;
  a.parts_freed = 2;
  a.not_freed = {"L2-1 on sheet 1 at 4.5 mm"};
  a.layers.push_back({2, 400.0, {1.0, 0.25, 0.6, {1.0, 2.0, 3.0}}, {2.0, 0.5, 0.9, {4.0, 5.0, 6.0}}, 1, 0});
  report.as_cut = a;
  const std::string text = plan_report_json(report);
  auto back = parse_plan_report(text);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(plan_report_json(*back), text);
  ASSERT_TRUE(back->as_cut);
  EXPECT_EQ(back->as_cut->not_freed, a.not_freed);
  EXPECT_EQ(back->as_cut->layers.at(0).as_cut.max_at_mm[2], 6.0);
}

// A STEP model's plan says what the file told it (model.cad: unit, chord, normals, solids, surface
// kinds) and what its deviation was measured against; both read back, and a mesh's report
// measured against itself leaves the keys out.
TEST(PlanJob, TheCadFiguresReadBackAndAreLeftOutForAMesh) {
  PlanReport report = planned().report;
  EXPECT_EQ(plan_report_json(report).find("\"cad\""), std::string::npos);
  report.model.cad = ReportCad{"INCH", 0.005, "exact", {{"fork", 118, 4000}, {"pin", 3, 96}}, {{"plane", 40}, {"torus", 81}}};
  report.model.deviation_reference = ReportDeviationReference{"fork.step", "step", 40000, 0.0005};
  const std::string text = plan_report_json(report);
  auto back = parse_plan_report(text);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(plan_report_json(*back), text);
  ASSERT_TRUE(back->model.cad);
  EXPECT_EQ(back->model.cad->solids.at(1).name, "pin");
  ASSERT_TRUE(back->model.deviation_reference);
  EXPECT_EQ(back->model.deviation_reference->chord_tolerance_mm, 0.0005);
  EXPECT_EQ(plan_report_json(planned().report).find("deviation_reference"), std::string::npos);
  EXPECT_EQ(back->model.cad->surface_kinds.at(1), (std::pair<std::string, std::int64_t>{"torus", 81}));
  EXPECT_EQ(nlohmann::json::parse(report_cad_json(*report.model.cad)), nlohmann::json::parse(text)["model"]["cad"]);
}

// A reader of the programs (the web console's 3D toolpath) needs the head to turn X Y Z A C into
// the tool tip and axis, and the operator the rack slot each sheet is taken from.
TEST(PlanJob, TheReportCarriesTheHeadAndEachSheetsRackSlot) {
  const PlanReport& report = planned().report;
  ASSERT_TRUE(report.cam && report.cam->head);
  EXPECT_EQ(report.cam->head->pivot_mm, 120.0);
  EXPECT_EQ(report.cam->head->a_sign, 1);
  EXPECT_EQ(report.cam->head->c_sign, -1);
  EXPECT_NEAR(report.cam->head->c_offset_deg, 90.0, 1e-9);
  EXPECT_FALSE(report.cam->rtcp);
  ASSERT_TRUE(report.sheets);
  std::size_t thick = 0;
  for (const ReportSheet& s : *report.sheets) {
    EXPECT_EQ(s.slot, s.thickness_mm == 5.0 ? std::optional<std::string>("B4") : std::nullopt) << s.index;
    thick += s.thickness_mm == 5.0;
  }
  EXPECT_GT(thick, 0u);
  EXPECT_EQ(report.settings.stock[1].slot, "B4");
  EXPECT_FALSE(report.settings.stock[0].slot);
}

// A job planned by 0.7.0 (no head, no slots) is still read when laminad resumes it after an upgrade.
TEST(PlanJob, AReportWithoutHeadOrSlotsStillReads) {
  nlohmann::json j = nlohmann::json::parse(plan_report_json(planned().report));
  j["cam"].erase("head");
  for (auto& s : j["sheets"]) s.erase("slot");
  for (auto& s : j["settings"]["stock"]) s.erase("slot");
  auto back = parse_plan_report(j.dump());
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_FALSE(back->cam->head);
  EXPECT_FALSE(back->sheets->back().slot);
}

// Which layers were cut from an outline simplified off the material (issue 22): said per layer
// in report.json; a report written before the key reads without it.
TEST(PlanJob, TheReportSaysWhichLayersStandOnASimplifiedOutline) {
  static const Mesh fine = [] {
    auto m = build_mesh(mesh_test::uv_sphere(20.0, 720, 32, Eigen::Vector3d(0, 0, 20)), MeshParams{});
    return std::move(*m);
  }();
  auto r = plan_job(fine, request(false));
  ASSERT_TRUE(r) << r.error().error.message;
  ASSERT_EQ(r->report.layers.size(), r->plan.layers.size());
  int simplified = 0;
  for (std::size_t i = 0; i < r->plan.layers.size(); ++i) {
    ASSERT_TRUE(r->report.layers[i].outline_simplified.has_value()) << "layer " << i;
    EXPECT_EQ(*r->report.layers[i].outline_simplified, r->plan.layers[i].outline_simplified) << "layer " << i;
    simplified += r->plan.layers[i].outline_simplified ? 1 : 0;
  }
  EXPECT_GT(simplified, 0) << "a 720-facet ring is simplified";
  nlohmann::json j = nlohmann::json::parse(plan_report_json(r->report));
  EXPECT_TRUE(j["layers"][0].contains("outline_simplified"));
  for (auto& l : j["layers"]) l.erase("outline_simplified");
  auto back = parse_plan_report(j.dump());
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_FALSE(back->layers.front().outline_simplified);
}

TEST(PlanJob, WithoutProgramsTheReportHasNoSheetsAndReadsBack) {
  auto r = plan_job(ball(), request(false));
  ASSERT_TRUE(r) << r.error().error.message;
  EXPECT_FALSE(r->cam);
  const std::string text = plan_report_json(r->report);
  EXPECT_EQ(text.find("\"sheets\""), std::string::npos);
  auto back = parse_plan_report(text);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_FALSE(back->sheets);
}

// Issue 22: the strategies not chosen cost as much as the plan's own deviation, so they are
// measured only when asked; the chosen one's figures are the same either way.
TEST(PlanJob, TheOtherStrategiesAreMeasuredOnlyWhenAsked) {
  PlanJobRequest q = request(false);
  auto alone = plan_job(ball(), q);
  ASSERT_TRUE(alone) << alone.error().error.message;
  ASSERT_EQ(alone->report.deviation.size(), 1u);
  EXPECT_EQ(alone->report.deviation[0].first, "curved");
  EXPECT_EQ(alone->report.settings.compare_strategies, false);
  q.settings.compare_strategies = true;
  auto all = plan_job(ball(), q);
  ASSERT_TRUE(all) << all.error().error.message;
  ASSERT_EQ(all->report.deviation.size(), 3u);
  EXPECT_EQ(all->report.settings.compare_strategies, true);
  EXPECT_EQ(all->report.deviation[0].first, "vertical");
  EXPECT_EQ(all->report.deviation[2].first, "curved");
  EXPECT_EQ(all->report.deviation[2].second.volume_mm3, alone->report.deviation[0].second.volume_mm3);
  EXPECT_EQ(all->report.deviation[2].second.max_mm, alone->report.deviation[0].second.max_mm);
  const std::string text = plan_report_json(alone->report);
  EXPECT_NE(text.find("\"compare_strategies\": false"), std::string::npos) << "the report says which";
}

TEST(PlanJob, ProgressNamesEveryPhaseInOrderAndItsStepsGrow) {
  std::vector<PlanStep> steps;
  auto r = plan_job(ball(), request(true), [&](const PlanStep& s) { steps.push_back(s); });
  ASSERT_TRUE(r) << r.error().error.message;
  std::vector<PlanPhase> started;
  for (const PlanStep& s : steps)
    if (s.done == 0 && s.total == 0) started.push_back(s.phase);
  EXPECT_EQ(started, (std::vector<PlanPhase>{PlanPhase::choosing_layers, PlanPhase::planning_bevels,
                                             PlanPhase::nesting_and_programs, PlanPhase::measuring_deviation,
                                             PlanPhase::writing_stack}));
  int deviation_steps = 0, sheet_steps = 0, layering_steps = 0, last_done = 0;
  PlanPhase phase = PlanPhase::checking;
  for (const PlanStep& s : steps) {
    if (s.phase != phase) phase = s.phase, last_done = 0;
    if (s.total == 0) continue;
    EXPECT_GT(s.done, last_done) << plan_phase_name(s.phase);
    EXPECT_LE(s.done, s.total) << plan_phase_name(s.phase);
    last_done = s.done;
    deviation_steps += s.phase == PlanPhase::measuring_deviation;
    sheet_steps += s.phase == PlanPhase::nesting_and_programs;
    layering_steps += s.phase == PlanPhase::choosing_layers;
  }
  // The layering's verification moves the bar with every layer it plans (issue 22: it moved once
  // a round before, and said "of 12", the bound, not what was asked).
  EXPECT_GE(layering_steps, static_cast<int>(r->layering.layers.size()));
  EXPECT_EQ(deviation_steps, 1) << "the chosen strategy only, unless compare_strategies";
  // Each part as the nesting places it (the Menger sponge nested for a minute with the bar still),
  // then each sheet's program.
  EXPECT_EQ(sheet_steps, static_cast<int>(r->cam->parts.size() + r->cam->sheets.size()));
}

// The plan's measures (deviation, stack) are taken beside the nesting. When the rack sends the
// stack back (the nesting ran out of a thickness), the measures kept must be the final plan's,
// not those of the stack it sent back.
TEST(PlanJob, WhenTheRackSendsTheStackBackTheMeasuresAreTheFinalPlans) {
  PlanJobRequest q = request(true);
  // One Ø40 layer per 5 mm sheet (70 mm, less the margins), one such sheet: the ball's first
  // stack takes several 5 mm layers, the nesting places one, and the stack is laid out again.
  q.settings.stock.sheets = {{2.5, 300, 300, 40, "", ""}, {5.0, 70, 70, 1, "", ""}};
  auto r = plan_job(ball(), q);
  ASSERT_TRUE(r) << r.error().error.message;
  const auto& w = r->report.warnings;
  ASSERT_TRUE(std::any_of(w.begin(), w.end(), [](const std::string& s) { return s.find("the rack's 5 mm") != s.npos; }))
      << "the rack must have sent the first stack back";
  auto d = measure_deviation(ball(), r->plan, deviation_params(q.settings));
  ASSERT_TRUE(d) << d.error().message;
  ASSERT_EQ(r->deviations.size(), 1u);
  EXPECT_EQ(r->deviations[0].deviation.volume_mm3, d->volume_mm3);
  EXPECT_EQ(r->deviations[0].deviation.max_mm, d->max_mm);
  EXPECT_EQ(r->stack_stl.size(), 84 + 50 * (stack_mesh(r->plan).corners.size() / 3));
}

TEST(PlanJob, AnErrorSaysInWhichPhase) {
  PlanJobRequest q = request(false);
  q.settings.stock.sheets = {{100.0, 0, 0, 0, "", ""}};
  q.settings.thicknesses_mm = {100.0};
  auto r = plan_job(ball(), q);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().phase, PlanPhase::choosing_layers);
  EXPECT_EQ(r.error().error.code, ErrorCode::invalid_argument);

  q = request(false);
  q.settings.deviation_step_mm = 1e-4;  // 400,000 sections over the ball's 40 mm
  r = plan_job(ball(), q);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().phase, PlanPhase::checking);
}

// ---- the schema, one key at a time ----

std::string with(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

std::string error_of(const std::string& text) {
  auto r = parse_plan_report(text);
  return r ? std::string("(accepted)") : r.error().message;
}

TEST(PlanReportSchema, AMismatchIsRefusedWithTheKeysPath) {
  const std::string text = plan_report_json(planned().report);
  EXPECT_EQ(error_of(with(text, "\"program\":", "\"programme\":")),
            "report.json: sheets[0].program: missing");
  EXPECT_EQ(error_of(with(text, "\"index\": 1,\n      \"thickness_mm\"", "\"index\": \"1\",\n      \"thickness_mm\"")),
            "report.json: sheets[0].index: expected an integer, found a string");
  EXPECT_EQ(error_of(with(text, "\"warnings\": [", "\"warnings\": 1, \"extra\": [")),
            "report.json: warnings: expected an array, found a number");
  EXPECT_EQ(error_of(with(text, "\"stock_source\": \"test\",", "\"stock_source\": \"test\", \"colour\": 1,")),
            "report.json: settings.colour: not a key of the report");
  EXPECT_EQ(error_of(with(text, "\"within_tolerance\": ", "\"within_tolerance\": 1, \"was\": ")),
            "report.json: layers[0].within_tolerance: expected a boolean, found a number");
  EXPECT_NE(error_of(text.substr(0, text.size() / 2)).find("report.json: not JSON"), std::string::npos);
  EXPECT_EQ(error_of(with(text, "\"direction\": null", "\"direction\": [0, 0, 1]")), "(accepted)")
      << "an optional member is null or its value";
}

}  // namespace
}  // namespace lamina
