// Measured dynamics to stability on the 003 case (issue: "a stability diagram
// computed from the measured FRF directly and from the fitted modes agree
// within 3 % in limiting depth").
//
//   data : FRFs Hxx and Hyy of all nine modes of 003 Tab. 1, 6000 log-spaced
//          points 10 Hz-6 kHz, with complex noise of 0, 1 % and 2 % of |H|
//          (dynamics/frf_noise.hpp); the 2 % set is the bundled
//          examples/data/003_kr270_tab1.uff (seed 3).
//   cut  : examples/003_kr270_measured_frf.yaml — slot, Ktc 1600 MPa,
//          Krc 600 MPa, Ø12 mm two-flute cutter, no process damping.
//   ours : zero-order limits at 100 speeds 1000-6000 rpm (a) from the FRFs
//          directly (linear interpolation between measured points), (b) from
//          the modes fitted to them (LSCF + LSFD), (c) from the exact modes.
//   tolerance: 3 % between (a) and (b) at every speed (the number),
//          for noise up to 1 % — a hammer test averaging four 2 % hits.
//   finding, printed and documented (docs/validation.md): with 2 % noise in
//          every point the direct diagram deviates by up to 3.6 % because
//          ZOA's limit follows the noisy Re G near the tool mode's peak, while the fit averages the
//          noise over the band and stays within 1 % of the exact diagram; the 3 % holds there for
//          the fitted modes, not for the raw 2 %-noise FRF.

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numbers>

#include "robomill/analysis/structure.hpp"
#include "robomill/dynamics/frf_noise.hpp"
#include "robomill/dynamics/measured_receptance.hpp"
#include "robomill/job/job.hpp"
#include "robomill/stability/lobes.hpp"
#include "robomill/stability/zero_order.hpp"
#include "support/validation_record.hpp"

namespace test_measured_dynamics_cpp {

namespace {

using namespace robomill;

struct Differences {
  double direct_vs_fitted = 0.0, direct_vs_exact = 0.0, fitted_vs_exact = 0.0;
};

class MeasuredDynamics : public ::testing::Test {
 protected:
  MeasuredDynamics()
      : job_(job::load_job(std::string(ROBOMILL_SOURCE_DIR) +
                           "/examples/003_kr270_measured_frf.yaml")),
        tool_(*job_.tool),
        speeds_(stability::linear_range(1000.0 * std::numbers::pi / 30.0,
                                        6000.0 * std::numbers::pi / 30.0, 100)) {}

  std::vector<stability::ZeroOrderLimit> modal_limits(const dynamics::ModalModel& modes) const {
    stability::ZeroOrderOptions options;
    options.depth_max_m = job_.stability->depth_max_m;
    const stability::RegenerativeModel model(tool_, *job_.cutting, *job_.process, modes);
    return stability::ZeroOrderSolver(model, options).limits(speeds_);
  }

  /// Worst relative differences between the three diagrams, at every speed.
  Differences compare(const std::vector<dynamics::Frf>& measured) const {
    const dynamics::MeasuredReceptance receptance(measured);
    std::vector<double> grid_rad_s;
    for (const double f : receptance.frequencies_hz())
      grid_rad_s.push_back(2.0 * std::numbers::pi * f);
    const auto direct =
        stability::ZeroOrderSolver(
            stability::mean_cutting_stiffness_per_depth(tool_, *job_.cutting, *job_.process),
            tool_.teeth(), receptance, std::move(grid_rad_s), job_.stability->depth_max_m)
            .limits(speeds_);
    const auto fitted = modal_limits(analysis::fit_structure(job_, measured).modes);
    const auto exact = modal_limits(job::modal_model(job_));
    Differences d;
    for (std::size_t i = 0; i < speeds_.size(); ++i) {
      EXPECT_TRUE(direct[i].limited && fitted[i].limited && exact[i].limited);
      auto worse = [](double& worst, double a, double b) {
        worst = std::max(worst, std::abs(a / b - 1.0));
      };
      worse(d.direct_vs_fitted, direct[i].depth_limit_m, fitted[i].depth_limit_m);
      worse(d.direct_vs_exact, direct[i].depth_limit_m, exact[i].depth_limit_m);
      worse(d.fitted_vs_exact, fitted[i].depth_limit_m, exact[i].depth_limit_m);
    }
    return d;
  }

