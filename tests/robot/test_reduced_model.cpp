// Reduced 6-D elasto-dynamic model at the tool tip (002 §2, Eq 8-23).

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include "robomill/robot/reduced_model.hpp"

namespace test_reduced_model_cpp {

namespace {

using namespace robomill::robot;

struct RandomRobot {
  Eigen::MatrixXd jacobian;
  Eigen::VectorXd kq;
  Eigen::MatrixXd mass;
};

// A random "robot": Jacobian entries in [-1, 1] (m/rad, rad/rad), 000 §6.1-like
// stiffnesses 1e6 … 7e6 N·m/rad, an SPD mass matrix of 1 … 100 kg·m².
RandomRobot random_robot(int rows, int joints, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  RandomRobot robot;
  robot.jacobian = Eigen::MatrixXd::NullaryExpr(rows, joints, [&] { return unit(rng); });
  robot.kq = Eigen::VectorXd::NullaryExpr(joints, [&] { return 4e6 + 3e6 * unit(rng); });
  const Eigen::MatrixXd b = Eigen::MatrixXd::NullaryExpr(joints, joints, [&] { return unit(rng); });
  robot.mass = 10.0 * b * b.transpose() + Eigen::MatrixXd::Identity(joints, joints);
  return robot;
}

std::string describe(const FrequencyComparison& c) {
  std::string text;
  for (Eigen::Index i = 0; i < c.reduced_hz.size(); ++i) {
    char line[128];
    std::snprintf(line, sizeof line, "  mode %ld: reduced %.6f Hz, full %.6f Hz, rel %+.2e\n",
                  static_cast<long>(i + 1), c.reduced_hz[i], c.full_hz[i],
                  c.relative_difference[i]);
    text += line;
  }
  return text;
}

TEST(ReducedModel, ExactWhenSixJointJacobianIsSquare) {
  // n = 6: Jq = Kq⁻¹ Jᵀ Kr = J⁻¹, so (Kr, Mr) = J⁻ᵀ (Kq, M) J⁻¹ — a change of
  // coordinates, and the frequencies of Eq 21 equal those of Eq 5.
  for (unsigned seed : {1u, 2u, 3u, 4u, 5u}) {
    const RandomRobot r = random_robot(6, 6, seed);
    const ReducedModel model = reduce_model(r.jacobian, r.kq, r.mass);
    EXPECT_TRUE((model.deformation_shapes - r.jacobian.inverse()).norm() <
                1e-9 * r.jacobian.inverse().norm());
    const FrequencyComparison c = compare_with_full_model(model, r.kq, r.mass);
    EXPECT_LT(c.max_abs_relative_difference, 1e-9) << "seed " << seed << "\n" << describe(c);
    if (seed == 1u)
      std::printf("n = 6, 6-D (exact):\n%s", describe(c).c_str());
  }
}

TEST(ReducedModel, ExactWhenThreeJointTranslationalJacobianIsSquare) {
  for (unsigned seed : {11u, 12u, 13u}) {
    const RandomRobot r = random_robot(3, 3, seed);
    const ReducedModel model = reduce_model(r.jacobian, r.kq, r.mass);
    const FrequencyComparison c = compare_with_full_model(model, r.kq, r.mass);
    EXPECT_LT(c.max_abs_relative_difference, 1e-9) << "seed " << seed << "\n" << describe(c);
    if (seed == 11u)
      std::printf("n = 3, 3-D (exact):\n%s", describe(c).c_str());
  }
}

// Rayleigh-Ritz on a d-dimensional subspace of the n-dimensional problem: by
// the Courant-Fischer min-max principle (Cauchy interlacing) the i-th reduced
// frequency is at least the i-th full frequency.
void expect_upper_bounds(int rows, int joints, unsigned seed, bool print) {
  const RandomRobot r = random_robot(rows, joints, seed);
  const ReducedModel model = reduce_model(r.jacobian, r.kq, r.mass);
  const FrequencyComparison c = compare_with_full_model(model, r.kq, r.mass);
  ASSERT_EQ(c.reduced_hz.size(), rows);
  for (Eigen::Index i = 0; i < rows; ++i) {
    EXPECT_GE(c.reduced_hz[i], c.full_hz[i] * (1.0 - 1e-12))
        << "mode " << i + 1 << ", seed " << seed << "\n"
        << describe(c);
  }
  if (print)
    std::printf("n = %d, %d-D (upper bound):\n%s", joints, rows, describe(c).c_str());
}

TEST(ReducedModel, SevenJointReducedFrequenciesBoundFullOnesFromAbove) {
  for (unsigned seed = 21; seed < 29; ++seed)
    expect_upper_bounds(6, 7, seed, seed == 21);
}

TEST(ReducedModel, TranslationalReductionOfSixJointsBoundsFullFrequencies) {
  for (unsigned seed = 31; seed < 39; ++seed)
    expect_upper_bounds(3, 6, seed, seed == 31);
  // The same through linear_jacobian of a 6×6 Jacobian.
  const RandomRobot r = random_robot(6, 6, 40);
  const ReducedModel model = reduce_model(linear_jacobian(r.jacobian), r.kq, r.mass);
  const FrequencyComparison c = compare_with_full_model(model, r.kq, r.mass);
  for (Eigen::Index i = 0; i < 3; ++i)
    EXPECT_GE(c.reduced_hz[i], c.full_hz[i] * (1.0 - 1e-12));
}

TEST(ReducedModel, StiffnessIsInverseOfComplianceAndShapesAreStaticDeformations) {
  for (int joints : {6, 7, 9}) {
    const RandomRobot r = random_robot(6, joints, 50u + static_cast<unsigned>(joints));
    const ReducedModel model = reduce_model(r.jacobian, r.kq, r.mass);
    const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(6, 6);
    EXPECT_LT((model.stiffness * model.compliance - identity).norm(), 1e-9);
    EXPECT_LT(
        (model.compliance - r.jacobian * r.kq.cwiseInverse().asDiagonal() * r.jacobian.transpose())
            .norm(),
        1e-12 * model.compliance.norm());
    // J Jq = C Kr = I: a unit tip displacement is produced by its own shape.
    EXPECT_LT((r.jacobian * model.deformation_shapes - identity).norm(), 1e-9);
    // 002 below Eq 9: Jqᵀ Ktot Jq = Kr.
    const Eigen::MatrixXd jq_k_jq =
        model.deformation_shapes.transpose() * r.kq.asDiagonal() * model.deformation_shapes;
    EXPECT_LT((jq_k_jq - model.stiffness).norm(), 1e-9 * model.stiffness.norm());
    // Mass-normalized modes: Φᵀ Mr Φ = I, Φᵀ Kr Φ = diag(ω²).
    const Eigen::MatrixXd& phi = model.mode_shapes;
    EXPECT_LT((phi.transpose() * model.mass * phi - identity).norm(), 1e-9);
    const Eigen::VectorXd omega2 =
        (2.0 * std::numbers::pi * model.natural_frequencies_hz).array().square().matrix();
    EXPECT_LT(
        (phi.transpose() * model.stiffness * phi - Eigen::MatrixXd(omega2.asDiagonal())).norm(),
        1e-9 * omega2.maxCoeff());
  }
}

TEST(ReducedModel, ProportionalJointDampingGivesRayleighDampingRatios) {
  // Dq = α M + β Kq reduces (exactly, n = 6) to α Mr + β Kr: ζ = α/(2ω) + βω/2.
  const RandomRobot r = random_robot(6, 6, 60);
  const double alpha = 2.0;
  const double beta = 1e-5;
  const Eigen::MatrixXd damping = alpha * r.mass + beta * Eigen::MatrixXd(r.kq.asDiagonal());
  const ReducedModel model = reduce_model(r.jacobian, r.kq, r.mass, damping);
  for (Eigen::Index i = 0; i < 6; ++i) {
    const double omega = 2.0 * std::numbers::pi * model.natural_frequencies_hz[i];
    EXPECT_NEAR(model.damping_ratios[i], alpha / (2.0 * omega) + beta * omega / 2.0, 1e-9);
  }
  const ReducedModel undamped = reduce_model(r.jacobian, r.kq, r.mass);
  EXPECT_EQ(undamped.damping.norm(), 0.0);
  EXPECT_EQ(undamped.damping_ratios.norm(), 0.0);
}

TEST(ReducedModel, SingularComplianceIsRefused) {
  // Five joints cannot hold a 6-D tip: C has rank 5.
  const RandomRobot five = random_robot(6, 5, 70);
  try {
    reduce_model(five.jacobian, five.kq, five.mass);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("3-D reduction"), std::string::npos) << e.what();
  }
  // ... but their translational reduction is fine.
  EXPECT_NO_THROW(reduce_model(linear_jacobian(five.jacobian), five.kq, five.mass));
  // A singular posture: two parallel joint columns.
  RandomRobot six = random_robot(6, 6, 71);
  six.jacobian.col(5) = six.jacobian.col(4);
  EXPECT_THROW(reduce_model(six.jacobian, six.kq, six.mass), std::invalid_argument);
  EXPECT_THROW(stiffness_from_compliance(compliance_from_jacobian(six.jacobian, six.kq)),
               std::invalid_argument);
}

TEST(ReducedModel, InvalidInputIsRefused) {
  const RandomRobot r = random_robot(6, 6, 80);
  Eigen::VectorXd kq = r.kq;
  kq[2] = 0.0;
  EXPECT_THROW(reduce_model(r.jacobian, kq, r.mass), std::invalid_argument);
  kq[2] = std::nan("");
  EXPECT_THROW(reduce_model(r.jacobian, kq, r.mass), std::invalid_argument);
  EXPECT_THROW(reduce_model(r.jacobian, r.kq.head(5), r.mass), std::invalid_argument);
  EXPECT_THROW(reduce_model(r.jacobian.topRows(4), r.kq, r.mass), std::invalid_argument);
  EXPECT_THROW(reduce_model(r.jacobian, r.kq, r.mass.topLeftCorner(5, 5)), std::invalid_argument);
  Eigen::MatrixXd asymmetric = r.mass;
  asymmetric(0, 1) += 1.0;
  EXPECT_THROW(reduce_model(r.jacobian, r.kq, asymmetric), std::invalid_argument);
  EXPECT_THROW(reduce_model(r.jacobian, r.kq, -r.mass), std::invalid_argument);
  EXPECT_THROW(linear_jacobian(r.jacobian.topRows(3)), std::invalid_argument);
  Eigen::MatrixXd j = r.jacobian;
  j(1, 1) = INFINITY;
  EXPECT_THROW(reduce_model(j, r.kq, r.mass), std::invalid_argument);
}

}  // namespace

}  // namespace test_reduced_model_cpp
