// Uncertainty propagation throughput (issue 33, deliverable 5): the stability
// band of a two-mode tool tip by the zero-order method, 1000 draws x 200
// spindle speeds, on one and two threads (the issue asks under 5 s on two
// cores). Each draw is a whole job (job_of_draw reads the job again with the
// draw's values) and a whole zero-order diagram; what the draws share, the
// cut's A0 basis, is computed once (stability_band.cpp, shared_cut_basis).
//
//   build/bench/bench_uncertainty --benchmark_min_time=0.2
//
// The counter limits_per_s is draws x speeds per second of wall time.

#include <benchmark/benchmark.h>

#include <string>

#include "../tests/support/two_mode_tool_tip.hpp"
#include "robomill/analysis/stability_band.hpp"
#include "robomill/analysis/stability_diagram.hpp"
#include "robomill/job/job.hpp"

namespace {

using namespace robomill;

/// A two-mode tool tip (x 703 Hz, y 761 Hz), three teeth in quarter
/// immersion, 200 speeds over 5 000-25 000 rpm (the first lobes of both
/// modes), with the robot cell's usual ignorance: the modes' stiffness and
/// damping (one common factor each) and the cutting coefficients.
std::string band_job_yaml(int draws) {
  return "name: uncertainty benchmark\n" + robomill::test::two_mode_tool_tip_yaml() +
         "stability:\n"
         "  method: zoa\n"
         "  speeds: {from: 5000 rpm, to: 25000 rpm, count: 200}\n"
         "  depth_max: 20 mm\n"
         "  depths: 100\n"
         "uncertainty:\n"
         "  samples: " +
         std::to_string(draws) +
         "\n"
         "  seed: 7\n"
         "  variables:\n"
         "    - {name: stiffness, path: [dynamics.modes.0.k, dynamics.modes.1.k], mode: scale, "
         "distribution: lognormal, sigma: 0.25}\n"
         "    - {name: damping, path: [dynamics.modes.0.zeta, dynamics.modes.1.zeta], mode: "
         "scale, distribution: lognormal, sigma: 0.35}\n"
         "    - {name: coefficients, path: [cutting.Ktc, cutting.Krc], mode: scale, "
         "distribution: lognormal, sigma: 0.1}\n";
}

void BM_StabilityBand(benchmark::State& state) {
  const int draws = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  const job::Job job = job::parse_job(band_job_yaml(draws), "bench_uncertainty.yaml");
  const analysis::StabilityDiagram nominal = analysis::stability_diagram(job, threads);
  for (auto _ : state) {
    benchmark::DoNotOptimize(analysis::stability_band(job, nominal, threads));
  }
  state.counters["limits_per_s"] = benchmark::Counter(
      static_cast<double>(draws) * 200.0 * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate);
}
BENCHMARK(BM_StabilityBand)
    ->ArgNames({"draws", "threads"})
    ->Args({1000, 1})
    ->Args({1000, 2})
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace
