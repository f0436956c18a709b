// Stability-lobe throughput on the literature's benchmark grid (DESIGN.md §5;
// the stability issue's speed criteria): one-DOF benchmark, a/D = 0.05, 200
// speeds from 5 000 to 25 000 rpm x 100 depths up to 10 mm, 40 steps per
// tooth period, full discretization; and the boundary mode giving the 200
// limits to 0.1 % depth precision.

#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>

#include "../tests/stability/benchmark_1dof.hpp"
#include "robomill/stability/lobes.hpp"

namespace {

using namespace robomill;

std::vector<double> benchmark_speeds() {
  return stability::linear_range(test::rpm(5000.0), test::rpm(25000.0), 200);
}

void BM_BenchmarkMap(benchmark::State& state) {
  const auto model = test::benchmark_1dof(0.05);
  stability::LobeOptions options;
  options.method = static_cast<stability::FloquetMethod>(state.range(0));
  options.steps = 40;
  options.depth_max_m = 10e-3;
  options.threads = static_cast<int>(state.range(1));
  const auto depths = stability::linear_range(0.1e-3, 10e-3, 100);
  const auto speeds = benchmark_speeds();
  for (auto _ : state) {
    benchmark::DoNotOptimize(stability::stability_map(model, speeds, depths, options));
  }
  state.counters["grid_points_per_s"] = benchmark::Counter(
      20000.0 * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_BenchmarkMap)
    ->ArgNames({"method", "threads"})
    ->Args({1, 1})
    ->Args({1, 2})
    ->Args({0, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_BenchmarkBoundary(benchmark::State& state) {
  const auto model = test::benchmark_1dof(0.05);
  stability::LobeOptions options;
  options.method = stability::FloquetMethod::fdm;
  options.steps = 40;
  options.depth_max_m = 10e-3;
  options.depth_tolerance = 1e-3;
  options.threads = static_cast<int>(state.range(0));
  const auto speeds = benchmark_speeds();
  int evaluations = 0;
  for (auto _ : state) {
    const auto points = stability::stability_boundary(model, speeds, options);
    evaluations = 0;
    for (const auto& p : points)
      evaluations += p.evaluations;
    benchmark::DoNotOptimize(points);
  }
  state.counters["floquet_solves"] = evaluations;
  state.counters["limits_per_s"] = benchmark::Counter(
      200.0 * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_BenchmarkBoundary)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

namespace {

// Where the time of one Floquet solve goes: building the monodromy matrix
// (m steps of 2n-row updates) versus its dense eigenvalues (Hessenberg
// reduction ≈ 10/3 D³ flops plus Francis QR ≈ 10 D³ flops, D = 2n + m n).
// The benchmark at a/D = 0.05, 10 000 rpm, FDM with m = 40: a solver ready
// to build monodromy matrices from per-unit-depth coupling samples.
struct MonodromyCase {
  stability::RegenerativeModel model = test::benchmark_1dof(0.05);
  stability::CouplingSamples samples = model.sample(1.0, 40);
  stability::FloquetSolver solver{stability::FloquetMethod::fdm,
                                  {model.modes().natural_rad_s(), model.modes().damping_ratios()},
                                  40};
  MonodromyCase() { solver.set_delay(60.0 / (2.0 * 10000.0)); }
};

void BM_MonodromyBuild(benchmark::State& state) {
  MonodromyCase c;
  auto& [model, samples, solver] = c;
  double depth = 1e-3;
  double columns = 0.0;
  for (auto _ : state) {
    const Eigen::MatrixXd& psi = solver.monodromy(samples, depth);
    columns = static_cast<double>(psi.cols());
    benchmark::DoNotOptimize(psi.data());
    depth += 1e-9;
  }
  // Per step: (2n x 2n)(2n x D) + 2 (2n x n)(n x D) multiply-adds, n = 1, D the
  // kept state size (the active delayed positions).
  const double flops = 40.0 * 2.0 * (4.0 * columns + 2.0 * 2.0 * columns);
  state.counters["state_size"] = columns;
  state.counters["GFLOP_per_s"] = benchmark::Counter(
      flops * 1e-9 * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MonodromyBuild);

void BM_MonodromyEigenvalues(benchmark::State& state) {
  MonodromyCase c;
  auto& [model, samples, solver] = c;
  const Eigen::MatrixXd psi = solver.monodromy(samples, 1e-3);
  Eigen::EigenSolver<Eigen::MatrixXd> eigen;
  for (auto _ : state) {
    eigen.compute(psi, false);
    benchmark::DoNotOptimize(eigen.eigenvalues().data());
  }
  const double d = static_cast<double>(psi.rows());
  const double flops = (10.0 / 3.0 + 10.0) * d * d * d;  // textbook estimate
  state.counters["state_size"] = d;
  state.counters["GFLOP_per_s"] = benchmark::Counter(
      flops * 1e-9 * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MonodromyEigenvalues);

}  // namespace
