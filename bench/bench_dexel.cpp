// Throughput of the tri-dexel stock and the cutter-workpiece engagement
// (toolpath/dexel_stock.hpp, toolpath/cutter_engagement.hpp), DESIGN.md §6:
// a 300 × 300 × 50 mm stock at 0.5 mm, a 10 mm flat end mill cutting 5 mm
// deep raster passes (step-over 8 mm) sampled every 0.5 mm, as the program
// analysis does it (engagement at p_k, then the sweep p_{k-1} → p_k).
//  - BM_DexelSweep: exact sweeps per second (3-axis: stadium + capsule per
//    ray), with the instances a quarter cell apart they stand for;
//  - BM_DexelInstances: single cutter instances per second (the 5-axis path);
//  - BM_DexelEngagement: engagement queries per second;
//  - BM_DexelProgram: sweep + engagement per sample, the program loop.
// Every benchmark reports the stock's memory_bytes.

#include <benchmark/benchmark.h>

#include <vector>

#include "robomill/toolpath/cutter_engagement.hpp"
#include "robomill/toolpath/dexel_stock.hpp"

namespace {

using namespace robomill::toolpath;
using Eigen::Vector3d;

constexpr double kResolution = 0.5e-3, kStep = 0.5e-3, kStepOver = 8e-3, kDepth = 5e-3;
const CutterShape kCutter{5e-3, 0.0, 40e-3};

StockBox bench_box() {
  StockBox box;
  box.min_m = Vector3d::Zero();
  box.max_m = Vector3d(300e-3, 300e-3, 50e-3);
  return box;
}

// Raster samples: passes along x, alternating, step-over in y, 5 mm deep.
std::vector<Vector3d> raster(int passes) {
  std::vector<Vector3d> path;
  const int per_pass = static_cast<int>(300e-3 / kStep);
  for (int p = 0; p < passes; ++p) {
    const double y = 5e-3 + p * kStepOver;
    for (int k = 0; k <= per_pass; ++k) {
      const double x = (p % 2 == 0) ? k * kStep : 300e-3 - k * kStep;
      path.emplace_back(x, y, 50e-3 - kDepth);
    }
  }
  return path;
}

void BM_DexelSweep(benchmark::State& state) {
  const auto path = raster(static_cast<int>(state.range(0)));
  std::size_t bytes = 0;
  long long sweeps = 0;
  for (auto _ : state) {
    state.PauseTiming();
    DexelStock stock(bench_box(), kResolution);
    state.ResumeTiming();
    for (std::size_t k = 1; k < path.size(); ++k) {
      stock.remove_sweep(kCutter, path[k - 1], Vector3d::UnitZ(), path[k], Vector3d::UnitZ());
    }
    sweeps += static_cast<long long>(path.size() - 1);
    bytes = stock.memory_bytes();
  }
  state.SetItemsProcessed(sweeps);
  // The instances a quarter cell apart that the exact sweeps replace.
  state.counters["instance_equivalents_per_s"] = benchmark::Counter(
      static_cast<double>(sweeps) * kStep / (0.25 * kResolution), benchmark::Counter::kIsRate);
  state.counters["memory_MB"] = static_cast<double>(bytes) / 1e6;
}
BENCHMARK(BM_DexelSweep)->ArgName("passes")->Arg(8)->Unit(benchmark::kMillisecond);

void BM_DexelInstances(benchmark::State& state) {
  const auto path = raster(2);
  DexelStock stock(bench_box(), kResolution);
  // A slightly tilted axis: what 5-axis removal costs per instance.
  const Vector3d axis = Vector3d(0.05, 0.0, 1.0).normalized();
  long long instances = 0;
  std::size_t k = 0;
  for (auto _ : state) {
    stock.remove(kCutter, path[k], axis);
    k = (k + 1) % path.size();
    ++instances;
  }
  state.SetItemsProcessed(instances);
  state.counters["memory_MB"] = static_cast<double>(stock.memory_bytes()) / 1e6;
}
BENCHMARK(BM_DexelInstances);

void BM_DexelEngagement(benchmark::State& state) {
  const auto path = raster(4);
  DexelStock stock(bench_box(), kResolution);
  const std::size_t cut = path.size() * 3 / 4;  // three passes cut, queries on the fourth
  for (std::size_t k = 1; k < cut; ++k) {
    stock.remove_sweep(kCutter, path[k - 1], Vector3d::UnitZ(), path[k], Vector3d::UnitZ());
  }
  const EngagementGrid grid = default_engagement_grid(kCutter, kResolution);
  long long queries = 0;
  std::size_t k = cut;
  for (auto _ : state) {
    const CutterEngagement e =
        engagement_at(stock, kCutter, path[k], Vector3d::UnitZ(), path[k] - path[k - 1], grid);
    benchmark::DoNotOptimize(e.engaged_rad);
    k = k + 1 < path.size() ? k + 1 : cut;
    ++queries;
  }
  state.SetItemsProcessed(queries);
  state.counters["angle_steps"] = grid.angle_steps;
  state.counters["memory_MB"] = static_cast<double>(stock.memory_bytes()) / 1e6;
}
BENCHMARK(BM_DexelEngagement);

void BM_DexelProgram(benchmark::State& state) {
  const auto path = raster(static_cast<int>(state.range(0)));
  const EngagementGrid grid = default_engagement_grid(kCutter, kResolution);
  long long samples = 0;
  std::size_t bytes = 0;
  for (auto _ : state) {
    state.PauseTiming();
    DexelStock stock(bench_box(), kResolution);
    state.ResumeTiming();
    for (std::size_t k = 1; k < path.size(); ++k) {
      const CutterEngagement e =
          engagement_at(stock, kCutter, path[k], Vector3d::UnitZ(), path[k] - path[k - 1], grid);
      benchmark::DoNotOptimize(e.section_m2);
      stock.remove_sweep(kCutter, path[k - 1], Vector3d::UnitZ(), path[k], Vector3d::UnitZ());
    }
    samples += static_cast<long long>(path.size() - 1);
    bytes = stock.memory_bytes();
  }
  state.SetItemsProcessed(samples);
  state.counters["memory_MB"] = static_cast<double>(bytes) / 1e6;
}
BENCHMARK(BM_DexelProgram)->ArgName("passes")->Arg(8)->Unit(benchmark::kMillisecond);

}  // namespace
