// Air costs nothing (issue 31, point 5): the stretches of a move away from the
// stock are timed and measured but not sampled, and the samples near the
// stock are those of a run that samples every step.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "robomill/toolpath/program_analysis.hpp"
#include "toolpath/program_fixtures.hpp"

namespace robomill::toolpath {
namespace test_program_air_cpp {
namespace {

constexpr double kPi = std::numbers::pi;
const double kSpindle = 8000.0 * 2.0 * kPi / 60.0;
const double kFeed = 600e-3 / 60.0;  // 600 mm/min

using fixtures::aluminium;
using fixtures::flat_tool;

Move line_move(const Eigen::Vector3d& from, const Eigen::Vector3d& to, int line,
               MotionKind kind = MotionKind::linear) {
  return fixtures::line_move(from, to, kFeed, kSpindle, kind, line);
}

struct AirRun {
  ProgramAnalysis analysis;
  std::vector<PathSample> samples;
  double volume_left_m3 = 0.0;
};

const StockBox kBox{Eigen::Vector3d(0, -20e-3, 0), Eigen::Vector3d(60e-3, 20e-3, 20e-3)};

AirRun run(const Program& program, bool sample_air) {
  DexelStock stock(kBox, 0.5e-3);
  Tooling tooling;
  tooling.emplace(0, flat_tool());
  ProgramAnalysisSettings settings;
  settings.threads = 2;
  settings.force_steps_per_tooth = 8;
  settings.sample_air = sample_air;
  AirRun result;
  result.analysis = analyse_program(
      program, tooling, aluminium(), stock, settings, [&](std::span<const PathSample> block) {
        result.samples.insert(result.samples.end(), block.begin(), block.end());
      });
  result.volume_left_m3 = stock.volume_m3();
  return result;
}

// A slot that runs out of the stock and 2 m on (a feed move, as a mistyped
// coordinate would be), comes back 2 m along another line and cuts a second
// slot: every sample of the skipped run is one of the full run's (same move,
// same step, same numbers), every sample the full run has beyond it engages
// and removes nothing, and the times, lengths, volume and peaks are the same.
TEST(ProgramAir, AirStretchAddsItsLengthAndTimeButNoSamples) {
  Program program;
  const double z = 18e-3;
  program.moves.push_back(line_move({-10e-3, -5e-3, z}, {-10e-3, -5e-3, z}, 1, MotionKind::rapid));
  program.moves.push_back(line_move({-10e-3, -5e-3, z}, {2.0, -5e-3, z}, 2));
  program.moves.push_back(line_move({2.0, -5e-3, z}, {2.0, 8e-3, z}, 3));
  program.moves.push_back(line_move({2.0, 8e-3, z}, {-10e-3, 8e-3, z}, 4));
  const AirRun full = run(program, true), skipped = run(program, false);

  // The full run samples every step of the 2 m moves at 0.25 mm (half the
  // resolution); the skipped one only near the stock.
  EXPECT_GT(full.samples.size(), 16000u);
  EXPECT_LT(skipped.samples.size(), 2000u);
  EXPECT_EQ(skipped.analysis.samples, skipped.samples.size());

  // Times and lengths: the whole path, sampled or not.
  EXPECT_DOUBLE_EQ(skipped.analysis.cutting_time_s, full.analysis.cutting_time_s);
  EXPECT_NEAR(skipped.analysis.cutting_time_s, (2.01 + 0.013 + 2.01) / kFeed, 1e-9);
  ASSERT_EQ(skipped.analysis.moves.size(), 4u);
  double unsampled_m = 0.0;
  for (std::size_t m = 0; m < 4; ++m) {
    const MoveTotals& a = skipped.analysis.moves[m];
    const MoveTotals& b = full.analysis.moves[m];
    EXPECT_DOUBLE_EQ(a.length_m, b.length_m);
    EXPECT_DOUBLE_EQ(a.time_s, b.time_s);
    EXPECT_EQ(a.steps, b.steps);
    EXPECT_EQ(a.engaged_samples, b.engaged_samples) << "move " << m;
    EXPECT_DOUBLE_EQ(a.removed_m3, b.removed_m3);
    EXPECT_DOUBLE_EQ(a.max_force_n, b.max_force_n);
    EXPECT_EQ(b.unsampled_length_m, 0.0);
    // What is not sampled is measured: the steps left out times the step
    // (all of a move with no sample).
    EXPECT_NEAR(a.unsampled_length_m,
                a.samples == 0 ? a.length_m
                               : a.length_m * static_cast<double>(b.samples - a.samples) /
                                     static_cast<double>(a.steps),
                1e-12);
    unsampled_m += a.unsampled_length_m;
  }
  // The far move (line 3) is all air; the long ones mostly.
  EXPECT_EQ(skipped.analysis.moves[2].samples, 0);
  EXPECT_DOUBLE_EQ(skipped.analysis.moves[2].unsampled_length_m, 13e-3);
  EXPECT_GT(skipped.analysis.moves[1].unsampled_length_m, 1.8);
  EXPECT_GT(skipped.analysis.moves[3].unsampled_length_m, 1.8);
  EXPECT_NEAR(skipped.analysis.unsampled_length_m, unsampled_m, 1e-12);
  EXPECT_NEAR(skipped.analysis.unsampled_time_s, unsampled_m / kFeed, 1e-9);
  EXPECT_EQ(full.analysis.unsampled_length_m, 0.0);

  // The same cut: volume and loads.
  EXPECT_DOUBLE_EQ(skipped.volume_left_m3, full.volume_left_m3);
  EXPECT_DOUBLE_EQ(skipped.analysis.volume_removed_m3, full.analysis.volume_removed_m3);
  EXPECT_GT(skipped.analysis.volume_removed_m3, 1e-7);
  EXPECT_DOUBLE_EQ(skipped.analysis.max_force_n, full.analysis.max_force_n);
  EXPECT_EQ(skipped.analysis.max_force_line, full.analysis.max_force_line);
  EXPECT_EQ(skipped.analysis.engaged_samples, full.analysis.engaged_samples);

  // Sample by sample: the skipped run's samples are the full run's at the
  // same move and step; the full run's others are air.
  std::size_t j = 0;
  for (const PathSample& f : full.samples) {
    if (j < skipped.samples.size() && skipped.samples[j].move == f.move &&
        skipped.samples[j].step == f.step) {
      const PathSample& s = skipped.samples[j++];
      EXPECT_EQ(s.move_fraction, f.move_fraction);
      EXPECT_EQ(s.t_s, f.t_s);
      EXPECT_EQ(s.tip_m, f.tip_m);
      EXPECT_EQ(s.engaged_rad, f.engaged_rad);
      EXPECT_EQ(s.axial_depth_m, f.axial_depth_m);
      EXPECT_EQ(s.section_m2, f.section_m2);
      EXPECT_EQ(s.force_mean_n, f.force_mean_n);
      EXPECT_EQ(s.force_peak_n, f.force_peak_n);
      continue;
    }
    EXPECT_EQ(f.engaged_rad, 0.0) << "move " << f.move << " step " << f.step;
    EXPECT_FALSE(f.analysed);
  }
  EXPECT_EQ(j, skipped.samples.size());
  // A move's samples are consecutive steps.
  for (std::size_t i = 1; i < skipped.samples.size(); ++i) {
    if (skipped.samples[i].move == skipped.samples[i - 1].move) {
      EXPECT_EQ(skipped.samples[i].step, skipped.samples[i - 1].step + 1);
    }
  }
}

// A mistyped coordinate: a 100 km feed move (G1 X100000000) through the
// stock is timed in full, sampled only near the stock, and named in a warning.
TEST(ProgramAir, HundredKilometreMoveIsWarnedAndSampledOnlyNearTheStock) {
  Program program;
  const double z = 18e-3;
  program.moves.push_back(line_move({-10e-3, 0, z}, {-10e-3, 0, z}, 7, MotionKind::rapid));
  program.moves.push_back(line_move({-10e-3, 0, z}, {100e3, 0, z}, 8));
  const AirRun skipped = run(program, false);
  const double length_m = 100e3 + 10e-3;
  EXPECT_NEAR(skipped.analysis.cutting_time_s, length_m / kFeed, 1e-6);
  // Near the stock: the 60 mm block, the cutter's reach and a few steps on
  // each side, at 0.25 mm: well under 1 000 samples (4 × 10⁸ in all).
  EXPECT_LT(skipped.analysis.samples, 1000u);
  EXPECT_GT(skipped.analysis.engaged_samples, 200u);
  EXPECT_GT(skipped.analysis.unsampled_length_m, 100e3 - 1.0);
  bool warned = false;
  for (const ProgramAnalysis::Warning& w : skipped.analysis.warnings)
    warned = warned || (w.line == 8 && w.text.find("100 km long") != std::string::npos);
  EXPECT_TRUE(warned);
}

// The stretch of a move near a box: a straight move clipped exactly; a
// move that passes beside it, or an arc far from it, has none.
TEST(ProgramAir, MoveNearBoxClipsStraightMovesExactly) {
  const StockBox box{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1)};
  const MoveStretch through = move_near_box(line_move({-9, 0.5, 0.5}, {11, 0.5, 0.5}, 1), box, 1.0);
  EXPECT_NEAR(through.from_u, 8.0 / 20.0, 1e-15);
  EXPECT_NEAR(through.to_u, 11.0 / 20.0, 1e-15);
  EXPECT_TRUE(move_near_box(line_move({-9, 2.5, 0.5}, {11, 2.5, 0.5}, 1), box, 1.0).empty());
  EXPECT_FALSE(move_near_box(line_move({-9, 1.9, 0.5}, {11, 1.9, 0.5}, 1), box, 1.0).empty());
  Move arc = line_move({10, 0, 0}, {10, 0, 0}, 1, MotionKind::arc);
  arc.centre_m = Eigen::Vector3d(9, 0, 0);
  arc.sweep_rad = 2.0 * kPi;
  EXPECT_TRUE(move_near_box(arc, box, 1.0).empty());
  EXPECT_FALSE(move_near_box(arc, box, 7.5).empty());
}

}  // namespace
}  // namespace test_program_air_cpp
}  // namespace robomill::toolpath
