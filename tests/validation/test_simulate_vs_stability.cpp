// The time-domain simulation's chatter verdict (simulation::simulate +
// simulation::detect_chatter, docs/simulation.md) against the
// frequency-domain boundary of `robomill stability` (stability/lobes.hpp:
// FDM, 40 steps per tooth period, its defaults) — issue 20, point 1.
//
//   grid : two cases, 20 spindle speeds each, at 0.8x and 1.25x the FDM
//          limiting depth of each speed: 40 (speed, depth) points per case.
//          1. DESIGN.md §5's one-DOF benchmark (a/D 0.05, down milling,
//             2 teeth, 922 Hz, ζ 0.011), 5000-24 000 rpm;
//          2. a two-mode robot: 003 Tab. 1's KR270 modes X1 (19.88 Hz,
//             ζ 0.81 %, 3.65e6 N/m, along our y) and Y1 (17.8 Hz, ζ 1.76 %,
//             2.31e6 N/m, along x), as in examples/demo.yaml; 20 mm two-flute
//             end mill, straight flutes, half immersion down milling, 000
//             Eq 39's aluminium coefficients (edge forces included: they force
//             the structure but do not enter the boundary); fz 0.1 mm;
//             300-2200 rpm, where the robot modes set the limit.
//   stability's verdict at a point: the FDM spectral radius ρ at that exact
//          depth (stability_map, the same engine): chatter when ρ > 1. (Above
//          a limit a cut can be stable again, so 1.25x is not assumed
//          unstable.)
//   simulate's verdict: the run `robomill simulate` makes — the cut started
//          at rest in the steady cut, the automatic step (40 steps per tooth
//          period, raised to 8 per period of the highest mode and 12 across
//          the engaged arc), the steady window the last 20 % of the run, fz
//          from the process — over 600 tooth periods. Why 600: the slowest
//          growth at 1.25x in the grids is ρ = 1.0059 per tooth period (robot,
//          800 rpm): 480 periods before the window multiply the start-up
//          transient by 17, and every 1.25x run ends with ≥ 11 µm of
//          non-harmonic vibration, 11 times the floor. The slowest decay at
//          0.8x is ρ = 0.9944 (robot, 800 rpm): over the window's halves
//          (60 periods apart) ρ^60 = 0.72, below the 0.8 persistence gate.
//   acceptance: the verdicts agree at ≥ 95 % of each case's points (the
//          issue's target). Every disagreement is recorded with its reason,
//          found by experiment: a re-run at 8x the steps per tooth (the
//          simulation's step), the Floquet decay or growth over the run
//          (transient too short, growth too slow), the FDM at 160 steps (a
//          lobe flank). Chatter frequencies are printed beside; the
//          frequency check is on two deliberately unstable cuts: within 5 %
//          of stability's chatter frequency at the limit.
//   findings (docs/validation.md): the benchmark agrees at 40 of 40 points,
//          the robot at 38 of 40. Both robot disagreements (800 and 900 rpm,
//          0.8x) are the simulation's step: the half-immersion entry lies on
//          the angular grid and acts as a relay; at 8x the steps, or with the
//          grid shifted by half a step, the runs are stable.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "../stability/benchmark_1dof.hpp"
#include "robomill/core/parallel.hpp"
#include "robomill/simulation/response_metrics.hpp"
#include "robomill/simulation/simulator.hpp"
#include "robomill/stability/lobes.hpp"
#include "simulated_cuts.hpp"
#include "support/validation_record.hpp"

