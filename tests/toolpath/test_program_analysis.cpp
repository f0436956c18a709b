// The cut along a program against closed forms (issue 18, "How it will be
// judged"): a straight slot against `robomill forces` for the same cut, a side
// cut against the arccos law, the steady engagement of a round pocket corner
// against its geometric closed form, a helical ramp's depth per turn against
// its pitch, the removed volume against the analytic volume, and the same
// pocket in G-code, APT and KRL.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "robomill/cutting/milling_forces.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/toolpath/arc.hpp"
#include "robomill/toolpath/program_analysis.hpp"
#include "toolpath/program_fixtures.hpp"

namespace robomill::toolpath {
namespace test_program_analysis_cpp {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
const std::filesystem::path kSource = ROBOMILL_SOURCE_DIR;

using fixtures::aluminium;
using fixtures::flat_tool;
using fixtures::line_move;

// Runs a program and keeps every sample.
struct ProgramRun {
  ProgramAnalysis analysis;
  std::vector<PathSample> samples;
};

ProgramRun run(const Program& program, const tool::Tool& cutter, DexelStock& stock,
               ProgramAnalysisSettings settings = {}) {
  ProgramRun result;
  Tooling tooling;
  tooling.emplace(0, cutter);
  settings.threads = 2;
  result.analysis = analyse_program(
      program, tooling, aluminium(), stock, settings, [&](std::span<const PathSample> block) {
        result.samples.insert(result.samples.end(), block.begin(), block.end());
      });
  return result;
}

const double kSpindle = 8000.0 * 2.0 * kPi / 60.0;
const double kFeed = 600e-3 / 60.0;  // 600 mm/min

// A slot along +x from x = −10 to 50 mm at y = 0 with the tip at height z:
// the approach (a rapid to the start) and the one feed move.
Program straight_slot(double z_m) {
  Program program;
  program.moves.push_back(
      line_move({-10e-3, 0, z_m}, {-10e-3, 0, z_m}, kFeed, kSpindle, MotionKind::rapid));
  program.moves.push_back(line_move({-10e-3, 0, z_m}, {50e-3, 0, z_m}, kFeed, kSpindle));
  return program;
}

// A straight slot: a program of one approach and one feed move along +x at
// depth ap through a fresh stock. Every sample away from the ends engages
// [0, π] over the depth, so its forces must be those of `robomill forces` for
// a slot of that depth (cutting::MillingForceModel with ae = D, sampled at the
// same rotation steps): to 0.1 % (the issue's tolerance). Assumption: the
// stock top and the depth are multiples of the slice height, so ap is exact.
TEST(ProgramAnalysis, SlotForcesAreThoseOfTheForcesCommand) {
  const tool::Tool cutter = flat_tool();
  const double ap = 2e-3, top = 20e-3;
  DexelStock stock({Eigen::Vector3d(0, -20e-3, 0), Eigen::Vector3d(60e-3, 20e-3, top)}, 0.25e-3);
  const Program program = straight_slot(top - ap);
  ProgramAnalysisSettings settings;
  settings.force_steps_per_tooth = 90;
  const ProgramRun result = run(program, cutter, stock, settings);

  cutting::MillingProcess process;
  process.spindle_rad_s = kSpindle;
  process.feed_per_tooth_m = kFeed / (3 * 8000.0 / 60.0);
  process.axial_depth_m = ap;
  process.radial_depth_m = cutter.diameter_m();
  const cutting::MillingForceModel model(cutter, aluminium(), process,
                                         cutting::default_axial_elements(cutter, ap));
  const cutting::ForceSeries series = cutting::sample_forces(model, {1, 90}, 1);
  const cutting::ForceStatistics stats = cutting::summarize(series, kSpindle);
  double peak = 0.0;
  for (const Eigen::Vector3d& f : series.force_n)
    peak = std::max(peak, f.norm());

  int checked = 0;
  for (const PathSample& s : result.samples) {
    if (s.kind != MotionKind::linear || s.tip_m.x() < 10e-3 || s.tip_m.x() > 40e-3)
      continue;
    ++checked;
    EXPECT_NEAR(s.engaged_rad, kPi, 1e-9) << "x = " << s.tip_m.x();
    EXPECT_NEAR(s.axial_depth_m, ap, 1e-9);
    EXPECT_NEAR(s.radial_width_m, cutter.diameter_m(), 1e-9);
    EXPECT_NEAR(s.force_mean_n.x(), stats.mean_n.x(), 1e-3 * stats.mean_n.norm());
    EXPECT_NEAR(s.force_mean_n.y(), stats.mean_n.y(), 1e-3 * stats.mean_n.norm());
    EXPECT_NEAR(s.force_mean_n.z(), stats.mean_n.z(), 1e-3 * stats.mean_n.norm());
    EXPECT_NEAR(s.force_peak_n, peak, 1e-3 * peak);
    EXPECT_NEAR(s.torque_mean_nm, stats.mean_torque_nm, 1e-3 * std::abs(stats.mean_torque_nm));
    EXPECT_NEAR(s.power_w, stats.mean_power_w, 1e-3 * std::abs(stats.mean_power_w));
  }
  EXPECT_GT(checked, 50);
  // Removed volume: L D ap plus the half disc at the slot's end, within 1 %
  // (the issue's tolerance); the slot enters the stock at its face x = 0 and
  // ends at x = 50 mm, so the stock loses (50 mm × D + π R² / 2) × ap.
  const double radius = cutter.radius_m();
  const double expected = (50e-3 * cutter.diameter_m() + 0.5 * kPi * radius * radius) * ap;
  EXPECT_NEAR(result.analysis.volume_removed_m3, expected, 0.01 * expected);
}

// The mean loads of `robomill forces` for a slot of depth ap with this cutter.
cutting::ForceStatistics forces_command_slot(const tool::Tool& cutter, double ap) {
  cutting::MillingProcess process;
  process.spindle_rad_s = kSpindle;
  process.feed_per_tooth_m = kFeed / (cutter.teeth() * 8000.0 / 60.0);
  process.axial_depth_m = ap;
  process.radial_depth_m = cutter.diameter_m();
  const cutting::MillingForceModel model(cutter, aluminium(), process,
                                         cutting::default_axial_elements(cutter, ap));
  return cutting::summarize(cutting::sample_forces(model, {1, 90}, 1), kSpindle);
}

tool::Tool shaped_tool(tool::ToolType type, double corner_m) {
  tool::ToolSpec spec;
  spec.type = type;
  spec.diameter_m = 10e-3;
  spec.teeth = 3;
  spec.helix_rad = 30.0 * kDeg;
  spec.overhang_m = 40e-3;
  spec.corner_radius_m = corner_m;
  return tool::Tool(spec);
}

// One straight slot of depth ap through a fresh stock whose top is 20.137 mm;
// the samples of its steady middle.
std::vector<PathSample> steady_slot(const tool::Tool& cutter, double ap, double resolution_m) {
  const double top = 20.137e-3;
  DexelStock stock({Eigen::Vector3d(0, -20e-3, 0), Eigen::Vector3d(60e-3, 20e-3, top)},
                   resolution_m);
  const Program program = straight_slot(top - ap);
  ProgramAnalysisSettings settings;
  settings.force_steps_per_tooth = 90;
  std::vector<PathSample> steady;
  for (const PathSample& s : run(program, cutter, stock, settings).samples) {
    if (s.kind == MotionKind::linear && s.tip_m.x() >= 10e-3 && s.tip_m.x() <= 40e-3)
      steady.push_back(s);
  }
  return steady;
}

// Issue 31, point 1: the depth of cut is the program's, not the slice
// grid's. Slots 0.3, 0.6, 1.1 and 2.2 mm deep (not multiples of the 0.25 or
// 0.5 mm slices) under a stock top at 20.137 mm (not on any grid line), at
// 0.5 and 0.25 mm resolution: ap, the chip area, the section and the mean
// force of every sample in the steady part of the slot equal the program's
// depth and `robomill forces` for a slot of that depth. Before: ap 0.5 mm
// for the 0.6 mm slot (forces −16.6 %), the 0.3 mm slot unseen at 0.5 mm.
// Tolerances: ap within 0.1 µm (the stock's float ray coordinates on a
// 20 mm box round to 2 nm; the issue asks 1 %); the mean force within 0.2 %
// (the issue asks 1.5 %; what is left is the force samples' rotation
// steps, the same in both); section and chip area within 0.1 %.
struct SlotCase {
  double depth_mm, resolution_mm;
};
class ExactSlotDepth : public ::testing::TestWithParam<SlotCase> {};

TEST_P(ExactSlotDepth, DepthAndForcesAreTheProgramsWhateverTheGrid) {
  const auto [depth_mm, resolution_mm] = GetParam();
  const tool::Tool cutter = flat_tool(10e-3, 3, 30.0);
  const double ap = depth_mm * 1e-3;
  const std::vector<PathSample> samples = steady_slot(cutter, ap, resolution_mm * 1e-3);
  const cutting::ForceStatistics stats = forces_command_slot(cutter, ap);
  const double fz = kFeed / (3 * 8000.0 / 60.0);
  for (const PathSample& s : samples) {
    ASSERT_TRUE(s.analysed) << "x = " << s.tip_m.x();
    EXPECT_NEAR(s.axial_depth_m, ap, 1e-7) << "x = " << s.tip_m.x();
    EXPECT_NEAR(s.section_m2, cutter.diameter_m() * ap, 1e-3 * cutter.diameter_m() * ap);
    // Mean Σ h b over a tooth period of a slot: N fz 2 ap / (2π) (h = fz
    // sin φ, b = dz, and a slot's ∫ sin φ dφ over [0, π] is 2).
    const double chip_area = 3 * fz * 2.0 * ap / (2.0 * kPi);
    EXPECT_NEAR(s.chip_area_m2, chip_area, 1e-3 * chip_area);
    EXPECT_NEAR(s.force_mean_n.x(), stats.mean_n.x(), 2e-3 * stats.mean_n.norm());
    EXPECT_NEAR(s.force_mean_n.y(), stats.mean_n.y(), 2e-3 * stats.mean_n.norm());
    EXPECT_NEAR(s.force_mean_n.z(), stats.mean_n.z(), 2e-3 * stats.mean_n.norm());
    EXPECT_NEAR(s.power_w, stats.mean_power_w, 2e-3 * std::abs(stats.mean_power_w));
  }
  EXPECT_GT(samples.size(), 20u);
}

INSTANTIATE_TEST_SUITE_P(
    IssueDepths, ExactSlotDepth,
    ::testing::Values(SlotCase{0.3, 0.5}, SlotCase{0.6, 0.5}, SlotCase{1.1, 0.5},
                      SlotCase{2.2, 0.5}, SlotCase{0.3, 0.25}, SlotCase{0.6, 0.25},
                      SlotCase{1.1, 0.25}, SlotCase{2.2, 0.25},
                      // thinner than half a 0.5 mm slice
                      SlotCase{0.12, 0.5}, SlotCase{0.07, 0.25}),
    [](const ::testing::TestParamInfo<SlotCase>& info) {
      return "ap" + std::to_string(static_cast<int>(std::lround(info.param.depth_mm * 1000))) +
             "um_res" +
             std::to_string(static_cast<int>(std::lround(info.param.resolution_mm * 1000))) + "um";
    });

// A slot through a 3.37 mm plate with the tip 1.13 mm below it (a profile
// cut through the part, as CAM writes it): the engaged edge runs from the
// plate's bottom to its top, 1.13 … 4.50 mm above the tip, whatever the
// slices. The mean force is that of a 3.37 mm slot (the helix lag only
// shifts each element's phase, which the mean over a tooth period does not
// see); ap is measured from the tip.
TEST(ProgramAnalysis, ThroughSlotEngagesThePlateOnly) {
  const tool::Tool cutter = flat_tool(10e-3, 3, 30.0);
  const double plate = 3.37e-3, below = 1.13e-3;
  DexelStock stock({Eigen::Vector3d(0, -20e-3, 0), Eigen::Vector3d(60e-3, 20e-3, plate)}, 0.5e-3);
  const Program program = straight_slot(-below);
  ProgramAnalysisSettings settings;
  settings.force_steps_per_tooth = 90;
  const ProgramRun result = run(program, cutter, stock, settings);
  const cutting::ForceStatistics stats = forces_command_slot(cutter, plate);
  int checked = 0;
  for (const PathSample& s : result.samples) {
    if (s.kind != MotionKind::linear || s.tip_m.x() < 10e-3 || s.tip_m.x() > 40e-3)
      continue;
    ++checked;
    EXPECT_NEAR(s.axial_depth_m, plate + below, 1e-7);
    EXPECT_NEAR(s.section_m2, cutter.diameter_m() * plate, 1e-3 * cutter.diameter_m() * plate);
    EXPECT_NEAR(s.force_mean_n.x(), stats.mean_n.x(), 1e-2 * stats.mean_n.norm());
    EXPECT_NEAR(s.force_mean_n.y(), stats.mean_n.y(), 1e-2 * stats.mean_n.norm());
    EXPECT_NEAR(s.power_w, stats.mean_power_w, 1e-2 * std::abs(stats.mean_power_w));
  }
  EXPECT_GT(checked, 20);
}

// Issue 31, point 2, along a program: a bull nose with a 0.001 mm corner
// cuts the flat end mill's slot and one with R − 0.001 mm the ball's: the
// same ap, section and mean loads to 0.1 % (the dexel sweeps, engagement
// probes and force elements of the torus against those of the cylinder and
// the sphere).
TEST(ProgramAnalysis, BullNoseLimitsAlongAProgram) {
  struct Limit {
    tool::Tool bull, reference;
    std::string name;
  };
  const std::vector<Limit> limits = {
      {shaped_tool(tool::ToolType::bull, 0.001e-3), shaped_tool(tool::ToolType::flat, 0.0), "flat"},
      {shaped_tool(tool::ToolType::bull, 5e-3 - 0.001e-3), shaped_tool(tool::ToolType::ball, 0.0),
       "ball"}};
  for (const Limit& limit : limits) {
    for (const double ap : {1.3e-3, 6.7e-3}) {
      const std::vector<PathSample> bull = steady_slot(limit.bull, ap, 0.25e-3);
      const std::vector<PathSample> reference = steady_slot(limit.reference, ap, 0.25e-3);
      ASSERT_EQ(bull.size(), reference.size());
      ASSERT_GT(bull.size(), 20u);
      for (std::size_t i = 0; i < bull.size(); ++i) {
        const PathSample &b = bull[i], &r = reference[i];
        SCOPED_TRACE(limit.name + " limit, ap " + std::to_string(ap * 1e3) + " mm, x " +
                     std::to_string(b.tip_m.x() * 1e3) + " mm");
        EXPECT_NEAR(b.axial_depth_m, r.axial_depth_m, 1e-7);
        EXPECT_NEAR(b.section_m2, r.section_m2, 1e-3 * r.section_m2);
        EXPECT_LE((b.force_mean_n - r.force_mean_n).norm(), 1e-3 * r.force_mean_n.norm());
        EXPECT_NEAR(b.power_w, r.power_w, 1e-3 * r.power_w);
      }
    }
  }
}

// A bull nose's slot shallower than its corner (r_c = 2.5 mm, ap 1.37 mm):
// the cross-section is the area under the corner's profile,
//   S = 2 [(R − r_c) ap + ∫ √(r_c² − u²) du over u ∈ [r_c − ap, r_c]],
// every slice above the lowest engages the whole front half, and the power
// and mean force are those of `robomill forces` for the same slot.
// Tolerances: the section 0.5 % (slices at 0.25 mm take r at their centres:
// the midpoint rule on a profile with a square root at the tip); power and
// force 3 %: the lowest slice, where the corner is almost flat (κ 18°), is
// tested on the vertical rays (its normal is mostly axial), which place the
// slot's side walls only to a cell, and it misses 0.15 rad at each side
// (measured: power −2.5 %, docs/toolpath.md "Limits"; a ball end has the
// same, which the limit test above shares).
TEST(ProgramAnalysis, BullNoseSlotInsideTheCornerMatchesItsClosedForm) {
  const double radius = 5e-3, corner = 2.5e-3, ap = 1.37e-3;
  const tool::Tool bull = shaped_tool(tool::ToolType::bull, corner);
  const std::vector<PathSample> samples = steady_slot(bull, ap, 0.25e-3);
  ASSERT_GT(samples.size(), 20u);
  auto antiderivative = [&](double u) {
    return 0.5 * u * std::sqrt(std::max(0.0, corner * corner - u * u)) +
           0.5 * corner * corner * std::asin(std::clamp(u / corner, -1.0, 1.0));
  };
  const double section =
      2.0 * ((radius - corner) * ap + antiderivative(corner) - antiderivative(corner - ap));
  const cutting::ForceStatistics stats = forces_command_slot(bull, ap);
  for (const PathSample& s : samples) {
    EXPECT_NEAR(s.axial_depth_m, ap, 1e-7);
    EXPECT_NEAR(s.section_m2, section, 5e-3 * section);
    EXPECT_NEAR(s.power_w, stats.mean_power_w, 3e-2 * stats.mean_power_w);
    EXPECT_LE((s.force_mean_n - stats.mean_n).norm(), 3e-2 * stats.mean_n.norm());
  }
}

// A side cut of width ae along a straight edge of the stock, down milling
// (material on the −y side, cutting/engagement.hpp): the engaged arc is
// [acos(ae/R − 1), π]. Tolerance: the angle grid's step plus the dexel
// resolution seen at that angle, res / (R sin φ_entry).
TEST(ProgramAnalysis, SideCutFollowsTheArccosLaw) {
  const tool::Tool cutter = flat_tool();
  const double radius = cutter.radius_m(), resolution = 0.1e-3, top = 10e-3;
  for (double ae : {1e-3, 2.5e-3, 5e-3, 7.5e-3}) {
    SCOPED_TRACE(ae);
    // The tool centre at y = 0; the stock's edge at y = ae − R.
    DexelStock stock({Eigen::Vector3d(0, -20e-3, 0), Eigen::Vector3d(40e-3, ae - radius, top)},
                     resolution);
    Program program;
    program.moves.push_back(line_move({-10e-3, 0, top - 3e-3}, {-10e-3, 0, top - 3e-3}, kFeed,
                                      kSpindle, MotionKind::rapid));
    program.moves.push_back(
        line_move({-10e-3, 0, top - 3e-3}, {40e-3, 0, top - 3e-3}, kFeed, kSpindle));
    const ProgramRun result = run(program, cutter, stock);
    const double entry = std::acos(ae / radius - 1.0);
    const EngagementGrid grid = default_engagement_grid(cutter_shape(cutter), resolution);
    const double tolerance =
        kPi / grid.angle_steps + resolution / (radius * std::max(std::sin(entry), 0.2));
    int checked = 0;
    for (const PathSample& s : result.samples) {
      if (s.kind != MotionKind::linear || s.tip_m.x() < 10e-3 || s.tip_m.x() > 30e-3)
        continue;
      ++checked;
      EXPECT_NEAR(s.entry_rad, entry, tolerance) << "x = " << s.tip_m.x();
      EXPECT_NEAR(s.exit_rad, kPi, kPi / grid.angle_steps);
      EXPECT_NEAR(s.radial_width_m, ae, resolution + radius * kPi / grid.angle_steps);
    }
    EXPECT_GT(checked, 20);
  }
}

// The steady engagement in a round pocket corner. The tool centre turns on a
// circle of radius rc about the corner's centre C; the previous pass left the
// wall concentric at rc + R − ae. A point of the tool circle at angle θ from
// the outward normal lies at |C P|² = rc² + R² + 2 rc R cos θ from C, so the
// front half is in material for cos θ ≥ ((rc + R − ae)² − rc² − R²) / (2 rc
// R): the engaged angle is the arccos of that (→ acos(1 − ae/R) on a straight
// wall as rc → ∞; larger in a tighter corner). The corner is the middle of a
// full turn, once the start's transient is past.
TEST(ProgramAnalysis, PocketCornerEngagementMatchesTheClosedForm) {
  const tool::Tool cutter = flat_tool();
  const double radius = cutter.radius_m(), resolution = 0.1e-3, top = 10e-3, ap = 2e-3;
  const Eigen::Vector3d centre(25e-3, 25e-3, top - ap);
  for (double rc : {5e-3, 8e-3, 15e-3}) {
    SCOPED_TRACE(rc);
    const double ae = 2e-3;
    DexelStock stock({Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(50e-3, 50e-3, top)}, resolution);
    Program program;
    auto circle = [&](double r, int line) {
      const Eigen::Vector3d start = centre + Eigen::Vector3d(r, 0, 0);
      ArcResult arc = arc_from_centre(start, start, centre, Eigen::Vector3d::UnitZ(), false);
      EXPECT_EQ(arc.problem, ArcProblem::none);
      arc.move.feed_m_s = kFeed;
      arc.move.spindle_rad_s = kSpindle;
      arc.move.line = line;
      return arc.move;
    };
    program.moves.push_back(line_move(centre, centre, kFeed, kSpindle, MotionKind::rapid, 1));
    // The previous pass: everything inside rc − ae + R cleared (discs of the
    // tool along radii, then the circle of radius rc − ae).
    for (double r = 0.0; r < rc - ae; r += 0.5 * radius) {
      const Eigen::Vector3d a = centre + Eigen::Vector3d(r, 0, 0);
      program.moves.push_back(
          line_move(program.moves.back().end_m, a, kFeed, kSpindle, MotionKind::linear, 2));
      if (r > 0.0) {
        Move ring = circle(r, 2);
        program.moves.push_back(ring);
      }
    }
    const Eigen::Vector3d previous = centre + Eigen::Vector3d(rc - ae, 0, 0);
    program.moves.push_back(
        line_move(program.moves.back().end_m, previous, kFeed, kSpindle, MotionKind::linear, 2));
    if (rc - ae > 0.0)
      program.moves.push_back(circle(rc - ae, 2));
    // This pass: out to rc, then the full turn (line 3).
    program.moves.push_back(line_move(previous, centre + Eigen::Vector3d(rc, 0, 0), kFeed, kSpindle,
                                      MotionKind::linear, 2));
    program.moves.push_back(circle(rc, 3));
    const ProgramRun result = run(program, cutter, stock);

    const double cos_limit =
        ((rc + radius - ae) * (rc + radius - ae) - rc * rc - radius * radius) / (2.0 * rc * radius);
    const double expected = std::acos(std::clamp(cos_limit, -1.0, 1.0));
    const EngagementGrid grid = default_engagement_grid(cutter_shape(cutter), resolution);
    const double tolerance = kPi / grid.angle_steps + resolution / (radius * std::sin(expected));
    int checked = 0;
    for (const PathSample& s : result.samples) {
      if (s.line != 3)
        continue;
      // The middle of the turn: from a quarter to three quarters.
      const Eigen::Vector3d d = s.tip_m - centre;
      const double angle = std::atan2(d.y(), d.x());
      if (angle < 0.5 * kPi - 0.6 || angle > 0.5 * kPi + 2.0)
        continue;
      ++checked;
      EXPECT_NEAR(s.engaged_rad, expected, tolerance) << "at " << angle / kDeg << " deg";
      EXPECT_NEAR(s.axial_depth_m, ap, 1e-9);
    }
    EXPECT_GT(checked, 10);
  }
}

// A helical ramp into a bore: the tool centre on a helix of radius rh < R
// descending a pitch p per turn. Once a full turn is done, the material
// under the front of the tool is the layer the previous turn left: the axial
// depth of cut is the pitch, within one slice height.
TEST(ProgramAnalysis, HelicalRampCutsItsPitchPerTurn) {
  const tool::Tool cutter = flat_tool();
  const double resolution = 0.1e-3, top = 10e-3, pitch = 0.5e-3, rh = 3e-3;
  DexelStock stock({Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(30e-3, 30e-3, top)}, resolution);
  const Eigen::Vector3d axis_point(15e-3, 15e-3, top);
  const Eigen::Vector3d start = axis_point + Eigen::Vector3d(rh, 0, 0);
  Program program;
  program.moves.push_back(line_move(start, start, kFeed, kSpindle, MotionKind::rapid, 1));
  ArcResult helix = arc_from_centre(start, start - Eigen::Vector3d(0, 0, 3 * pitch), axis_point,
                                    Eigen::Vector3d::UnitZ(), false, 2);
  ASSERT_EQ(helix.problem, ArcProblem::none);
  helix.move.feed_m_s = kFeed;
  helix.move.spindle_rad_s = kSpindle;
  helix.move.line = 2;
  program.moves.push_back(helix.move);
  ASSERT_NEAR(std::abs(helix.move.sweep_rad), 3 * 2 * kPi, 1e-9);
  const ProgramRun result = run(program, cutter, stock);
  const EngagementGrid grid = default_engagement_grid(cutter_shape(cutter), resolution);
  int checked = 0;
  for (const PathSample& s : result.samples) {
    if (s.line != 2 || s.tip_m.z() > top - 1.2 * pitch)  // after the first turn
      continue;
    ++checked;
    // ap is measured from the tip to where the material ends along the axis
    // at the middle of the top slice's arcs (issue 31). The ramp's top is not
    // flat: an arc beside the bore's wall reads the material on up to a cell
    // above the next slice's test height, which found none (measured: up to
    // 0.72 mm on this 0.5 mm pitch): within a slice and a dexel cell.
    EXPECT_NEAR(s.axial_depth_m, pitch, grid.slice_height_m + resolution + 1e-9)
        << "z = " << s.tip_m.z();
  }
  EXPECT_GT(checked, 10);
}

// The same pocket written in G-code, APT and KRL gives the same samples and
// forces: the programs' feed moves resample identically (equal spacing), so
// sample by sample the positions agree to the readers' rounding and the
// forces to the engagement's.
TEST(ProgramAnalysis, SamePocketInThreeDialectsGivesTheSameSamples) {
  auto read = [](const std::filesystem::path& file) {
    std::ifstream stream(file);
    std::stringstream text;
    text << stream.rdbuf();
    return text.str();
  };
  const Program gcode = io::read_gcode(read(kSource / "tests/toolpath/programs/pocket.nc"), {});
  const Program apt = io::read_apt(read(kSource / "tests/toolpath/programs/pocket.cl"), {});
  io::KrlOptions krl_options;
  krl_options.dat_text = read(kSource / "examples/programs/pocket.dat");
  const Program krl = io::read_krl(read(kSource / "examples/programs/pocket.src"), krl_options);

  ProgramAnalysisSettings settings;
  settings.sample_spacing_m = 0.5e-3;
  settings.default_spindle_rad_s = kSpindle;  // KRL carries no S
  auto feed_samples = [&](const Program& program) {
    DexelStock stock({Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(60e-3, 40e-3, 20e-3)}, 0.25e-3);
    std::vector<PathSample> kept;
    for (const PathSample& s : run(program, flat_tool(), stock, settings).samples)
      if (s.kind == MotionKind::linear && s.engaged_rad > 0.0)
        kept.push_back(s);
    return kept;
  };
  const std::vector<PathSample> reference = feed_samples(gcode);
  ASSERT_GT(reference.size(), 100u);
  for (const auto& [name, program] :
       std::vector<std::pair<std::string, const Program*>>{{"apt", &apt}, {"krl", &krl}}) {
    SCOPED_TRACE(name);
    const std::vector<PathSample> other = feed_samples(*program);
    ASSERT_EQ(other.size(), reference.size());
    for (std::size_t i = 0; i < reference.size(); ++i) {
      ASSERT_LT((other[i].tip_m - reference[i].tip_m).norm(), 1e-9) << i;
      EXPECT_NEAR(other[i].feed_m_s, reference[i].feed_m_s, 1e-9);
      EXPECT_NEAR(other[i].engaged_rad, reference[i].engaged_rad, 1e-9);
      EXPECT_NEAR(other[i].force_peak_n, reference[i].force_peak_n,
                  1e-6 * reference[i].force_peak_n + 1e-9);
    }
  }
}

}  // namespace
}  // namespace test_program_analysis_cpp
}  // namespace robomill::toolpath
