// Throughput of the time-domain simulation (simulation/simulator.hpp):
// tooth-element force evaluations per second (DESIGN.md §6), and the issue's
// yardstick — one second of 4-tooth cutting at 10 000 rpm with 20 axial
// elements on a 2-DOF structure (002 Case C's fixation), one core.

#include <benchmark/benchmark.h>

#include <numbers>

#include "robomill/simulation/simulator.hpp"

namespace {

using namespace robomill;

void BM_SimulateOneSecond(benchmark::State& state) {
  tool::ToolSpec spec;
  spec.diameter_m = 20e-3;
  spec.teeth = 4;
  spec.helix_rad = 30.0 * std::numbers::pi / 180.0;
  spec.overhang_m = 80e-3;
  const tool::Tool tool(spec);
  const cutting::FractionalLaw law{5e6, 1.8e-5, 0.1, 0.3, 0.0};  // 002 §3.1
  const cutting::MillingProcess process{10000.0 * 2.0 * std::numbers::pi / 60.0, 1e-4, 2e-3, 20e-3,
                                        cutting::MillingDirection::down};
  const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(2, 2);
  const auto structure =
      simulation::fixation_structure(100.0 * identity, 550.0 * identity, 3e5 * identity);
  simulation::SimulationOptions options;
  options.duration_s = 1.0;
  options.steps_per_tooth = static_cast<int>(state.range(0));
  options.axial_elements = 20;
  simulation::Workpiece part;
  part.border_x_m = 10e-3;
  long long evaluations = 0;
  for (auto _ : state) {
    const auto result = simulation::simulate(tool, law, process, structure, part, options);
    evaluations += result.element_evaluations;
    benchmark::DoNotOptimize(result.displacement_m.back());
  }
  state.counters["element_evals_per_s"] =
      benchmark::Counter(static_cast<double>(evaluations), benchmark::Counter::kIsRate);
  state.counters["simulated_s_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SimulateOneSecond)->Arg(20)->Arg(40)->Arg(100)->Unit(benchmark::kMillisecond);

}  // namespace
