// Google Benchmark of the mesh readers' worst cases (issue 16, item 12): a 3MF whose nested
// components expand to many instances, a 3MF with many build items, an OBJ face with many corners
// (a circle and a star), and the stack caps' triangulation of such a ring. Only the API that
// existed before the fix is used, so bench/readers_old_vs_new.sh can build this same file against
// the old lamina_core and run both side by side.
//   build/bench/bench_readers --benchmark_filter=Obj
#include "io_test_util.hpp"
#include "lamina/core/mesh_io.hpp"
#include "geometry/polygon_triangulation.hpp"  // core/src: the private header of the core being measured

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace {

using lamina::test::kTriangleObject;
using lamina::test::model;
using lamina::test::package;

// Object k + 1 holds `fanout` components of object k; one build item of the top object, so the
// build has fanout^levels triangles from a file of a few hundred bytes.
std::vector<std::byte> nested_components(int levels, int fanout) {
  std::string resources = kTriangleObject;
  for (int k = 1; k <= levels; ++k) {
    resources += fmt::format("<object id=\"{}\" type=\"model\"><components>", k + 1);
    for (int c = 0; c < fanout; ++c)
      resources += fmt::format("<component objectid=\"{}\" transform=\"1 0 0 0 1 0 0 0 1 {} 0 0\"/>", k, c);
    resources += "</components></object>\n";
  }
  return package(model(resources, fmt::format("<item objectid=\"{}\"/>\n", levels + 1)));
}

std::vector<std::byte> many_items(int items) {
  std::string build;
  for (int i = 0; i < items; ++i) build += fmt::format("<item objectid=\"1\" transform=\"1 0 0 0 1 0 0 0 1 {} 0 0\"/>\n", i);
  return package(model(kTriangleObject, build));
}

// An n-gon on the unit circle, or a star (every other corner at radius 0.5: n/2 reflex corners).
std::vector<Eigen::Vector2d> ring(int n, bool star) {
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * std::numbers::pi * i / n, r = star && i % 2 == 1 ? 0.5 : 1.0;
    pts.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  return pts;
}

std::string obj_face(int n, bool star) {
  std::string text;
  for (const auto& p : ring(n, star)) text += fmt::format("v {:.9g} {:.9g} 0\n", p.x(), p.y());
  text += "f";
  for (int i = 1; i <= n; ++i) text += fmt::format(" {}", i);
  return text + "\n";
}

void run_3mf(benchmark::State& state, const std::vector<std::byte>& zip) {
  std::size_t triangles = 0;
  for (auto _ : state) {
    auto soup = lamina::parse_3mf(zip, "bench.3mf");
    if (!soup) {
      state.SkipWithError(soup.error().message.c_str());
      return;
    }
    triangles = soup->triangle_count();
  }
  state.counters["triangles"] = static_cast<double>(triangles);
  state.counters["file_bytes"] = static_cast<double>(zip.size());
}

// Arg: the fan-out per level of 4 levels (fanout^4 instances).
void BM_3mfNestedComponents(benchmark::State& state) {
  run_3mf(state, nested_components(4, static_cast<int>(state.range(0))));
}

void BM_3mfBuildItems(benchmark::State& state) { run_3mf(state, many_items(static_cast<int>(state.range(0)))); }

void BM_ObjFace(benchmark::State& state) {
  const std::string text = obj_face(static_cast<int>(state.range(0)), state.range(1) != 0);
  for (auto _ : state) {
    auto soup = lamina::parse_obj(text, "bench.obj");
    if (!soup) {
      state.SkipWithError(soup.error().message.c_str());
      return;
    }
    benchmark::DoNotOptimize(soup->corners.data());
  }
}

void BM_CapTriangulation(benchmark::State& state) {
  lamina::Polygon2 outer;
  for (const auto& p : ring(static_cast<int>(state.range(0)), state.range(1) != 0)) outer.push_back(p);
  for (auto _ : state) {
    auto tris = lamina::geometry_detail::triangulate_polygon_with_holes(outer, {});
    benchmark::DoNotOptimize(tris.data());
  }
}

constexpr auto kUnit = benchmark::kMillisecond;
BENCHMARK(BM_3mfNestedComponents)->Arg(6)->Arg(10)->Arg(14)->Unit(kUnit)->UseRealTime();
BENCHMARK(BM_3mfBuildItems)->Arg(2000)->Arg(5000)->Arg(20000)->Unit(kUnit)->UseRealTime();
BENCHMARK(BM_ObjFace)->ArgsProduct({{1000, 10000, 100000}, {0, 1}})->ArgNames({"corners", "star"})->Unit(kUnit)->UseRealTime();
BENCHMARK(BM_CapTriangulation)->ArgsProduct({{1000, 10000, 100000}, {0, 1}})->ArgNames({"corners", "star"})->Unit(kUnit)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
