// Time-domain stability methods (SDM, FDM, FDM2) on the one-DOF benchmark.

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "benchmark_1dof.hpp"
#include "robomill/stability/floquet.hpp"
#include "robomill/stability/lobes.hpp"

namespace test_floquet_cpp {

namespace {

using namespace robomill;
using stability::FloquetMethod;

// A multiplier fixes the chatter frequency only modulo the tooth-passing
// frequency and up to its conjugate: at 535 Hz tooth passing, arg μ = 2π·137/535
// is the vibration at 137, 398, 672, 933, 1207 Hz …; a 922 Hz mode picks 933 Hz,
// which comes from the conjugate (2·535 − 137).
TEST(Floquet, ChatterFrequencyConsidersTheConjugateMultiplier) {
  const dynamics::ModalModel modes({dynamics::directional_mode(0, 922.0, 0.011, 1.34e6)});
  const double tooth_hz = 535.0;
  for (const double sign : {1.0, -1.0}) {
    const auto multiplier = std::polar(1.0, sign * 2.0 * std::numbers::pi * 137.0 / tooth_hz);
    EXPECT_NEAR(stability::chatter_frequency_hz(multiplier, 1.0 / tooth_hz, modes), 933.0, 1e-9);
  }
  // Period doubling: odd multiples of half the tooth-passing frequency.
  EXPECT_NEAR(stability::chatter_frequency_hz({-1.0, 0.0}, 1.0 / 700.0, modes), 1050.0, 1e-9);
}

TEST(Floquet, FreeVibrationDecaysByTheStructuralDamping) {
  // With no cut (depth 0) the multipliers are e^{(−ζ ± i√(1−ζ²)) ωn τ}: the
  // spectral radius is e^{−ζ ωn τ} exactly for every method.
  const auto model = test::benchmark_1dof(1.0);
  const auto samples = model.sample(1.0, 40);
  for (FloquetMethod method : {FloquetMethod::sdm, FloquetMethod::fdm, FloquetMethod::fdm2}) {
    stability::FloquetSolver solver(
        method, {model.modes().natural_rad_s(), model.modes().damping_ratios()}, 40);
    const double delay = 60.0 / (2.0 * 10000.0);
    solver.set_delay(delay);
    const double expected = std::exp(-0.011 * 2.0 * std::numbers::pi * 922.0 * delay);
    EXPECT_NEAR(solver.solve(samples, 0.0).spectral_radius, expected, 1e-9);
  }
}

double limit_mm(FloquetMethod method, int steps, double radial_immersion, double spindle_rpm) {
  const auto model = test::benchmark_1dof(radial_immersion);
  stability::LobeOptions options;
  options.method = method;
  options.steps = steps;
  options.depth_max_m = 10e-3;
  options.depth_tolerance = 1e-5;
  options.coarse_points = 40;
  options.threads = 1;
  return stability::stability_boundary(model, {test::rpm(spindle_rpm)}, options)[0].depth_limit_m *
         1e3;
}

// Judged point of the stability issue: SDM, FDM and FDM2 converge to the same
// boundary as the discretization is refined. Shown by the spread between the
// three methods at m = 40, 80, 160 steps per tooth period: it must shrink to
// under half its m = 40 value and end below 1.2 % of the limit (SDM is first
// order in h, FDM/FDM2 second order, so SDM dominates the remaining spread).
TEST(Floquet, MethodsConvergeToTheSameBoundary) {
  for (double immersion : {1.0, 0.05}) {
    for (double speed : {7000.0, 12000.0, 20000.0}) {
      double spread[3] = {0, 0, 0}, mean = 0.0;
      const int levels[3] = {40, 80, 160};
      for (int level = 0; level < 3; ++level) {
        double low = INFINITY, high = 0.0, sum = 0.0;
        for (FloquetMethod method : {FloquetMethod::sdm, FloquetMethod::fdm, FloquetMethod::fdm2}) {
          const double limit = limit_mm(method, levels[level], immersion, speed);
          low = std::min(low, limit);
          high = std::max(high, limit);
          sum += limit;
          std::cout << "[validation] 1-DOF benchmark a/D " << immersion << ", " << speed << " rpm, "
                    << (method == FloquetMethod::sdm   ? "SDM "
                        : method == FloquetMethod::fdm ? "FDM "
                                                       : "FDM2")
                    << " m = " << levels[level] << ": limit " << limit << " mm\n";
        }
        spread[level] = high - low;
        mean = sum / 3.0;
      }
      EXPECT_LT(spread[2], 0.5 * spread[0]) << "a/D " << immersion << ", " << speed << " rpm";
      EXPECT_LT(spread[2], 0.012 * mean) << "a/D " << immersion << ", " << speed << " rpm";
    }
  }
}

}  // namespace

namespace {

// With a time-invariant coupling p the model is the regenerative turning
// equation η'' + 2ζωη' + ω²η = p (η − η_τ), whose lowest critical |p| over all
// delays is 2 ω² ζ (1 + ζ) (Tlusty: b_lim = 1/(2 K |Re G|min) with
// Re G min = −1/(4kζ(1+ζ)) at ω² = ωn²(1 + 2ζ)); the zero-order approximation
// is exact for such a system, so this checks the time-domain machinery alone.
double critical_coupling(robomill::stability::FloquetMethod method, double delay_s) {
  using namespace robomill::stability;
  const double omega = 2.0 * std::numbers::pi * 922.0, zeta = 0.011;
  const int steps = 60;
  FloquetSolver solver(
      method, {Eigen::VectorXd::Constant(1, omega), Eigen::VectorXd::Constant(1, zeta)}, steps);
  solver.set_delay(delay_s);
  CouplingSamples unit;
  unit.nodes.assign(steps + 1, Eigen::MatrixXd::Constant(1, 1, -1.0));
  unit.means.assign(steps, Eigen::MatrixXd::Constant(1, 1, -1.0));
  double stable = 0.0, unstable = 100.0 * omega * omega * zeta;
  while (unstable - stable > 1e-7 * unstable) {
    const double middle = 0.5 * (stable + unstable);
    (solver.solve(unit, middle).spectral_radius >= 1.0 ? unstable : stable) = middle;
  }
  return unstable;
}

TEST(Floquet, TimeInvariantCouplingReproducesTheTurningLimit) {
  const double omega = 2.0 * std::numbers::pi * 922.0, zeta = 0.011;
  const double expected = 2.0 * omega * omega * zeta * (1.0 + zeta);
  for (auto method :
       {robomill::stability::FloquetMethod::sdm, robomill::stability::FloquetMethod::fdm,
        robomill::stability::FloquetMethod::fdm2}) {
    double lowest = INFINITY;
    // Delays around the 3rd lobe's minimum: τ = (k + 3/4)/f_c with f_c ≈ fn(1+ζ).
    for (double cycles = 2.70; cycles <= 2.80; cycles += 0.0025) {
      lowest = std::min(lowest, critical_coupling(method, cycles / (922.0 * (1.0 + zeta))));
    }
    std::cout << "[validation] turning limit |p|min: ours " << lowest << " 1/s², closed form "
              << expected << " 1/s²\n";
    // 60 steps per tooth period (≈ 22 per vibration period): FDM is within
    // 0.7 %, FDM2 0.9 %, all above the exact value (discretization error).
    EXPECT_NEAR(lowest, expected, 0.015 * expected);
  }
}

}  // namespace

}  // namespace test_floquet_cpp
