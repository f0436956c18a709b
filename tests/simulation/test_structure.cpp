// The exact discretization of simulation/structure.hpp against closed forms.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "robomill/simulation/structure.hpp"

namespace test_structure_cpp {

namespace {

using namespace robomill;
using simulation::discretize;

// A 1-DOF oscillator under a constant force: the step response of
// m ẍ + c ẋ + k x = F is known in closed form; the discretization is exact
// for a held force, so a coarse step (a quarter period) reproduces it to
// round-off — the accuracy does not depend on the step in the linear part.
TEST(Structure, StepResponseIsExactWhateverTheStep) {
  const double m = 2.0, k = 8e4, zeta = 0.03;
  const double wn = std::sqrt(k / m), c = 2.0 * zeta * std::sqrt(k * m);
  const auto s = simulation::fixation_structure(Eigen::MatrixXd::Constant(1, 1, m),
                                                Eigen::MatrixXd::Constant(1, 1, c),
                                                Eigen::MatrixXd::Constant(1, 1, k));
  const double force = 10.0;
  const double wd = wn * std::sqrt(1.0 - zeta * zeta);
  for (const double fraction : {0.25, 0.01}) {
    const double dt = fraction * 2.0 * std::numbers::pi / wn;
    const auto d = discretize(s, dt);
    Eigen::VectorXd z = Eigen::VectorXd::Zero(2);
    const Eigen::Vector3d f(force, 0.0, 0.0);
    for (int n = 1; n <= 40; ++n) {
      z = d.transition * z + d.hold * f;
      const double t = n * dt;
      const double exact =
          force / k *
          (1.0 - std::exp(-zeta * wn * t) * (std::cos(wd * t) + zeta * wn / wd * std::sin(wd * t)));
      ASSERT_NEAR((d.displacement * z)(0), exact, 1e-10 * force / k) << "step " << n;
    }
  }
}

// A force ramp F = F' t is reproduced exactly by the first-order hold.
TEST(Structure, RampResponseIsExactWithTheFirstOrderHold) {
  const double m = 1.0, k = 1e4, c = 4.0;
  const auto s = simulation::fixation_structure(Eigen::MatrixXd::Constant(1, 1, m),
                                                Eigen::MatrixXd::Constant(1, 1, c),
                                                Eigen::MatrixXd::Constant(1, 1, k));
  const double slope = 100.0;  // N/s
  const double dt = 0.01;      // ~1/6 of the period
  const auto d = discretize(s, dt);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(2);
  // Reference: the same ramp integrated with a step 1000 times finer.
  const auto fine = discretize(s, dt / 1000.0);
  Eigen::VectorXd zf = Eigen::VectorXd::Zero(2);
  for (int n = 0; n < 50; ++n) {
    const Eigen::Vector3d f0(slope * n * dt, 0, 0), f1(slope * (n + 1) * dt, 0, 0);
    z = d.transition * z + d.hold * f0 + d.ramp * (f1 - f0);
    for (int i = 0; i < 1000; ++i) {
      const double t = n * dt + i * dt / 1000.0;
      const Eigen::Vector3d g0(slope * t, 0, 0), g1(slope * (t + dt / 1000.0), 0, 0);
      zf = fine.transition * zf + fine.hold * g0 + fine.ramp * (g1 - g0);
    }
    ASSERT_NEAR(z(0), zf(0), 1e-10 * std::abs(zf(0)) + 1e-15) << n;
  }
}

// The modal form and the matrix form of the same system agree, and the
// static compliance is Lᵀ K⁻¹ L.
TEST(Structure, ModalAndMatrixFormsAgree) {
  const double m = 100.0, k = 3e5, zeta = 0.05;
  const double fn = std::sqrt(k / m) / (2.0 * std::numbers::pi);
  const dynamics::ModalModel modes(
      {dynamics::directional_mode(0, fn, zeta, k), dynamics::directional_mode(1, fn, zeta, k)});
  const auto modal = simulation::modal_structure(modes);
  const auto matrix = simulation::fixation_structure(
      m * Eigen::MatrixXd::Identity(2, 2),
      2.0 * zeta * std::sqrt(k * m) * Eigen::MatrixXd::Identity(2, 2),
      k * Eigen::MatrixXd::Identity(2, 2));
  EXPECT_NEAR(simulation::static_compliance(modal)(0, 0), 1.0 / k, 1e-12 / k);
  EXPECT_NEAR(simulation::static_compliance(matrix)(1, 1), 1.0 / k, 1e-12 / k);
  EXPECT_NEAR(simulation::natural_frequencies_hz(matrix)(0), fn, 1e-9 * fn);
  const auto a = discretize(modal, 1e-3), b = discretize(matrix, 1e-3);
  Eigen::VectorXd za = Eigen::VectorXd::Zero(4), zb = Eigen::VectorXd::Zero(4);
  for (int n = 0; n < 200; ++n) {
    const Eigen::Vector3d f(std::sin(0.1 * n) * 50.0, 30.0, 0.0);
    za = a.transition * za + a.hold * f;
    zb = b.transition * zb + b.hold * f;
    ASSERT_TRUE((a.displacement * za - b.displacement * zb).norm() < 1e-12) << n;
  }
}

TEST(Structure, RejectsNonPhysicalFixations) {
  const Eigen::MatrixXd one = Eigen::MatrixXd::Identity(2, 2);
  EXPECT_THROW(simulation::fixation_structure(-one, one, one), std::invalid_argument);
  EXPECT_THROW(simulation::fixation_structure(one, -one, one), std::invalid_argument);
  EXPECT_THROW(simulation::fixation_structure(one, one, Eigen::MatrixXd::Identity(3, 3)),
               std::invalid_argument);
  EXPECT_TRUE(simulation::rigid_structure().rigid());
}

}  // namespace

}  // namespace test_structure_cpp