  std::vector<dynamics::Frf> synthesized(double noise) const {
    std::vector<double> grid(6000);
    for (std::size_t i = 0; i < grid.size(); ++i)
      grid[i] = 10.0 * std::pow(600.0, static_cast<double>(i) / 5999.0);
    const dynamics::ModalModel modes = job::modal_model(job_);
    std::vector<dynamics::Frf> frfs;
    for (int axis = 0; axis < 2; ++axis) {
      frfs.push_back(dynamics::synthesize(modes, axis, axis, grid));
      dynamics::add_relative_noise(frfs.back(), noise, 3 + static_cast<std::uint32_t>(axis));
    }
    return frfs;
  }

  static void print(const char* what, const Differences& d) {
    std::cout << "[validation] 003 slot, 100 speeds, " << what << ": direct FRF vs fitted modes "
              << 100.0 * d.direct_vs_fitted << " %, direct vs exact " << 100.0 * d.direct_vs_exact
              << " %, fitted vs exact " << 100.0 * d.fitted_vs_exact << " % (worst)\n";
  }

  job::Job job_;
  tool::Tool tool_;
  std::vector<double> speeds_;
};

TEST_F(MeasuredDynamics, DirectFrfAndFittedModesAgreeWithin3PercentUpTo1PercentNoise) {
  for (const double noise : {0.0, 0.01}) {
    const Differences d = compare(synthesized(noise));
    print(noise == 0.0 ? "noise-free FRFs" : "1 % noise", d);
    EXPECT_LT(d.direct_vs_fitted, 0.03) << "noise " << noise;
  }
}

TEST_F(MeasuredDynamics, BundledTwoPercentNoiseMeasurementFitsToTheExactDiagram) {
  const Differences d = compare(analysis::load_measured_frfs(job_));
  print("bundled 2 % noise UFF58", d);
  // The fit averages the noise: its diagram stays within 1 % of the exact one.
  EXPECT_LT(d.fitted_vs_exact, 0.01);
}

// 000 Table 2 through the bundled hammer test examples/data/000_kr600_table2.uff
// (tip FRFs of the two tool modes, 2 % noise, 0.5 Hz steps 1-4 kHz): the fit
// must give back fn within 0.5 %, ζ within 10 % and the tip modal mass
// 1/ψ(0)² within 10 % (the tolerances for the 003 fit).
TEST(MeasuredDynamicsPaper000, Table2FromTheBundledHammerTest) {
  const job::Job job =
      job::load_job(std::string(ROBOMILL_SOURCE_DIR) + "/examples/000_kr600_multipoint.yaml");
  const analysis::StructureFit fit =
      analysis::fit_structure(job, analysis::load_measured_frfs(job));
  ASSERT_EQ(fit.modes.size(), 2);
  for (std::size_t i = 0; i < 2; ++i) {
    const job::ModeSpec& truth = job.modes[i];
    const dynamics::Mode& fitted = fit.modes.modes()[i];
    const double mass_kg = 1.0 / fitted.shape.squaredNorm();
    std::cout << "[validation] 000 Table 2 mode " << truth.direction << ": fn "
              << truth.natural_frequency_hz << " -> " << fitted.natural_frequency_hz << " Hz, zeta "
              << 100 * truth.damping_ratio << " -> " << 100 * fitted.damping_ratio
              << " %, tip mass " << truth.mass_kg << " -> " << mass_kg << " kg\n";
    EXPECT_NEAR(fitted.natural_frequency_hz, truth.natural_frequency_hz,
                0.005 * truth.natural_frequency_hz);
    EXPECT_NEAR(fitted.damping_ratio, truth.damping_ratio, 0.10 * truth.damping_ratio);
    EXPECT_NEAR(mass_kg, truth.mass_kg, 0.10 * truth.mass_kg);
    const std::string item = std::string("Tab. 2 mode ") + truth.direction + " (hammer test)";
    const char* assumptions = "synthetic UFF58 from Tab. 2 with 2 % noise, 0.5 Hz steps 1-4 kHz";
    test::record_relative("000", item, "natural frequency (fitted)", "Hz",
                          truth.natural_frequency_hz, fitted.natural_frequency_hz, 0.005,
                          assumptions);
    test::record_relative("000", item, "damping ratio (fitted)", "", truth.damping_ratio,
                          fitted.damping_ratio, 0.10, assumptions);
    test::record_relative("000", item, "tip modal mass 1/psi(0)^2 (fitted)", "kg", truth.mass_kg,
                          mass_kg, 0.10, assumptions);
  }
}

}  // namespace

}  // namespace test_measured_dynamics_cpp
