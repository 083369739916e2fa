// Google Benchmark of the first pipeline stages on a 1,000,000-triangle UV sphere (radius 50 mm)
// sliced every 0.1 mm (1000 planes): read (binary STL), topology (build_mesh), slice, and the
// three together. The STL is written once to a temporary file before the benchmarks run.
//   build/bench/bench_pipeline --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include "lamina/core/mesh.hpp"
#include "lamina/core/mesh_io.hpp"
#include "lamina/core/slice.hpp"
#include "shapes.hpp"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <filesystem>
#include <unistd.h>

namespace {

// The sphere's temporary STL, written on first use and removed at exit (one object owns both).
struct SphereFile {
  std::filesystem::path path;
  ~SphereFile() {
    std::error_code ec;
    if (!path.empty()) std::filesystem::remove(path, ec);
  }
} sphere;

const std::filesystem::path& sphere_file() {
  if (sphere.path.empty()) {
    const auto p = std::filesystem::temp_directory_path() /
                   ("lamina-bench-sphere-" + std::to_string(::getpid()) + ".stl");
    lamina::test::write_binary_stl(lamina::test::uv_sphere(50.0, 1000, 501), p);
    sphere.path = p;
  }
  return sphere.path;
}

void BM_Read(benchmark::State& state) {
  for (auto _ : state) {
    auto soup = lamina::read_mesh_file(sphere_file());
    if (!soup) state.SkipWithError(soup.error().message.c_str());
    benchmark::DoNotOptimize(soup);
  }
}

void BM_Topology(benchmark::State& state) {
  const auto soup = lamina::read_mesh_file(sphere_file());
  for (auto _ : state) {
    auto mesh = lamina::build_mesh(*soup, lamina::MeshParams{});
    benchmark::DoNotOptimize(mesh);
  }
}

void BM_Slice(benchmark::State& state) {
  const auto mesh = lamina::build_mesh(*lamina::read_mesh_file(sphere_file()), lamina::MeshParams{});
  const auto zs = lamina::heights_by_step(mesh->summary.bbox_max_mm.z(), 0.1);
  lamina::SliceParams p;
  p.parallel = state.range(0) != 0;
  for (auto _ : state) {
    auto slices = lamina::slice_mesh(*mesh, zs, p);
    benchmark::DoNotOptimize(slices);
  }
  state.counters["slices"] = static_cast<double>(zs.size());
}

void BM_ReadTopologySlice(benchmark::State& state) {
  for (auto _ : state) {
    auto soup = lamina::read_mesh_file(sphere_file());
    auto mesh = lamina::build_mesh(*soup, lamina::MeshParams{});
    soup = {};
    const auto zs = lamina::heights_by_step(mesh->summary.bbox_max_mm.z(), 0.1);
    auto slices = lamina::slice_mesh(*mesh, zs, lamina::SliceParams{});
    benchmark::DoNotOptimize(slices);
  }
}

}  // namespace

BENCHMARK(BM_Read)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Topology)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Slice)->Arg(1)->Arg(0)->ArgName("parallel")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReadTopologySlice)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();
