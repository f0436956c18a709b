// A whole program through `robomill toolpath`'s pipeline (issue 18's speed
// target, DESIGN.md §6): a 100 000-line 3-axis G-code program — z-level
// raster passes written as short G1 segments, the way CAM posts a 3-D
// finishing path — on a 300 × 300 × 50 mm stock at 0.5 mm, read by the
// G-code reader, then material removal, engagement and forces at every sample
// (toolpath/program_analysis.hpp) on two threads. The target: under 30 s on
// two cores, memory growing with the stock, not with the program (samples
// stream out in blocks). Reports samples per second, program lines per
// second and the stock's memory.

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <string>

#include "robomill/io/program_readers.hpp"
#include "robomill/toolpath/program_analysis.hpp"

namespace {

using namespace robomill;

// Raster passes along x at 2 mm depth, 5 mm step-over, alternating, each
// pass written as `segments` G1 blocks.
std::string raster_program(int lines) {
  std::string text = "%\nO1000 (BENCH RASTER)\nG90 G94 G17 G21\nT1 M6\nS10000 M3\nG0 X0 Y5 Z55\n";
  const int passes = 58;
  const int per_pass = lines / passes;
  text += "G0 Z48.\nG1 X0 F2400.\n";
  for (int p = 0; p < passes; ++p) {
    const double y = 5.0 + 5.0 * p;
    if (p > 0)
      text += fmt::format("G1 Y{:.3f}\n", y);
    for (int k = 1; k <= per_pass; ++k) {
      const double fraction = static_cast<double>(k) / per_pass;
      const double x = (p % 2 == 0) ? 300.0 * fraction : 300.0 * (1.0 - fraction);
      text += fmt::format("X{:.4f}\n", x);
    }
  }
  text += "G0 Z60.\nM30\n%\n";
  return text;
}

void BM_ToolpathProgram(benchmark::State& state) {
  const int lines = static_cast<int>(state.range(0));
  const std::string text = raster_program(lines);
  const toolpath::Program program = io::read_gcode(text, {});
  tool::ToolSpec spec;
  spec.diameter_m = 10e-3;
  spec.teeth = 3;
  spec.helix_rad = 30.0 * 3.14159265358979 / 180.0;
  spec.overhang_m = 40e-3;
  toolpath::Tooling tooling;
  tooling.emplace(0, tool::Tool(spec));
  cutting::LinearLaw law;
  law.Ktc_pa = 796e6;
  law.Krc_pa = 169e6;
  law.Kte_n_per_m = 27.7e3;
  law.Kre_n_per_m = 15.4e3;
  toolpath::ProgramAnalysisSettings settings;
  settings.threads = 2;
  std::size_t samples = 0, memory = 0;
  for (auto _ : state) {
    toolpath::DexelStock stock({Eigen::Vector3d::Zero(), Eigen::Vector3d(300e-3, 300e-3, 50e-3)},
                               0.5e-3);
    const toolpath::ProgramAnalysis analysis = toolpath::analyse_program(
        program, tooling, law, stock, settings, [](std::span<const toolpath::PathSample>) {});
    samples = analysis.samples;
    memory = stock.memory_bytes();
    benchmark::DoNotOptimize(analysis.max_force_n);
  }
  state.counters["lines"] = lines;
  state.counters["samples"] = static_cast<double>(samples);
  state.counters["samples_per_s"] = benchmark::Counter(
      static_cast<double>(samples), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["lines_per_s"] =
      benchmark::Counter(lines, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["stock_MB"] = static_cast<double>(memory) / 1e6;
}
BENCHMARK(BM_ToolpathProgram)
    ->Arg(10'000)
    ->Arg(100'000)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

}  // namespace