namespace test_simulate_vs_stability_cpp {

namespace {

using namespace robomill;
using test::robot_two_modes;
using test::sig4;
using test::simulate_steps;
constexpr double kPi = std::numbers::pi;
const auto& kRatios = test::kLimitRatios;
constexpr double kToothPeriods = test::kSimulatedToothPeriods;  // run length (see above)
constexpr double kSteadyShare = test::kSteadyWindowShare;
constexpr double kMinAgreement = 0.95;
const char* kSection = "sim";  // the validation report's simulate-vs-stability section

struct Case {
  const char* name;
  stability::RegenerativeModel model;
  std::vector<double> rpm;
  std::string assumptions;
};

simulation::ChatterVerdict simulate_verdict(const stability::RegenerativeModel& model,
                                            double spindle_rad_s, double depth_m, int step_factor,
                                            int* steps_used = nullptr,
                                            double start_step_shift = 0.0) {
  cutting::MillingProcess process = model.process();
  process.spindle_rad_s = spindle_rad_s;
  process.axial_depth_m = depth_m;
  simulation::SimulationOptions options;
  options.steps_per_tooth = step_factor * simulate_steps(model, process);
  options.duration_s = kToothPeriods * 2.0 * kPi / (spindle_rad_s * model.tool().teeth());
  // A shift of the angular grid by a fraction of a step (tooth 1's angle at
  // t = 0): what the entry into the part sees of the grid.
  options.start_angle_rad =
      start_step_shift * 2.0 * kPi / (model.tool().teeth() * options.steps_per_tooth);
  if (steps_used)
    *steps_used = options.steps_per_tooth;
  const auto result = simulation::simulate(model.tool(), model.law(), process,
                                           simulation::modal_structure(model.modes()),
                                           simulation::Workpiece{}, options);
  simulation::ResponseOptions analysis;
  analysis.spindle_rad_s = spindle_rad_s;
  analysis.teeth = model.tool().teeth();
  analysis.steady_window_s = kSteadyShare * options.duration_s;
  analysis.feed_per_tooth_m = process.feed_per_tooth_m;
  return simulation::analyze_response(result, analysis).chatter;
}

struct Point {
  double rpm = 0, ratio = 0, limit_m = 0, depth_m = 0, rho = 0, limit_hz = 0;
  std::string bifurcation;
  int steps = 0;
  simulation::ChatterVerdict sim;
  bool agree = false;
  std::string reason;
};

double spectral_radius(const stability::RegenerativeModel& model, double spindle_rad_s,
                       double depth_m, int steps) {
  stability::LobeOptions options;
  options.steps = steps;
  options.depth_max_m = depth_m;
  options.threads = 1;
  return stability::stability_map(model, {spindle_rad_s}, {depth_m}, options).spectral_radius(0, 0);
}

/// A vibration amplitude for the report, in µm: two significant digits (the
/// last digits of a simulated limit cycle are not worth a stale report),
/// numerical noise as "< 0.001".
std::string um(double metres) {
  const double v = metres * 1e6;
  if (v < 1e-3)
    return "< 0.001 um";
  return (v >= 10.0 ? fmt::format("{:.0f}", v) : fmt::format("{:#.2g}", v)) + " um";
}

/// Why simulate and stability disagree at `p`, found by experiment.
std::string diagnose(const stability::RegenerativeModel& model, const Point& p) {
  const double spindle = test::rpm(p.rpm);
  const double window_periods = kSteadyShare * kToothPeriods;
  const double before_periods = kToothPeriods - window_periods;
  if (p.sim.chatter) {  // stability: stable
    // The simulation's own step: 8x the steps, and the same step with the
    // angular grid shifted by half a step.
    int steps = 0;
    const auto fine = simulate_verdict(model, spindle, p.depth_m, 8, &steps);
    const auto shifted = simulate_verdict(model, spindle, p.depth_m, 1, nullptr, 0.5);
    const auto describe = [](const simulation::ChatterVerdict& v) {
      return fmt::format("{}, non-harmonic {}, persistence {:.2f}",
                         v.chatter ? "chatter" : "stable", um(v.nonharmonic_rms_m), v.persistence);
    };
    if (!fine.chatter || !shifted.chatter)
      return fmt::format(
          "the simulation's step: at {} steps per tooth (8x) {}; at {} steps with the angular "
          "grid shifted by half a step {}. The tooth's entry into the part is placed to a step: "
          "a relay on the vibration (docs/simulation.md, known limitation)",
          steps, describe(fine), p.steps, describe(shifted));
    const double predicted = std::pow(p.rho, 0.5 * window_periods);
    if (predicted >= simulation::ChatterOptions{}.min_persistence)
      return fmt::format("transient too short: rho = {:.4f} decays by only {} over half the window",
                         p.rho, sig4(predicted));
    return fmt::format(
        "sustained at rho = {:.4f} < 1, also at 8x the steps ({}): a nonlinear limit cycle (loss "
        "of contact) beside the stable cut",
        p.rho, describe(fine));
  }
  // stability: chatter, simulate: stable.
  const double growth = std::pow(p.rho, before_periods);
  if (growth < 1e3)
    return fmt::format("growth too slow for the run: rho = {:.4f}, x{} over {} tooth periods",
                       p.rho, sig4(growth), before_periods);
  const double fine_rho = spectral_radius(model, spindle, p.depth_m, 160);
  if (fine_rho < 1.0)
    return fmt::format("lobe flank: the FDM at 160 steps gives rho = {:.4f} (stable)", fine_rho);
  return fmt::format("unexplained: rho = {:.4f} ({:.4f} at 160 steps), non-harmonic {}", p.rho,
                     fine_rho, um(p.sim.nonharmonic_rms_m));
}

std::string stability_text(const Point& p) {
  return p.rho > 1.0 ? fmt::format("chatter (rho {:.4f})", p.rho)
                     : fmt::format("stable (rho {:.4f})", p.rho);
}

std::string simulate_text(const Point& p) {
  return p.sim.chatter ? fmt::format("chatter {} Hz (non-harmonic {})", sig4(p.sim.frequency_hz),
                                     um(p.sim.nonharmonic_rms_m))
                       : fmt::format("stable (non-harmonic {})", um(p.sim.nonharmonic_rms_m));
}

void run_grid(const Case& c) {
  std::vector<double> speeds;
  for (double r : c.rpm)
    speeds.push_back(test::rpm(r));
  // `robomill stability`'s defaults: FDM, 40 steps, relative tolerance 1e-3.
  stability::LobeOptions lobes;
  lobes.depth_max_m = 20e-3;
  const auto limits = stability::stability_boundary(c.model, speeds, lobes);
  std::vector<Point> points(speeds.size() * 2);
  core::parallel_for(points.size(), 0, [&](std::size_t i) {
    const std::size_t s = i / 2;
    Point& p = points[i];
    p.rpm = c.rpm[s];
    p.ratio = kRatios[i % 2];
    p.limit_m = limits[s].depth_limit_m;
    p.limit_hz = limits[s].chatter_frequency_hz;
    p.bifurcation = limits[s].bifurcation;
    p.depth_m = p.ratio * p.limit_m;
    p.rho = spectral_radius(c.model, speeds[s], p.depth_m, lobes.steps);
    p.sim = simulate_verdict(c.model, speeds[s], p.depth_m, 1, &p.steps);
    p.agree = p.sim.chatter == (p.rho > 1.0);
    if (!p.agree)
      p.reason = diagnose(c.model, p);
  });

  int agree = 0, chatter_points = 0, frequency_within = 0;
  double slowest_growth = 1e300, slowest_decay = 0.0;
  for (const auto& limit : limits)
    ASSERT_TRUE(limit.limited) << c.name;
  for (const Point& p : points) {
    agree += p.agree;
    if (p.rho > 1.0)
      slowest_growth = std::min(slowest_growth, p.rho);
    else
      slowest_decay = std::max(slowest_decay, p.rho);
    // The error column: where both chatter, the simulated frequency against
    // the boundary's (printed, not asserted: at 1.25x the limit the limit
    // cycle's frequency may move, or another mode join).
    std::string error = "—";
    if (p.sim.chatter && p.rho > 1.0) {
      ++chatter_points;
      const double deviation = (p.sim.frequency_hz - p.limit_hz) / p.limit_hz;
      frequency_within += std::abs(deviation) <= 0.05;
      error = "f " + test::signed_sig4(test::quantize(100.0 * deviation, 0.1), " %");
    }
    std::printf(
        "[validation] %s %5.0f rpm %.2fx %7.4f mm: stability %s, limit %.4f mm %s %.1f Hz; "
        "simulate %s (%d steps/tooth, floor %.3g um, persistence %.3g)%s%s\n",
        c.name, p.rpm, p.ratio, p.depth_m * 1e3, stability_text(p).c_str(), p.limit_m * 1e3,
        p.bifurcation.c_str(), p.limit_hz, simulate_text(p).c_str(), p.steps, p.sim.floor_m * 1e6,
        p.sim.persistence, p.agree ? "" : " DISAGREE: ", p.reason.c_str());
    test::record_validation(
        {kSection,
         fmt::format("{}, {:.0f} rpm, {}x limit ({} mm; limit {} mm, {} {} Hz)", c.name, p.rpm,
                     sig4(p.ratio), sig4(p.depth_m * 1e3), sig4(p.limit_m * 1e3), p.bifurcation,
                     sig4(p.limit_hz)),
         "chatter verdict", "—", stability_text(p), simulate_text(p), error, "same verdict",
         p.agree, p.agree ? fmt::format("{} steps per tooth", p.steps) : "DISAGREES: " + p.reason});
  }
  const double share = static_cast<double>(agree) / static_cast<double>(points.size());
  std::printf(
      "[validation] %s: simulate and stability agree at %d of %zu points (%.1f %%); "
      "chatter frequency within 5 %% of the boundary's at %d of %d chattering points; "
      "slowest growth rho %.4f (x%.3g before the window), slowest decay rho %.4f (%.3g "
      "over half the window)\n",
      c.name, agree, points.size(), 100.0 * share, frequency_within, chatter_points, slowest_growth,
      std::pow(slowest_growth, (1.0 - kSteadyShare) * kToothPeriods), slowest_decay,
      std::pow(slowest_decay, 0.5 * kSteadyShare * kToothPeriods));
  test::record_check(kSection, fmt::format("{}: all {} points", c.name, points.size()),
                     "verdicts that agree", "points", "≥ 95 %",
                     fmt::format("{} of {} ({} %)", agree, points.size(), sig4(100.0 * share)),
                     "≥ 95 % per case", share >= kMinAgreement, c.assumptions);
  EXPECT_GE(share, kMinAgreement) << c.name;
}

const std::string kRunAssumptions =
    "simulate as the command runs it: from rest in the steady cut, automatic step, 600 tooth "
    "periods, steady window the last 20 %";

TEST(SimulateVsStability, OneDofBenchmarkGrid) {
  Case c{"1-DOF benchmark a/D 0.05", test::benchmark_1dof(0.05), {}, kRunAssumptions};
  for (int i = 0; i < 20; ++i)
    c.rpm.push_back(5000.0 + 1000.0 * i);
  run_grid(c);
}

TEST(SimulateVsStability, TwoModeRobotGrid) {
  Case c{"two-mode robot (003 X1+Y1), half immersion",
         robot_two_modes(),
         {},
         kRunAssumptions + "; edge forces in the simulation only"};
  for (int i = 0; i < 20; ++i)
    c.rpm.push_back(300.0 + 100.0 * i);
  run_grid(c);
}

// Deliberately unstable cuts (1.25x the limit at a Hopf lobe of each case):
// simulate chatters within 5 % of the frequency stability predicts at the
// limit.
TEST(SimulateVsStability, UnstableCutChattersAtThePredictedFrequency) {
  const struct {
    const char* name;
    stability::RegenerativeModel model;
    double rpm;
  } cuts[] = {{"1-DOF benchmark a/D 0.05", test::benchmark_1dof(0.05), 12000.0},
              {"two-mode robot (003 X1+Y1), half immersion", robot_two_modes(), 1000.0}};
  for (const auto& cut : cuts) {
    stability::LobeOptions lobes;
    lobes.depth_max_m = 20e-3;
    const auto limit = stability::stability_boundary(cut.model, {test::rpm(cut.rpm)}, lobes)[0];
    ASSERT_TRUE(limit.limited);
    const auto sim = simulate_verdict(cut.model, test::rpm(cut.rpm), 1.25 * limit.depth_limit_m, 1);
    std::printf(
        "[validation] %s at %.0f rpm, 1.25x the limit (%.4f mm): stability %s at %.2f "
        "Hz, simulate %s at %.2f Hz\n",
        cut.name, cut.rpm, 1.25 * limit.depth_limit_m * 1e3, limit.bifurcation.c_str(),
        limit.chatter_frequency_hz, sim.chatter ? "chatter" : "stable", sim.frequency_hz);
    EXPECT_TRUE(sim.chatter) << cut.name;
    test::record_relative(kSection,
                          fmt::format("{}, {:.0f} rpm, 1.25x limit ({} mm, {})", cut.name, cut.rpm,
                                      sig4(1.25 * limit.depth_limit_m * 1e3), limit.bifurcation),
                          "chatter frequency (simulate vs stability at the limit)", "Hz",
                          limit.chatter_frequency_hz, sim.chatter ? sim.frequency_hz : 0.0, 0.05,
                          "the largest non-harmonic peak of the steady window (bin " +
                              sig4(1.0 / (kSteadyShare * kToothPeriods * 60.0 /
                                          (cut.rpm * cut.model.tool().teeth()))) +
                              " Hz); " + kRunAssumptions);
    EXPECT_NEAR(sim.frequency_hz, limit.chatter_frequency_hz, 0.05 * limit.chatter_frequency_hz)
        << cut.name;
  }
}

}  // namespace

}  // namespace test_simulate_vs_stability_cpp
