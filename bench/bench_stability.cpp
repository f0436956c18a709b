// Stability-lobe throughput on the literature's benchmark grid (DESIGN.md §5;
// the stability issue's speed criteria): one-DOF benchmark, a/D = 0.05, 200
// speeds from 5 000 to 25 000 rpm x 100 depths up to 10 mm, 40 steps per
// tooth period, for SDM, FDM and FDM2 and 1-4 modes (docs/stability-speed.md
// has the figures and the command); and the boundary mode giving the 200
// limits to 0.1 % depth precision.

#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "../tests/stability/benchmark_1dof.hpp"
#include "robomill/stability/lobes.hpp"

namespace {

using namespace robomill;

std::vector<double> benchmark_speeds() {
  return stability::linear_range(test::rpm(5000.0), test::rpm(25000.0), 200);
}

const char* method_name(int method) {
  return method == 0 ? "sdm" : method == 1 ? "fdm" : "fdm2";
}

// The peers' workload: 200 speeds x 100 depths, m = 40, one or two threads.
void BM_BenchmarkMap(benchmark::State& state) {
  const auto model = test::benchmark_modes(static_cast<int>(state.range(2)), 0.05);
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
  state.SetLabel(method_name(static_cast<int>(state.range(0))));
  // The eigenproblem's size D = 2n (+ n for FDM2) + n x the delayed positions
  // the cut reads (7 of 40 at a/D = 0.05).
  stability::FloquetSolver solver(options.method,
                                  {model.modes().natural_rad_s(), model.modes().damping_ratios()},
                                  options.steps);
  solver.set_delay(60.0 / (model.tool().teeth() * 10000.0));
  state.counters["eigenproblem_size"] =
      static_cast<double>(solver.monodromy(model.sample(1.0, options.steps), 1e-3).rows());
  state.counters["grid_points_per_s"] = benchmark::Counter(
      20000.0 * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_BenchmarkMap)
    ->ArgNames({"method", "threads", "modes"})
    ->Args({0, 1, 1})
    ->Args({1, 1, 1})
    ->Args({2, 1, 1})
    ->Args({0, 1, 2})
    ->Args({1, 1, 2})
    ->Args({0, 1, 3})
    ->Args({1, 1, 3})
    ->Args({0, 1, 4})
    ->Args({1, 1, 4})
    ->Args({1, 2, 1})
    ->Args({0, 2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_BenchmarkBoundary(benchmark::State& state) {
  const auto model = test::benchmark_1dof(0.05);
  stability::LobeOptions options;
  options.method = static_cast<stability::FloquetMethod>(state.range(0));
  options.steps = 40;
  options.depth_max_m = 10e-3;
  options.depth_tolerance = 1e-3;
  options.threads = static_cast<int>(state.range(1));
  const auto speeds = benchmark_speeds();
  int evaluations = 0;
  for (auto _ : state) {
    const auto points = stability::stability_boundary(model, speeds, options);
    evaluations = 0;
    for (const auto& p : points)
      evaluations += p.evaluations;
    benchmark::DoNotOptimize(points);
  }
  state.SetLabel(method_name(static_cast<int>(state.range(0))));
  state.counters["floquet_solves"] = evaluations;
  state.counters["limits_per_s"] = benchmark::Counter(
      200.0 * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_BenchmarkBoundary)
    ->ArgNames({"method", "threads"})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Args({1, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

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
  // The steps out of the cut are one product with a power of e^{A0 h}; what
  // remains is a (2n x 2n)(2n x D) product per step in the cut.
  state.counters["state_size"] = columns;
  state.counters["builds_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
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
