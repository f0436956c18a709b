// Z-map surface topography (001 §2.1-2.4): closed-form limits and invariants.

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "robomill/surface/roughness.hpp"
#include "robomill/surface/topography.hpp"

namespace test_zmap_cpp {

namespace {

using namespace robomill;
constexpr double kPi = std::numbers::pi;

tool::Tool ball_tool(double runout_m = 0.0, int teeth = 2) {
  tool::ToolSpec spec;
  spec.type = tool::ToolType::ball;
  spec.diameter_m = 8e-3;
  spec.teeth = teeth;
  spec.helix_rad = 45.0 * kPi / 180.0;
  spec.overhang_m = 25e-3;
  spec.runout.offset_m = runout_m;
  return tool::Tool(spec);
}

surface::RasterPath raster(double fz, double stepover, int passes, double first_y, double x0,
                           double x1) {
  surface::RasterPath path;
  path.spindle_rad_s = 6000.0 * 2.0 * kPi / 60.0;
  path.feed_per_tooth_m = fz;
  path.stepover_m = stepover;
  path.passes = passes;
  path.first_pass_y_m = first_y;
  path.x_start_m = x0;
  path.x_end_m = x1;
  return path;
}

surface::ZMapGrid grid(double lx, double ly, int nx, int ny) {
  surface::ZMapGrid g;
  g.length_x_m = lx;
  g.length_y_m = ly;
  g.cells_x = nx;
  g.cells_y = ny;
  return g;
}

double amplitude_at(const std::vector<double>& line, int count, int k) {
  std::complex<double> sum = 0.0;
  for (int i = 0; i < count; ++i)
    sum += line[static_cast<std::size_t>(i)] * std::polar(1.0, -2.0 * kPi * k * i / count);
  return 2.0 * std::abs(sum) / count;
}

TEST(SurfaceZMap, ScallopHeightBetweenPassesMatchesTheBallEndFormula) {
  const tool::Tool cutter = ball_tool();
  const double s = 0.5e-3;
  // Passes at y = -0.5, 0, 0.5, 1.0, 1.5 mm over a 1 mm x 1 mm patch.
  const auto path = raster(0.05e-3, s, 5, -0.5e-3, -1e-3, 2e-3);
  const auto g = grid(1e-3, 1e-3, 100, 100);
  const auto result = surface::cut_zmap(cutter, 0.5e-3, {}, path, g, {}, {});
  const auto r = surface::roughness(result.map);
  const double expected = surface::scallop_height(4e-3, s);
  EXPECT_NEAR(expected, 4e-3 - std::sqrt(16e-6 - 0.0625e-6), 1e-15);
  EXPECT_NEAR(r.max_residual_m, expected, 0.02 * expected);
  EXPECT_NEAR(r.stepover.rz_m, expected, 0.02 * expected);
  // Every node was cut: nothing is left at the stock top.
  for (double z : result.map.z_m)
    ASSERT_LT(z, 0.5e-3);
  std::printf("[surface] scallop: analytic %.4f um, Z-map max %.4f um (%.2f %%), mean %.4f um\n",
              expected * 1e6, r.max_residual_m * 1e6,
              100.0 * (r.max_residual_m - expected) / expected, r.stepover.rz_m * 1e6);
}

TEST(SurfaceZMap, FeedMarksOfALeadingBallEndMatchTheirAnalyticHeight) {
  // A vertical ball end cuts the centre line of its pass with the tip, whose
  // speed is zero: no feed marks there. With a lead angle the lowest point of
  // the ball is R sin(lead) off the axis and each tooth sweeps it once per
  // revolution with its edge lying along the feed (the meridian in the x-z
  // plane): the centre line of the pass holds arcs of radius R every fz,
  // of height R - sqrt(R^2 - (fz/2)^2).
  const tool::Tool cutter = ball_tool();
  surface::ToolOrientation o;
  o.lead_rad = 10.0 * kPi / 180.0;
  const double fz = 0.2e-3;
  const auto path = raster(fz, 0.1e-3, 1, 0.1e-3, -1e-3, 2e-3);
  const auto g = grid(1e-3, 0.2e-3, 100, 20);
  const auto result = surface::cut_zmap(cutter, 0.5e-3, o, path, g, {}, {});
  const auto line = surface::feed_line(result.map, 10);  // y = 0.1 mm, the pass's centre
  const auto [lo, hi] = std::minmax_element(line.begin(), line.end());
  const double expected = surface::scallop_height(4e-3, fz);
  // Node by node: a tooth is at the lowest point (azimuth +x of the spindle
  // frame, at κ = lead) when Ω t - ψ(lead) = π/2 (mod π): arc centres at
  // x_start + v_f t, every fz.
  const double lag = std::tan(cutter.helix_rad()) * (1.0 - std::cos(o.lead_rad));
  const double per_radian = 2.0 * fz / (2.0 * kPi);  // feed per radian of spindle turn
  double worst = 0.0, sampled_hi = 0.0;
  for (int i = 0; i <= 100; ++i) {
    const double x = i * 1e-5;
    double z = 1.0;
    for (int k = 0; k < 40; ++k) {
      const double centre = path.x_start_m + per_radian * (0.5 * kPi + lag + kPi * k);
      const double d = x - centre;
      if (std::abs(d) < 4e-3)
        z = std::min(z, 4e-3 - std::sqrt(16e-6 - d * d));
    }
    sampled_hi = std::max(sampled_hi, z);
    worst = std::max(worst, std::abs(z - line[static_cast<std::size_t>(i)]));
  }
  EXPECT_LT(worst, 0.02 * expected);
  EXPECT_NEAR(*hi - *lo, sampled_hi, 0.02 * expected);
  EXPECT_NEAR(*lo, 0.0, 0.02 * expected);  // the arcs' bottoms touch the nominal plane
  EXPECT_GT(*hi - *lo, 0.9 * expected);    // the grid misses the cusps by < dx/2
  std::printf(
      "[surface] feed marks: analytic %.4f um (%.4f um at the nodes), Z-map %.4f um, "
      "largest node error %.4f um (%.2f %% of the mark)\n",
      expected * 1e6, sampled_hi * 1e6, (*hi - *lo) * 1e6, worst * 1e6, 100.0 * worst / expected);
}

TEST(SurfaceZMap, RunoutMakesTheFeedMarksPeriodicOncePerRevolution) {
  const double fz = 0.1e-3;  // 0.2 mm per revolution: 5 periods over 1 mm
  const auto path = raster(fz, 0.1e-3, 1, 0.1e-3, -1e-3, 2e-3);
  const auto g = grid(1e-3, 0.2e-3, 100, 20);
  surface::ToolOrientation o;
  o.lead_rad = 10.0 * kPi / 180.0;
  double per_tooth[2], per_revolution[2];
  for (int with = 0; with < 2; ++with) {
    const tool::Tool cutter = ball_tool(with ? 0.02e-3 : 0.0);
    const auto result = surface::cut_zmap(cutter, 0.5e-3, o, path, g, {}, {});
    const auto line = surface::feed_line(result.map, 10);
    per_revolution[with] = amplitude_at(line, 100, 5);
    per_tooth[with] = amplitude_at(line, 100, 10);
  }
  EXPECT_LT(per_revolution[0], 0.02 * per_tooth[0]);
  EXPECT_GT(per_revolution[1], per_tooth[1]);
  std::printf(
      "[surface] feed-line spectrum (um): no runout: rev %.4f tooth %.4f; runout 20 um: "
      "rev %.4f tooth %.4f\n",
      per_revolution[0] * 1e6, per_tooth[0] * 1e6, per_revolution[1] * 1e6, per_tooth[1] * 1e6);
}

TEST(SurfaceZMap, HeightBudgetOnlySavesWork) {
  const tool::Tool cutter = ball_tool(0.02e-3);
  surface::ToolOrientation o;
  o.lead_rad = 10.0 * kPi / 180.0;
  o.tilt_rad = 5.0 * kPi / 180.0;
  o.redundancy_rad = 20.0 * kPi / 180.0;
  const auto path = raster(0.025e-3, 0.1e-3, 14, -0.3e-3, -0.8e-3, 1.3e-3);
  const auto g = grid(0.5e-3, 0.5e-3, 100, 100);
  surface::ZMapOptions automatic;
  surface::ZMapOptions generous;
  generous.height_budget_m = 50e-6;
  generous.steps_per_revolution =
      surface::resolution_rules(cutter, 0.5e-3, o, path, g, 50e-6).min_steps_per_revolution;
  automatic.steps_per_revolution = generous.steps_per_revolution;
  const auto a = surface::cut_zmap(cutter, 0.5e-3, o, path, g, {}, automatic);
  const auto b = surface::cut_zmap(cutter, 0.5e-3, o, path, g, {}, generous);
  double largest = 0.0;
  for (std::size_t n = 0; n < a.map.z_m.size(); ++n)
    largest = std::max(largest, std::abs(a.map.z_m[n] - b.map.z_m[n]));
  // The same surface to 1 nm (the edge samples shift with the band's start).
  EXPECT_LT(largest, 1e-9);
  EXPECT_LT(a.stats.point_evaluations, b.stats.point_evaluations);
}

TEST(SurfaceZMap, ThreadCountDoesNotChangeTheSurface) {
  const tool::Tool cutter = ball_tool(0.02e-3);
  surface::ToolOrientation o;
  o.lead_rad = 10.0 * kPi / 180.0;
  const auto path = raster(0.025e-3, 0.1e-3, 14, -0.3e-3, -0.8e-3, 1.3e-3);
  const auto g = grid(0.5e-3, 0.5e-3, 100, 100);
  surface::ZMapOptions one, four, strips;
  one.threads = 1;
  four.threads = 4;  // passes shared out, private grids merged by min
  strips.threads = 4;
  strips.private_grid_bytes = 0.0;  // column strips
  const auto a = surface::cut_zmap(cutter, 0.5e-3, o, path, g, {}, one);
  const auto b = surface::cut_zmap(cutter, 0.5e-3, o, path, g, {}, four);
  const auto c = surface::cut_zmap(cutter, 0.5e-3, o, path, g, {}, strips);
  EXPECT_EQ(a.map.z_m, b.map.z_m);
  EXPECT_EQ(a.map.z_m, c.map.z_m);
}

TEST(SurfaceZMap, VibrationRaisesRoughnessAndBreaksThePeriodicity) {
  const tool::Tool cutter = ball_tool();
  surface::ToolOrientation o;
  o.lead_rad = 10.0 * kPi / 180.0;
  o.tilt_rad = 5.0 * kPi / 180.0;
  const auto path = raster(0.025e-3, 0.1e-3, 16, -0.3e-3, -0.6e-3, 1.6e-3);
  const auto g = grid(1e-3, 1e-3, 200, 200);
  surface::Vibration vibration;
  vibration.step_s = 1e-4;
  for (int k = 0; k < 20000; ++k) {
    const double t = k * vibration.step_s;
    vibration.displacement_m.emplace_back(1e-6 * std::sin(2 * kPi * 18.0 * t),
                                          0.5e-6 * std::sin(2 * kPi * 23.0 * t + 1.0),
                                          1.5e-6 * std::sin(2 * kPi * 18.0 * t + 0.3));
  }
  const auto still_map = surface::cut_zmap(cutter, 0.5e-3, o, path, g, {}, {}).map;
  const auto shaken_map = surface::cut_zmap(cutter, 0.5e-3, o, path, g, vibration, {}).map;
  const auto still = surface::roughness(still_map);
  const auto shaken = surface::roughness(shaken_map);
  EXPECT_GT(shaken.sa_m, 2.0 * still.sa_m);
  EXPECT_GT(shaken.stepover.ra_m, still.stepover.ra_m);
  EXPECT_GT(shaken.max_residual_m, still.max_residual_m);
  // Periodicity along the feed: the share of the feed line's variance at
  // the harmonics of the feed per revolution (0.05 mm = 10 cells, 20
  // periods over the 200 cells), averaged over the lines.
  auto harmonic_share = [](const surface::ZMap& map) {
    double share = 0.0;
    for (int j = 0; j < map.grid.nodes_y(); ++j) {
      auto line = surface::feed_line(map, j);
      line.pop_back();  // 200 samples, whole periods
      double mean = 0.0;
      for (double z : line)
        mean += z / 200.0;
      for (double& z : line)
        z -= mean;
      double total = 0.0, harmonic = 0.0;
      for (int k = 1; k <= 100; ++k) {
        const double a = amplitude_at(line, 200, k);
        total += a * a;
        if (k % 20 == 0)
          harmonic += a * a;
      }
      share += (total > 0.0 ? harmonic / total : 1.0) / map.grid.nodes_y();
    }
    return share;
  };
  const double periodic_still = harmonic_share(still_map);
  const double periodic_shaken = harmonic_share(shaken_map);
  EXPECT_GT(periodic_still, 0.9);
  EXPECT_LT(periodic_shaken, 0.5 * periodic_still);
  std::printf(
      "[surface] vibration: Sa %.4f -> %.4f um, max residual %.4f -> %.4f um, share of "
      "the feed lines at the per-revolution harmonics %.3f -> %.3f\n",
      still.sa_m * 1e6, shaken.sa_m * 1e6, still.max_residual_m * 1e6, shaken.max_residual_m * 1e6,
      periodic_still, periodic_shaken);
}

// A vibration locked to the spindle (here 3 um along z at the tooth
// frequency and its harmonic) moves every tooth's imprint the same way, so
// the surface is the kinematic one, shifted: Sa barely changes, the texture
// interval stays the feed per tooth. The same vibration at half the
// revolution frequency (a period doubling) lowers every second revolution:
// the texture interval becomes two revolutions' feed, 4 fz on two teeth —
// 001 §3.3's "texture interval roughly four times larger" with vibration.
TEST(SurfaceZMap, VibrationLockedToTheSpindlePrintsLikeTheKinematicSurface) {
  const tool::Tool cutter = ball_tool();
  surface::ToolOrientation o;
  o.lead_rad = 10.0 * kPi / 180.0;
  o.tilt_rad = 5.0 * kPi / 180.0;
  const double fz = 0.025e-3;
  const auto path = raster(fz, 0.1e-3, 16, -0.3e-3, -0.6e-3, 1.6e-3);
  const auto g = grid(1e-3, 1e-3, 200, 200);
  const double spindle_hz = path.spindle_rad_s / (2.0 * kPi);
  auto shaken = [&](double frequency_hz) {
    surface::Vibration vibration;
    vibration.step_s = 2e-5;
    for (int k = 0; k < 100000; ++k) {
      const double t = k * vibration.step_s;
      vibration.displacement_m.emplace_back(0.0, 0.0,
                                            3e-6 * std::sin(2 * kPi * frequency_hz * t) +
                                                1e-6 * std::sin(4 * kPi * frequency_hz * t + 0.5));
    }
    return surface::roughness(surface::cut_zmap(cutter, 0.5e-3, o, path, g, vibration, {}).map);
  };
  const auto still = surface::roughness(surface::cut_zmap(cutter, 0.5e-3, o, path, g, {}, {}).map);
  const auto locked = shaken(2.0 * spindle_hz);  // the tooth frequency
  const auto doubled = shaken(0.5 * spindle_hz);
  EXPECT_NEAR(locked.sa_m, still.sa_m, 0.15 * still.sa_m);
  EXPECT_NEAR(still.feed_texture_interval_m, fz, 0.02 * fz);
  EXPECT_NEAR(locked.feed_texture_interval_m, fz, 0.02 * fz);
  EXPECT_NEAR(doubled.feed_texture_interval_m, 4.0 * fz, 0.02 * 4.0 * fz);
  EXPECT_GT(doubled.feed.ra_m, 3.0 * still.feed.ra_m);
  std::printf(
      "[surface] z vibration 3 um: Sa still %.4f, locked to the teeth %.4f, at half the "
      "revolution frequency %.4f um; texture interval %.4f, %.4f, %.4f mm (fz %.4f mm)\n",
      still.sa_m * 1e6, locked.sa_m * 1e6, doubled.sa_m * 1e6, still.feed_texture_interval_m * 1e3,
      locked.feed_texture_interval_m * 1e3, doubled.feed_texture_interval_m * 1e3, fz * 1e3);
}

TEST(SurfaceZMap, ResolutionRulesFollowEq29And30) {
  const tool::Tool cutter = ball_tool();
  const auto path = raster(0.025e-3, 0.1e-3, 1, 0.0, 0.0, 1e-3);
  const auto g = grid(2e-3, 2e-3, 100, 100);
  const auto rules = surface::resolution_rules(cutter, 0.5e-3, {}, path, g, 0.0);
  EXPECT_NEAR(rules.max_cell_m, 0.005e-3, 1e-12);  // min(fz, fp) / 5
  // Eq 30: a step moves the outermost evaluated edge point at most one cell.
  const double dt = 2 * kPi / (path.spindle_rad_s * rules.min_steps_per_revolution);
  EXPECT_LE(path.spindle_rad_s * rules.max_edge_radius_m * dt, 0.02e-3 * (1 + 1e-9));
  surface::ZMapOptions coarse;
  coarse.steps_per_revolution = rules.min_steps_per_revolution - 1;
  EXPECT_THROW(surface::cut_zmap(cutter, 0.5e-3, {}, path, g, {}, coarse), std::invalid_argument);
}

TEST(SurfaceZMap, EdgePointChainPutsTheBallBottomOnTheContactPoint) {
  const tool::Tool cutter = ball_tool();
  surface::ToolOrientation o;
  o.lead_rad = 10.0 * kPi / 180.0;
  const auto path = raster(0.025e-3, 0.1e-3, 3, 0.0, 0.0, 1e-3);
  // Every point of the ball lies R from the centre (x_start, y_pass, R).
  for (double kappa : {0.0, 0.3, 1.0, 1.5}) {
    const Eigen::Vector3d p = surface::edge_point(cutter, o, path, 0, 1, kappa, 0.0);
    const Eigen::Vector3d centre(0.0, 0.0, 4e-3);
    EXPECT_NEAR((p - centre).norm(), 4e-3, 1e-12);
  }
  // The tip (κ = 0) of a tool leaning 10° towards the feed is R (1 - cos 10°)
  // above the plane, behind the contact point.
  const Eigen::Vector3d tip = surface::edge_point(cutter, o, path, 0, 0, 0.0, 0.0);
  EXPECT_NEAR(tip.z(), 4e-3 * (1 - std::cos(o.lead_rad)), 1e-12);
  EXPECT_NEAR(tip.x(), -4e-3 * std::sin(o.lead_rad), 1e-12);
  EXPECT_NEAR(surface::shank_clearance_m(cutter, o), 4e-3 * (1 - std::sin(o.lead_rad)), 1e-12);
}

TEST(SurfaceRoughness, ProfileParametersOfASineAndARamp) {
  std::vector<double> z;
  for (int i = 0; i < 20000; ++i)
    z.push_back(1e-6 * std::sin(2 * kPi * i / 100.0) + 1e-3 * i);  // plus a tilt, removed
  const auto r = surface::profile_roughness(z);
  EXPECT_NEAR(r.ra_m, 2e-6 / kPi, 0.01e-6);
  EXPECT_NEAR(r.rq_m, 1e-6 / std::sqrt(2.0), 0.01e-6);
  EXPECT_NEAR(r.rz_m, 2e-6, 0.01e-6);
}

}  // namespace

namespace {

TEST(SurfaceZMap, VerticalFlatEndLeavesThePlane) {
  tool::ToolSpec spec;
  spec.type = tool::ToolType::flat;
  spec.diameter_m = 6e-3;
  spec.teeth = 3;
  spec.helix_rad = 30.0 * kPi / 180.0;
  spec.overhang_m = 30e-3;
  const tool::Tool cutter(spec);
  const auto path = raster(0.2e-3, 2e-3, 1, 0.5e-3, -3.1e-3, 4.1e-3);
  const auto g = grid(1e-3, 1e-3, 25, 25);
  const auto result = surface::cut_zmap(cutter, 0.5e-3, {}, path, g, {}, {});
  for (double z : result.map.z_m)
    ASSERT_NEAR(z, 0.0, 1e-12);
}

TEST(SurfaceZMap, ZigzagLeavesTheSameScallops) {
  const tool::Tool cutter = ball_tool();
  auto path = raster(0.05e-3, 0.5e-3, 5, -0.5e-3, -1e-3, 2e-3);
  const auto g = grid(1e-3, 1e-3, 100, 100);
  const auto one_way =
      surface::roughness(surface::cut_zmap(cutter, 0.5e-3, {}, path, g, {}, {}).map);
  path.pattern = surface::RasterPattern::zigzag;
  const auto zigzag =
      surface::roughness(surface::cut_zmap(cutter, 0.5e-3, {}, path, g, {}, {}).map);
  const double expected = surface::scallop_height(4e-3, 0.5e-3);
  EXPECT_NEAR(zigzag.max_residual_m, expected, 0.02 * expected);
  EXPECT_NEAR(zigzag.stepover.ra_m, one_way.stepover.ra_m, 0.02 * one_way.stepover.ra_m);
}

}  // namespace

}  // namespace test_zmap_cpp
