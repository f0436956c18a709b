// Joint stiffness identification from tool-tip loading tests (000 §6.1, Eq 3).

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include "expect_invalid.hpp"
#include "robomill/robot/stiffness_identification.hpp"

namespace test_stiffness_identification_cpp {

namespace {

using robomill::test::expect_invalid;

using namespace robomill::robot;
constexpr double kPi = std::numbers::pi;

// 000 §6.1: the KR600's identified joint stiffness, N·m/rad.
const Eigen::VectorXd kTruth =
    (Eigen::VectorXd(6) << 6.082e6, 6.816e6, 3.842e6, 2.926e6, 1.635e6, 2.479e6).finished();

// A 6-R arm of KR600 proportions in standard DH (a, α, d per joint). The load
// is applied, and the displacement measured, at the end of a loading lever
// 0.8 m off the flange axis: a force on the axis could not twist joint 6, and
// the wrist joints' share of the displacement grows with the lever squared.
constexpr double kA[6] = {0.5, 1.3, 0.055, 0.0, 0.0, 0.0};
constexpr double kAlpha[6] = {-kPi / 2, 0.0, -kPi / 2, kPi / 2, -kPi / 2, 0.0};
constexpr double kD[6] = {1.045, 0.0, 0.0, 1.025, 0.0, 0.29};

Eigen::Matrix4d dh(double theta, int i) {
  const double ct = std::cos(theta), st = std::sin(theta);
  const double ca = std::cos(kAlpha[i]), sa = std::sin(kAlpha[i]);
  Eigen::Matrix4d t;
  t << ct, -st * ca, st * sa, kA[i] * ct,  //
      st, ct * ca, -ct * sa, kA[i] * st,   //
      0, sa, ca, kD[i],                    //
      0, 0, 0, 1;
  return t;
}

// Geometric Jacobian (6×6, [linear; angular]) of the tool point, base frame:
// column i = [z_{i-1} × (p − o_{i-1}); z_{i-1}].
Eigen::MatrixXd jacobian(const Eigen::VectorXd& q, const Eigen::Vector3d& tool_in_flange_m,
                         Eigen::Matrix3d* flange_rotation = nullptr) {
  Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
  Eigen::Matrix<double, 3, 6> z, o;
  for (int i = 0; i < 6; ++i) {
    z.col(i) = t.block<3, 1>(0, 2);
    o.col(i) = t.block<3, 1>(0, 3);
    t = t * dh(q[i], i);
  }
  const Eigen::Vector3d p = (t * tool_in_flange_m.homogeneous()).head<3>();
  if (flange_rotation != nullptr)
    *flange_rotation = t.topLeftCorner<3, 3>();
  Eigen::MatrixXd j(6, 6);
  for (int i = 0; i < 6; ++i) {
    j.block<3, 1>(0, i) = z.col(i).cross(p - o.col(i));
    j.block<3, 1>(3, i) = z.col(i);
  }
  return j;
}

// 48 postures inside a KR600's range, rad. With 1 % noise on the whole
// displacement, 12 postures leave the wrist joints' standard errors at 1-4 %;
// 48 bring every one below 0.65 % (printed by the noisy test).
std::vector<Eigen::VectorXd> postures() {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> j1(-1.2, 1.2), j2(-2.0, -0.9), j3(0.3, 1.9), j4(-2.5, 2.5),
      j5(-1.8, -0.4), j6(-3.0, 3.0);
  std::vector<Eigen::VectorXd> list;
  for (int i = 0; i < 48; ++i) {
    list.push_back(
        (Eigen::VectorXd(6) << j1(rng), j2(rng), j3(rng), j4(rng), j5(rng), j6(rng)).finished());
  }
  return list;
}

// 000 Eq 3 forward: Δx = J Kq⁻¹ Jᵀ F (3 linear rows, a tip force), plus
// Gaussian noise of `noise` times each sample's displacement magnitude on
// every component.
std::vector<StiffnessSample> synthesize(const std::vector<Eigen::VectorXd>& qs,
                                        const std::vector<Eigen::Vector3d>& forces_n,
                                        const Eigen::Vector3d& tool_m, double noise,
                                        unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<StiffnessSample> samples;
  for (const auto& q : qs) {
    Eigen::Matrix3d rotation;
    const Eigen::MatrixXd jv = jacobian(q, tool_m, &rotation).topRows(3);
    for (const auto& f_tool : forces_n) {
      const Eigen::Vector3d f = rotation * f_tool;  // forces applied in the flange frame
      StiffnessSample s;
      s.jacobian = jv;
      s.load = f;
      s.displacement_m = jv * kTruth.cwiseInverse().asDiagonal() * jv.transpose() * f;
      const double sigma = noise * s.displacement_m.norm();
      for (Eigen::Index k = 0; k < 3; ++k)
        s.displacement_m[k] += sigma * gauss(rng);
      samples.push_back(std::move(s));
    }
  }
  return samples;
}

const Eigen::Vector3d kTool(0.8, 0.0, 0.3);  // loading point in the flange frame, m
const std::vector<Eigen::Vector3d> kForces{Eigen::Vector3d(800.0, 0.0, 0.0),
                                           Eigen::Vector3d(0.0, 800.0, 0.0),
                                           Eigen::Vector3d(0.0, 0.0, -800.0)};

TEST(StiffnessIdentification, NoiseFreeDataRecoverStiffnessExactly) {
  const auto samples = synthesize(postures(), kForces, kTool, 0.0, 1);
  const StiffnessIdentification id = identify_joint_stiffness(samples);
  for (Eigen::Index j = 0; j < 6; ++j)
    EXPECT_NEAR(id.stiffness_nm_per_rad[j] / kTruth[j], 1.0, 1e-9) << "joint " << j + 1;
  EXPECT_LT(id.rms_residual_m, 1e-15);
  EXPECT_NEAR(id.r_squared, 1.0, 1e-12);
  EXPECT_EQ(id.equations, 432);
  EXPECT_EQ(id.degrees_of_freedom, 426);
  std::printf("noise-free: condition number %.2f, max relative error %.2e\n", id.condition_number,
              (id.stiffness_nm_per_rad.cwiseQuotient(kTruth).array() - 1.0).abs().maxCoeff());
}

TEST(StiffnessIdentification, OnePercentNoiseRecoversEveryJointWithinTwoPercent) {
  const auto samples = synthesize(postures(), kForces, kTool, 0.01, 7);
  const StiffnessIdentification id = identify_joint_stiffness(samples);
  std::printf("1%% noise: condition %.2f, RMS residual %.3e m, R² %.6f\n", id.condition_number,
              id.rms_residual_m, id.r_squared);
  for (Eigen::Index j = 0; j < 6; ++j) {
    const double error = id.stiffness_nm_per_rad[j] / kTruth[j] - 1.0;
    std::printf("  joint %ld: k = %.4e N·m/rad (true %.4e), error %+.3f %%, se %.3f %%\n",
                static_cast<long>(j + 1), id.stiffness_nm_per_rad[j], kTruth[j], 100.0 * error,
                100.0 * id.stiffness_standard_error_nm_per_rad[j] / kTruth[j]);
    EXPECT_LT(std::abs(error), 0.02) << "joint " << j + 1;
    // The reported standard error is honest: the error is within 4 of them.
    EXPECT_LT(std::abs(error) * kTruth[j], 4.0 * id.stiffness_standard_error_nm_per_rad[j])
        << "joint " << j + 1;
  }
  EXPECT_EQ(id.residual_norm_m.size(), 144);
  EXPECT_GT(id.r_squared, 0.99);
  EXPECT_GT(id.rms_residual_m, 0.0);
}

TEST(StiffnessIdentification, SeparateForceAndMeasurementPointsAndWrenches) {
  // 000 Eq 3 with Jc ≠ Je: load at the tool point, laser-tracker ball elsewhere;
  // and 6-D wrenches with 6-D displacements.
  const Eigen::Vector3d ball(0.1, 0.15, 0.05);
  std::vector<StiffnessSample> samples;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const auto& q : postures()) {
    const Eigen::MatrixXd je = jacobian(q, kTool);
    const Eigen::MatrixXd jc = jacobian(q, ball);
    StiffnessSample s;
    s.jacobian = jc;
    s.force_jacobian = je;
    s.load = (Eigen::VectorXd(6) << 700 * unit(rng), 700 * unit(rng), 700 * unit(rng),
              100 * unit(rng), 100 * unit(rng), 100 * unit(rng))
                 .finished();
    s.displacement_m = jc * kTruth.cwiseInverse().asDiagonal() * je.transpose() * s.load;
    samples.push_back(s);
  }
  const StiffnessIdentification id = identify_joint_stiffness(samples);
  for (Eigen::Index j = 0; j < 6; ++j)
    EXPECT_NEAR(id.stiffness_nm_per_rad[j] / kTruth[j], 1.0, 1e-9) << "joint " << j + 1;
}

TEST(StiffnessIdentification, IllPosedDataAreRefusedNamingTheJoint) {
  // Tool point on the flange axis: no tip force twists joint 6.
  const auto on_axis = synthesize(postures(), kForces, Eigen::Vector3d(0.0, 0.0, 0.3), 0.0, 1);
  expect_invalid([&] { identify_joint_stiffness(on_axis); }, "joint 6 is not observable");
  // One posture, one force: 3 equations for 6 unknowns.
  const auto one_axis = synthesize({postures()[0]}, {kForces[0]}, kTool, 0.0, 1);
  expect_invalid([&] { identify_joint_stiffness(one_axis); }, "3 measured displacement");
  // One posture, one force axis (flange y, which loads every joint) repeated
  // at several magnitudes: 9 equations but rank ≤ 3.
  const auto repeated = synthesize(
      {postures()[0]},
      {Eigen::Vector3d(0, 300, 0), Eigen::Vector3d(0, 600, 0), Eigen::Vector3d(0, 900, 0)}, kTool,
      0.0, 1);
  expect_invalid([&] { identify_joint_stiffness(repeated); }, "rank-deficient");
  // Joints 2 and 3 with the same Jacobian column in every sample (parallel
  // axes through the same point): only c2 + c3 is observable.
  auto coupled = synthesize(postures(), kForces, kTool, 0.0, 1);
  for (auto& s : coupled)
    s.jacobian.col(2) = s.jacobian.col(1);
  expect_invalid([&] { identify_joint_stiffness(coupled); },
                 "joints 2 and 3 are not observable separately");
  // Near-duplicate postures: ill-conditioned under a strict limit.
  StiffnessIdentificationOptions strict;
  strict.max_condition_number = 2.0;
  const auto good = synthesize(postures(), kForces, kTool, 0.0, 1);
  expect_invalid([&] { identify_joint_stiffness(good, strict); }, "ill-conditioned");
  // Displacements of the wrong sign: a negative compliance.
  auto flipped = synthesize(postures(), kForces, kTool, 0.0, 1);
  for (auto& s : flipped)
    s.displacement_m = -s.displacement_m;
  expect_invalid([&] { identify_joint_stiffness(flipped); },
                 "stiffness is not identifiable from these data (fitted compliance");
}

TEST(StiffnessIdentification, InvalidSamplesAreRefused) {
  const auto good = synthesize(postures(), kForces, kTool, 0.0, 1);
  expect_invalid([&] { identify_joint_stiffness({}); }, "at least one");
  auto bad = good;
  bad[4].displacement_m[1] = std::nan("");
  expect_invalid([&] { identify_joint_stiffness(bad); }, "sample 5: has non-finite");
  bad = good;
  bad[2].jacobian = bad[2].jacobian.leftCols(5).eval();
  expect_invalid([&] { identify_joint_stiffness(bad); }, "sample 3: Jacobians must have 6");
  bad = good;
  bad[1].load = Eigen::VectorXd::Zero(6);
  expect_invalid([&] { identify_joint_stiffness(bad); }, "sample 2: a wrench needs a 6-row");
  bad = good;
  bad[0].displacement_m = Eigen::VectorXd::Zero(4);
  expect_invalid([&] { identify_joint_stiffness(bad); }, "sample 1: displacement");
}

}  // namespace

}  // namespace test_stiffness_identification_cpp
