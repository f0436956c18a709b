// The robot along a whole program (issue 19's speed target): a raster of
// side cuts and a slot — about 10 000 samples — on the KR 270 of
// examples/toolpath_robot_pocket.yaml with posture-dependent dynamics (the
// robot's own modes at every posture, 004 Eq 1-2), on two threads: per
// sample the inverse kinematics, the structure, the zero-order stable depth
// (the shortcut of robot_along_path.hpp) and the deflection. The target:
// under 20 s on two cores. Reports samples per second, the solves the
// shortcut needed and the program analysis alone for comparison.

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <memory>
#include <string>

#include "robomill/analysis/robot_path_setup.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/job/job.hpp"
#include "robomill/robot_path/feed_schedule.hpp"
#include "robomill/robot_path/program_optimization.hpp"
#include "robomill/robot_path/robot_along_path.hpp"
#include "robomill/toolpath/program_analysis.hpp"

namespace {

using namespace robomill;

// A slot along x at 2 mm depth, then side cuts 3 mm apart, alternating,
// across a 100 × 60 mm block (workpiece frame, top at z = 20 mm).
std::string raster_program() {
  std::string text = "%\nO1001 (ROBOT BENCH)\nG90 G94 G17 G21\nT1 M6\nS9000 M3\nG0 X-6 Y5 Z25\n";
  text += "G0 Z18.\nG1 X106. F1200.\n";
  for (int p = 1; p < 17; ++p) {
    text += fmt::format("G1 Y{:.3f}\n", 5.0 + 3.0 * p);
    text += fmt::format("G1 X{}.\n", p % 2 == 0 ? 106 : -6);
  }
  text += "G0 Z40.\nM30\n%\n";
  return text;
}

// The example's robot and cut, the raster program, two threads.
struct Bench {
  job::Job job = job::load_job(std::filesystem::path(ROBOMILL_SOURCE_DIR) / "examples" /
                               "toolpath_robot_pocket.yaml");
  toolpath::Program program = io::read_gcode(raster_program(), {});
  toolpath::Tooling tooling;
  toolpath::ProgramAnalysisSettings settings;
  Bench() {
    tooling.emplace(0, tool::Tool(job.toolpath->tools.at(1)));
    settings.threads = 2;
    settings.sample_spacing_m = 0.2e-3;
  }
  toolpath::DexelStock stock() const {
    return toolpath::DexelStock({Eigen::Vector3d::Zero(), Eigen::Vector3d(100e-3, 60e-3, 20e-3)},
                                0.25e-3);
  }
};

void BM_RobotAlongProgram(benchmark::State& state) {
  const bool robot_on = state.range(0) != 0;
  const Bench bench;
  const job::Job& job = bench.job;
  const toolpath::Program& program = bench.program;
  const toolpath::Tooling& tooling = bench.tooling;
  const toolpath::ProgramAnalysisSettings& settings = bench.settings;
  std::size_t samples = 0, solves = 0;
  for (auto _ : state) {
    toolpath::DexelStock stock = bench.stock();
    std::optional<analysis::RobotPathSetup> setup = analysis::robot_path_setup(job, 2);
    robot_path::RobotAlongPath along(*setup->model, setup->structure, tooling, *job.cutting,
                                     setup->stability, setup->settings);
    std::vector<robot_path::RobotSample> block;
    const toolpath::ProgramAnalysis analysis =
        toolpath::analyse_program(program, tooling, *job.cutting, stock, settings,
                                  [&](std::span<const toolpath::PathSample> samples_block) {
                                    if (!robot_on)
                                      return;
                                    block.resize(samples_block.size());
                                    along.evaluate(samples_block, block);
                                  });
    const robot_path::RobotPathSummary summary = along.finish();
    samples = analysis.samples;
    solves = summary.exact_limits;
    benchmark::DoNotOptimize(summary.min_margin);
  }
  state.counters["samples"] = static_cast<double>(samples);
  state.counters["samples_per_s"] = benchmark::Counter(
      static_cast<double>(samples), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["exact_limits"] = static_cast<double>(solves);
}
// --optimize's search: the first pass recording the solved and at-risk
// samples, then every recorded sample's limits at 41 candidate speeds and the
// choice per S word (program_optimization.hpp). The target: under 2 minutes.
void BM_RobotSpindleChoice(benchmark::State& state) {
  const Bench bench;
  const job::Job& job = bench.job;
  const toolpath::Program& program = bench.program;
  const toolpath::Tooling& tooling = bench.tooling;
  const toolpath::ProgramAnalysisSettings& settings = bench.settings;
  std::vector<double> candidates;
  for (int k = 0; k <= 40; ++k)
    candidates.push_back((4000.0 + 200.0 * k) * 2.0 * 3.14159265358979 / 60.0);
  std::size_t recorded_count = 0;
  for (auto _ : state) {
    toolpath::DexelStock stock = bench.stock();
    std::optional<analysis::RobotPathSetup> setup = analysis::robot_path_setup(job, 2);
    robot_path::RobotAlongPath along(*setup->model, setup->structure, tooling, *job.cutting,
                                     setup->stability, setup->settings);
    std::vector<robot_path::RobotSample> block;
    std::vector<robot_path::RecordedSample> recorded;
    toolpath::analyse_program(
        program, tooling, *job.cutting, stock, settings,
        [&](std::span<const toolpath::PathSample> samples_block) {
          block.resize(samples_block.size());
          along.evaluate(samples_block, block);
          for (std::size_t i = 0; i < block.size(); ++i)
            if (block[i].stability && (block[i].exact || block[i].at_risk))
              recorded.push_back({samples_block[i], block[i].q_rad, block[i].margin});
        });
    const auto choices = robot_path::choose_spindle_speeds(
        along, robot_path::spindle_regions(program), recorded, candidates, 0.02, 2);
    recorded_count = recorded.size();
    benchmark::DoNotOptimize(choices.data());
  }
  state.counters["recorded_samples"] = static_cast<double>(recorded_count);
  state.counters["candidate_speeds"] = static_cast<double>(candidates.size());
}
BENCHMARK(BM_RobotSpindleChoice)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

// --optimize's feed schedule (feed_schedule.hpp) on the same program: the
// whole program measured at trial feeds (forces, the robot's posture and
// deflection, joint speeds; no stable depths, which the feed does not move)
// until every line sits under the example's caps (120 N, 50 um, 20 deg/s,
// 50-2000 mm/min). Reports the runs it took and the lines changed.
void BM_RobotFeedSchedule(benchmark::State& state) {
  const Bench bench;
  const job::Job& job = bench.job;
  const toolpath::Program& program = bench.program;
  const toolpath::Tooling& tooling = bench.tooling;
  const toolpath::ProgramAnalysisSettings& settings = bench.settings;
  const robot_path::FeedLimits limits = *job.robot_path->feed_limits;
  int runs = 0;
  std::size_t changed = 0;
  for (auto _ : state) {
    std::optional<analysis::RobotPathSetup> setup = analysis::robot_path_setup(job, 2);
    robot_path::PathStabilitySettings no_limits = setup->stability;
    no_limits.enabled = false;
    const auto make_robot = [&] {
      return std::make_unique<robot_path::RobotAlongPath>(*setup->model, setup->structure, tooling,
                                                          *job.cutting, no_limits, setup->settings);
    };
    const robot_path::FeedSchedule schedule =
        robot_path::schedule_feeds(program, limits, [&](const std::vector<double>& scale) {
          return robot_path::measure_move_loads(program, scale, tooling, *job.cutting,
                                                bench.stock(), settings, make_robot);
        });
    runs = schedule.runs;
    changed = 0;
    for (const robot_path::LineFeed& line : schedule.lines)
      changed += line.changed() ? 1 : 0;
    benchmark::DoNotOptimize(schedule.max_after.force_peak_n);
  }
  state.counters["runs"] = runs;
  state.counters["lines_changed"] = static_cast<double>(changed);
}
BENCHMARK(BM_RobotFeedSchedule)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

BENCHMARK(BM_RobotAlongProgram)
    ->ArgName("robot")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

// Issue 33's speed target for a program: the raster's ~10 000 samples with
// the uncertain robot of examples/uncertainty_toolpath.yaml (a common factor
// on the joint stiffnesses, the modal damping ratio, Ktc and Krc), 200
// draws: each draw's structure at every sample's posture and its stable
// depths by the shortcut, P(chatter) per sample. The target: under 60 s on
// two cores. Reports the draws' zero-order solves and solves per second.
void BM_RobotAlongProgramDraws(benchmark::State& state) {
  const Bench bench;
  const job::Job job = job::load_job(
      std::filesystem::path(ROBOMILL_SOURCE_DIR) / "examples" / "uncertainty_toolpath.yaml",
      {{"uncertainty.samples", std::to_string(state.range(0))}});
  std::size_t samples = 0, solves = 0;
  double expected = 0.0;
  for (auto _ : state) {
    toolpath::DexelStock stock = bench.stock();
    std::optional<analysis::RobotPathSetup> setup = analysis::robot_path_setup(job, 2);
    const analysis::RobotPathDraws draws = analysis::robot_path_draws(job, 2);
    robot_path::RobotAlongPath along(*setup->model, setup->structure, bench.tooling, *job.cutting,
                                     setup->stability, setup->settings);
    along.set_draws(draws.path_draws());
    std::vector<robot_path::RobotSample> block;
    const toolpath::ProgramAnalysis analysis =
        toolpath::analyse_program(bench.program, bench.tooling, *job.cutting, stock, bench.settings,
                                  [&](std::span<const toolpath::PathSample> samples_block) {
                                    block.resize(samples_block.size());
                                    along.evaluate(samples_block, block);
                                  });
    const robot_path::RobotPathSummary summary = along.finish();
    samples = analysis.samples;
    solves = summary.draw_exact_limits;
    expected = summary.expected_chatter_samples;
    benchmark::DoNotOptimize(summary.max_p_chatter);
  }
  state.counters["samples"] = static_cast<double>(samples);
  state.counters["draw_solves"] = static_cast<double>(solves);
  state.counters["solves_per_s"] = benchmark::Counter(
      static_cast<double>(solves), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["expected_chatter_samples"] = expected;
}
BENCHMARK(BM_RobotAlongProgramDraws)
    ->ArgName("draws")
    ->Arg(200)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

}  // namespace
