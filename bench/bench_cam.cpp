// Google Benchmark of the cut-program stages on the 1,000,000-triangle sphere (radius 50 mm, the
// same mesh as bench_pipeline), planned once with `lamina plan`'s defaults (stock 1, 2.5, 5, 10 mm,
// optimal layering, curved bevels): parts, nesting (matrix and shape, side by side), the toolpaths
// of every sheet, and posting every sheet (toolpath + G-code) — the "≤ 2 s".
//   build/bench/bench_cam --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include "lamina/core/bevel.hpp"
#include "lamina/core/layering.hpp"
#include "lamina/core/mesh.hpp"
#include "lamina/core/nest.hpp"
#include "lamina/core/parts.hpp"
#include "lamina/core/post.hpp"
#include "lamina/core/toolpath.hpp"
#include "shapes.hpp"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>

namespace {

struct SpherePlan {
  lamina::BevelPlan plan;
  std::vector<lamina::Part> parts;
  lamina::Stock stock;
  lamina::Material material;
};

[[noreturn]] void die(const std::string& what) {
  std::fprintf(stderr, "bench_cam: %s\n", what.c_str());
  std::exit(1);
}

const SpherePlan& sphere() {
  static const SpherePlan s = [] {
    SpherePlan out;
    auto soup = lamina::test::uv_sphere(50.0, 1000, 501);
    auto mesh = lamina::build_mesh(soup, lamina::MeshParams{});
    if (!mesh) die(mesh.error().message);
    lamina::LayeringParams lp;
    lp.thicknesses_mm = {1, 2.5, 5, 10};
    lp.tolerance_mm = 0.2;
    auto layering = lamina::choose_layers(*mesh, lp);
    if (!layering) die(layering.error().message);
    auto plan = lamina::plan_bevels(*mesh, layering->layers, lamina::BevelParams{});
    if (!plan) die(plan.error().message);
    out.plan = std::move(*plan);
    auto parts = lamina::make_parts(out.plan, lamina::PartParams{});
    if (!parts) die(parts.error().message);
    out.parts = std::move(*parts);
    for (double t : {1.0, 2.5, 5.0, 10.0}) out.stock.sheets.push_back({t, 1250.0, 2500.0, 0, "aluminium 6061-T6", ""});
    out.material.name = "aluminium 6061-T6";
    out.material.specific_energy_j_per_m3 = 7.7e9;
    out.material.machinability = 213;
    return out;
  }();
  return s;
}

lamina::Nest nest(lamina::NestMethod method) {
  lamina::NestParams p;
  p.method = method;
  auto n = lamina::nest_parts(sphere().parts, sphere().stock, p);
  if (!n) die(n.error().message);
  return std::move(*n);
}

void BM_Parts(benchmark::State& state) {
  sphere();  // planned once, outside the timed loop
  for (auto _ : state) {
    auto parts = lamina::make_parts(sphere().plan, lamina::PartParams{});
    benchmark::DoNotOptimize(parts);
  }
  state.counters["parts"] = static_cast<double>(sphere().parts.size());
}

void BM_Nest(benchmark::State& state) {
  const auto method = state.range(0) ? lamina::NestMethod::shape : lamina::NestMethod::matrix;
  sphere();
  for (auto _ : state) benchmark::DoNotOptimize(nest(method));
}

// Toolpaths and programs of every sheet: what "posting all sheets" costs once the parts are placed.
void BM_PostAllSheets(benchmark::State& state) {
  const lamina::Nest n = nest(lamina::NestMethod::matrix);
  lamina::HeadKinematics head;
  head.rtcp = state.range(0) != 0;
  lamina::PostParams post;
  post.dialect = head.rtcp ? lamina::PostDialect::fanuc : lamina::PostDialect::grblhal;
  std::size_t bytes = 0;
  for (auto _ : state) {
    bytes = 0;
    for (const auto& sheet : n.sheets) {
      auto tp = lamina::plan_sheet_toolpath(sphere().plan, sphere().parts, sheet, sphere().material, lamina::ToolpathParams{});
      if (!tp) die(tp.error().message);
      auto program = lamina::post_program(*tp, head, post);
      if (!program) die(program.error().message);
      bytes += program->text.size();
    }
  }
  state.counters["sheets"] = static_cast<double>(n.sheets.size());
  state.counters["MB"] = static_cast<double>(bytes) / 1e6;
}

}  // namespace

BENCHMARK(BM_Parts)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Nest)->Arg(0)->Arg(1)->ArgName("shape")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_PostAllSheets)->Arg(0)->Arg(1)->ArgName("rtcp")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();
