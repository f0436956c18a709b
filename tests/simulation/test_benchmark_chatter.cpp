// DESIGN.md §5's one-DOF benchmark in the time domain: simulations just
// below and just above the full-discretization boundary (stability/lobes.hpp,
// FDM, 40 steps per tooth period) are judged stable and chatter by
// simulation/response_metrics.hpp, at three spindle speeds; and with the cut
// stable the steady forces are those of cutting/milling_forces.hpp.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "../stability/benchmark_1dof.hpp"
#include "robomill/core/parallel.hpp"
#include "robomill/cutting/milling_forces.hpp"
#include "robomill/simulation/response_metrics.hpp"
#include "robomill/simulation/simulator.hpp"

namespace test_benchmark_chatter_cpp {

namespace {

using namespace robomill;
constexpr double kPi = std::numbers::pi;
// "Just" below and above: 5 % either side of the FDM limit.
constexpr double kBelow = 0.95, kAbove = 1.05;

struct Verdict {
  simulation::ResponseMetrics metrics;
  simulation::SimulationResult result;
};

/// The benchmark (a/D = 0.05, down milling, 2 teeth, 922 Hz) at `depth`,
/// started in the steady cut with the structure at rest.
Verdict simulate_benchmark(double spindle_rad_s, double depth_m, double tooth_periods) {
  const stability::RegenerativeModel model = test::benchmark_1dof(0.05);
  cutting::MillingProcess process = model.process();
  process.spindle_rad_s = spindle_rad_s;
  process.axial_depth_m = depth_m;
  const auto structure = simulation::modal_structure(model.modes());
  simulation::SimulationOptions options;
  options.steps_per_tooth = 60;
  options.duration_s = tooth_periods * 2.0 * kPi / (2.0 * spindle_rad_s);
  Verdict v;
  v.result = simulation::simulate(model.tool(), model.law(), process, structure,
                                  simulation::Workpiece{}, options);
  simulation::ResponseOptions analysis;
  analysis.spindle_rad_s = spindle_rad_s;
  analysis.teeth = 2;
  analysis.steady_window_s = 0.25 * options.duration_s;
  analysis.feed_per_tooth_m = process.feed_per_tooth_m;
  v.metrics = simulation::analyze_response(v.result, analysis);
  return v;
}

TEST(BenchmarkChatter, JustBelowIsStableJustAboveChatters) {
  const stability::RegenerativeModel model = test::benchmark_1dof(0.05);
  const std::vector<double> speeds = {test::rpm(5000.0), test::rpm(7300.0), test::rpm(12000.0)};
  stability::LobeOptions lobes;
  lobes.depth_max_m = 10e-3;
  lobes.depth_tolerance = 1e-4;
  lobes.steps = 40;
  const auto limits = stability::stability_boundary(model, speeds, lobes);
  std::vector<Verdict> below(3), above(3);
  core::parallel_for(6, 0, [&](std::size_t i) {
    const std::size_t s = i / 2;
    const double factor = i % 2 == 0 ? kBelow : kAbove;
    (i % 2 == 0 ? below : above)[s] =
        simulate_benchmark(speeds[s], factor * limits[s].depth_limit_m, 600.0);
  });
  for (std::size_t s = 0; s < 3; ++s) {
    const auto& b = below[s].metrics.chatter;
    const auto& a = above[s].metrics.chatter;
    std::printf(
        "[validation] benchmark a/D 0.05 at %.0f rpm: FDM limit %.4f mm (%s, %.1f Hz); %.2fx: "
        "%s (non-harmonic RMS %.3g um, floor %.3g um; fraction %.3g, spread %.3g); %.2fx: %s at "
        "%.1f Hz (non-harmonic RMS %.3g um, persistence %.3g; fraction %.3g, spread %.3g)\n",
        speeds[s] * 30.0 / kPi, limits[s].depth_limit_m * 1e3, limits[s].bifurcation.c_str(),
        limits[s].chatter_frequency_hz, kBelow, b.chatter ? "chatter" : "stable",
        b.nonharmonic_rms_m * 1e6, b.floor_m * 1e6, b.nonharmonic_fraction, b.sample_spread, kAbove,
        a.chatter ? "chatter" : "stable", a.frequency_hz, a.nonharmonic_rms_m * 1e6, a.persistence,
        a.nonharmonic_fraction, a.sample_spread);
    EXPECT_FALSE(b.chatter) << s;
    EXPECT_TRUE(a.chatter) << s;
  }
}

}  // namespace

namespace {

// With the cut stable the response becomes tooth-periodic, u(t) = u(t − T),
// so the regenerative chip is the static one and the forces are those of the
// rigid force model at the same angles (the foundation's milling_forces).
TEST(BenchmarkChatter, StableSteadyForcesEqualTheForceModel) {
  const stability::RegenerativeModel model = test::benchmark_1dof(0.05);
  const double spindle = test::rpm(7300.0), depth = 1.5e-3;  // 0.43 x the FDM limit
  const Verdict v = simulate_benchmark(spindle, depth, 600.0);
  cutting::MillingProcess process = model.process();
  process.spindle_rad_s = spindle;
  process.axial_depth_m = depth;
  const cutting::MillingForceModel rigid(model.tool(), model.law(), process, 1);
  double peak = 0.0, worst = 0.0;
  const std::size_t last = v.result.size() - 1;
  for (std::size_t i = last - 2 * 60; i <= last; ++i) {  // the last two tooth periods
    const Eigen::Vector3d expected = rigid.at(spindle * v.result.time_s[i]).force_n;
    peak = std::max(peak, expected.norm());
    worst = std::max(worst, (v.result.force_n[i] - expected).norm());
  }
  std::printf(
      "[validation] benchmark stable at 7300 rpm, 1.5 mm: steady forces vs the rigid force "
      "model: max difference %.3g N of peak %.4g N\n",
      worst, peak);
  EXPECT_FALSE(v.metrics.chatter.chatter);
  EXPECT_LT(worst, 1e-4 * peak);
  // The only mode (922 Hz) lies far above half the spindle frequency
  // (61 Hz): no first frequency to report.
  EXPECT_EQ(v.metrics.direction[0].first_frequency_hz, 0.0);
}

}  // namespace

namespace {

// Process damping (000 Eq 19, linear equivalent C = K_sp w² b / (4 V)) in the
// time domain against the same damping in the FDM boundary: at a low speed,
// where it raises the limit well above the plain one, a cut 5 % below the
// process-damped FDM limit is stable with damping and chatters without it,
// and 5 % above that limit it chatters. Assumptions: the simulator applies the
// damping per axial element on the velocity normal to the edge, as the FDM
// model does on the tooth's radial direction (simulation/simulator.hpp); the
// FDM runs with 160 steps per tooth period. At 1500 rpm a tooth period holds
// 18 periods of the 922 Hz mode, and the default 40 steps leave the boundary
// unconverged (plain limit 3.93 mm at 40 steps, 1.86 at 80, 1.70 at 160, 1.66
// at 320; with damping 11.9, 8.61, 8.21, 8.29 mm).
TEST(BenchmarkChatter, ProcessDampingStabilizesAsTheFdmBoundaryPredicts) {
  const stability::RegenerativeModel model = test::benchmark_1dof(0.05);
  const double spindle = test::rpm(1500.0);
  stability::LinearProcessDamping damping;
  damping.indentation_n_per_m3 = 1.5e14;
  damping.wear_land_m = 150e-6;
  damping.friction = 0.0;
  stability::LobeOptions lobes;
  lobes.depth_max_m = 20e-3;
  lobes.depth_tolerance = 1e-3;
  lobes.steps = 160;
  const double plain_m = stability::stability_boundary(model, {spindle}, lobes)[0].depth_limit_m;
  lobes.process_damping = damping;
  const auto damped = stability::stability_boundary(model, {spindle}, lobes)[0];
  ASSERT_TRUE(damped.limited);
  const double damped_m = damped.depth_limit_m;
  ASSERT_GT(damped_m, 1.3 * plain_m) << "the case must separate the two limits";
  ASSERT_GT(kBelow * damped_m, 1.3 * plain_m);

  const double periods = 900.0;
  auto run = [&](double depth_m, bool with_damping) {
    const stability::RegenerativeModel& m = model;
    cutting::MillingProcess process = m.process();
    process.spindle_rad_s = spindle;
    process.axial_depth_m = depth_m;
    simulation::SimulationOptions options;
    options.axial_elements = 1;  // a straight edge (no helix)
    options.duration_s = periods * 2.0 * kPi / (2.0 * spindle);
    const auto structure = simulation::modal_structure(m.modes());
    // The step the damping needs (process_damping_step_limit_s), for both runs.
    const double limit_s =
        simulation::process_damping_step_limit_s(m.tool(), process, structure, damping);
    options.steps_per_tooth = std::max(60, static_cast<int>(std::ceil(kPi / spindle / limit_s)));
    if (with_damping)
      options.process_damping = damping;
    const auto result = simulation::simulate(m.tool(), m.law(), process, structure,
                                             simulation::Workpiece{}, options);
    simulation::ResponseOptions analysis;
    analysis.spindle_rad_s = spindle;
    analysis.teeth = 2;
    analysis.steady_window_s = 0.25 * options.duration_s;
    analysis.feed_per_tooth_m = process.feed_per_tooth_m;
    return simulation::analyze_response(result, analysis).chatter;
  };
  std::vector<simulation::ChatterVerdict> verdicts(3);
  core::parallel_for(3, 0, [&](std::size_t i) {
    verdicts[i] = i == 0   ? run(kBelow * damped_m, true)
                  : i == 1 ? run(kBelow * damped_m, false)
                           : run(kAbove * damped_m, true);
  });
  std::printf(
      "[validation] benchmark at 1500 rpm: FDM limit %.4f mm plain, %.4f mm with process damping; "
      "%.2fx damped limit: %s with damping (non-harmonic RMS %.3g um), %s without; %.2fx: %s\n",
      plain_m * 1e3, damped_m * 1e3, kBelow, verdicts[0].chatter ? "chatter" : "stable",
      verdicts[0].nonharmonic_rms_m * 1e6, verdicts[1].chatter ? "chatter" : "stable", kAbove,
      verdicts[2].chatter ? "chatter" : "stable");
  EXPECT_FALSE(verdicts[0].chatter);
  EXPECT_TRUE(verdicts[1].chatter);
  EXPECT_TRUE(verdicts[2].chatter);
}

}  // namespace

}  // namespace test_benchmark_chatter_cpp
