// Throughput of the milling-force kernel: tooth-element force evaluations per
// second (DESIGN.md §6), single-threaded and over the whole sampling.

#include <benchmark/benchmark.h>

#include <numbers>

#include "robomill/cutting/milling_forces.hpp"

namespace {

using namespace robomill;

cutting::MillingForceModel make_model(tool::ToolType type, int elements) {
  tool::ToolSpec spec;
  spec.type = type;
  spec.diameter_m = 0.012;
  spec.teeth = 3;
  spec.helix_rad = 45.0 * std::numbers::pi / 180.0;
  spec.overhang_m = 0.061;
  spec.runout.offset_m = 10e-6;
  cutting::LinearLaw law{855e6, 270.93e6, 0.0, 15.64e3, 14.167e3, 0.0};
  cutting::MillingProcess process{10000.0 * 2.0 * std::numbers::pi / 60.0, 0.02e-3, 4e-3, 4e-3,
                                  cutting::MillingDirection::down};
  return cutting::MillingForceModel(tool::Tool(spec), law, process, elements);
}

void BM_ForceAt(benchmark::State& state) {
  const auto model = make_model(tool::ToolType::flat, static_cast<int>(state.range(0)));
  double angle = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(model.at(angle));
    angle += 0.01;
  }
  // Every (element, tooth) pair is visited once per evaluation.
  state.counters["element_evals_per_s"] = benchmark::Counter(
      static_cast<double>(state.iterations() * state.range(0) * model.tool().teeth()),
      benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ForceAt)->Arg(20)->Arg(100)->Arg(500);

void BM_SampleForces(benchmark::State& state) {
  const auto model = make_model(tool::ToolType::ball, 100);
  const cutting::ForceSampling sampling{10, 360};
  const int threads = static_cast<int>(state.range(0));
  for (auto _ : state) {
    benchmark::DoNotOptimize(cutting::sample_forces(model, sampling, threads));
  }
  const double samples = 10.0 * 3.0 * 360.0;
  state.counters["samples_per_s"] = benchmark::Counter(
      samples * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["element_evals_per_s"] = benchmark::Counter(
      samples * 100.0 * 3.0 * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SampleForces)->Arg(1)->Arg(2)->UseRealTime();

}  // namespace
