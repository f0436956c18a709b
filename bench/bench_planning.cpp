// Throughput of the workpiece-pose objective (004 Eq 6): path evaluations per
// second (20 points: IK, M(q), the harmonic steady state of Eq 1-2) and path
// points per second of the steady state alone, on the 004 example job.

#include <benchmark/benchmark.h>

#include <string>

#include "robomill/job/job.hpp"
#include "robomill/planning/path_performance.hpp"
#include "support/case004.hpp"

namespace {

using namespace robomill;

struct Setup : test::Case004 {
  planning::PlacementProblem problem;
  explicit Setup(planning::OffsetMeasure measure) : problem(Case004::problem(measure)) {}
};

void BM_PathEvaluation(benchmark::State& state) {
  const Setup s(state.range(0) ? planning::OffsetMeasure::startup : planning::OffsetMeasure::peak);
  for (auto _ : state)
    benchmark::DoNotOptimize(planning::evaluate_path(s.robot, s.problem, {0.3, -0.2, 0.3}, 1));
  state.counters["paths_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.SetLabel(state.range(0) ? "startup" : "peak");
}
BENCHMARK(BM_PathEvaluation)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_SteadyStateAtOnePosture(benchmark::State& state) {
  const Setup s(planning::OffsetMeasure::peak);
  const auto path = planning::evaluate_path(s.robot, s.problem, {0.3, -0.2, 0.3}, 1);
  const auto dynamics = planning::posture_dynamics(s.robot, path.points[0].q);
  planning::OffsetWorkspace workspace;
  for (auto _ : state)
    benchmark::DoNotOptimize(planning::steady_state_offset(
        dynamics, path.points[0].placed.tool_to_cell, s.problem.force, workspace));
  state.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SteadyStateAtOnePosture)->Unit(benchmark::kMicrosecond);

}  // namespace
