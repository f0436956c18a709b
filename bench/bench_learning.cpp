// `robomill learn`'s cost (issue 35's speed criterion: 4000 samples, 9
// variables, 20 experiments, the posterior and the next test in under 10 s
// on two cores): analysis::learn on a two-mode tool tip (x and y modes of
// their own: fn, k, ζ each, and Ktc, Krc, Kte: the anchor's nine unknowns
// with the force model in Ktc/Krc rather than Ks/β) from 20 tests, on 1 and 2
// threads, with the switching strategy (so the posterior without the latest
// test and its band are computed too). The tests' verdicts are the nominal
// job's zero-order limits at 20 speeds and depths spread over the grid (a
// golden-ratio sequence, not a grid).
//
// Reported: seconds per learn (the manual time of one iteration) and the
// likelihood evaluations per second.

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <cmath>
#include <string>

#include "robomill/analysis/learning.hpp"
#include "robomill/analysis/learning_model.hpp"
#include "robomill/job/job.hpp"
#include "support/anchor_cut.hpp"

namespace {

using namespace robomill;

std::string job_text(const std::string& experiments) {
  return "name: learning benchmark\n" + test::anchor_cut_yaml() + R"(dynamics:
  modes:
    - {direction: x, fn: 1500 Hz, zeta: 0.03, k: 1.0e7 N/m}
    - {direction: y, fn: 1630 Hz, zeta: 0.025, k: 1.2e7 N/m}
stability: {method: zoa, speeds: {from: 4000 rpm, to: 12000 rpm, count: 200}, depth_max: 8 mm, depths: 100}
uncertainty:
  samples: 1000
  variables:
    - {name: Ktc, path: cutting.Ktc, distribution: truncated_normal, mean: 556, sd: 115, min: 0}
    - {name: Krc, path: cutting.Krc, distribution: truncated_normal, mean: 225, sd: 80, min: 0}
    - {name: Kte, path: cutting.Kte, distribution: truncated_normal, mean: 50, sd: 10, min: 0}
    - {name: fn_x, path: dynamics.modes.0.fn, distribution: truncated_normal, mean: 1500, sd: 150, min: 0}
    - {name: k_x, path: dynamics.modes.0.k, distribution: truncated_normal, mean: 1.0e7, sd: 2.0e6, min: 0}
    - {name: zeta_x, path: dynamics.modes.0.zeta, distribution: truncated_normal, mean: 0.03, sd: 0.009, min: 0}
    - {name: fn_y, path: dynamics.modes.1.fn, distribution: truncated_normal, mean: 1630, sd: 160, min: 0}
    - {name: k_y, path: dynamics.modes.1.k, distribution: truncated_normal, mean: 1.2e7, sd: 2.4e6, min: 0}
    - {name: zeta_y, path: dynamics.modes.1.zeta, distribution: truncated_normal, mean: 0.025, sd: 0.0075, min: 0}
learn: {samples: 4000, seed: 9}
)" + experiments;
}

/// 20 tests labelled by the nominal job's own zero-order limit.
std::string twenty_tests() {
  const job::Job nominal = job::parse_job(job_text(""), "bench.yaml");
  const analysis::LearningModel model(nominal);
  std::string text = "experiments:\n";
  constexpr double golden = 0.6180339887498949;
  for (int i = 1; i <= 20; ++i) {
    const double rpm = 4000.0 + 8000.0 * std::fmod(i * golden, 1.0);
    const double depth_mm = 0.5 + 5.0 * std::fmod(i * golden * golden + 0.31, 1.0);
    std::vector<double> speed = {rpm * 2.0 * M_PI / 60.0};
    std::vector<stability::ZeroOrderLimit> limit(1);
    model.limits(model.nominal_values(), speed, limit);
    const bool chatter = limit[0].limited && depth_mm * 1e-3 > limit[0].depth_limit_m;
    text += fmt::format("  - {{spindle: {:.1f} rpm, depth: {:.3f} mm, chatter: {}}}\n", rpm,
                        depth_mm, chatter ? "true" : "false");
  }
  return text;
}

void BM_Learn20Tests9Variables(benchmark::State& state) {
  static const job::Job job = job::parse_job(job_text(twenty_tests()), "bench.yaml");
  const int threads = static_cast<int>(state.range(0));
  std::int64_t evaluations = 0;
  for (auto _ : state) {
    const analysis::LearningResult r = analysis::learn(job, threads);
    benchmark::DoNotOptimize(r.next.depth_m);
    evaluations += r.sampler.likelihood_evaluations;
    state.SetIterationTime(r.elapsed_s);
  }
  state.counters["evaluations/s"] =
      benchmark::Counter(static_cast<double>(evaluations), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Learn20Tests9Variables)
    ->Arg(1)
    ->Arg(2)
    ->UseManualTime()
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

}  // namespace
