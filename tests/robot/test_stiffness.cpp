// Cartesian compliance C = J Kq⁻¹ Jᵀ (000 Eq 3): against the FK displacement
// of joints deflected by Δq = Kq⁻¹ Jᵀ w, its inverse (000 Eq 4), the
// translational block, principal stiffness and the singular cases.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "example_robots.hpp"
#include "robomill/robot/kinematics.hpp"
#include "robomill/robot/robot_model.hpp"
#include "robomill/robot/stiffness.hpp"

namespace test_stiffness_cpp {

namespace {

using namespace robomill::robot;
using namespace robomill::test;

// Deflect the joints by ±Δq, Δq = Kq⁻¹ Jᵀ w (the joint springs' response to
// the wrench), and compare the central FK displacement with C w.
void expect_compliance_matches_fk(const RobotModel& m, const Eigen::VectorXd& q,
                                  const Vector6d& wrench) {
  const Eigen::VectorXd dq =
      m.joint_stiffness().cwiseInverse().asDiagonal() * (tool_jacobian(m, q).transpose() * wrench);
  const Eigen::Isometry3d tp = tool_pose(m, q + dq), tm = tool_pose(m, q - dq);
  Vector6d fk;
  fk.head<3>() = (tp.translation() - tm.translation()) / 2;
  fk.tail<3>() = rotation_vector(tp.linear() * tm.linear().transpose()) / 2;
  const Vector6d cw = deflection(m, q, wrench);
  const double lin = (fk.head<3>() - cw.head<3>()).norm() / cw.head<3>().norm();
  const double ang = (fk.tail<3>() - cw.tail<3>()).norm() / cw.tail<3>().norm();
  EXPECT_LT(lin, 1e-6);
  EXPECT_LT(ang, 1e-6);
  std::printf(
      "[validation] %s compliance vs FK of Δq = Kq⁻¹Jᵀw (|Δq| = %.1e rad): linear %.2e, angular "
      "%.2e relative; tip deflection %.3e m\n",
      m.name().c_str(), dq.norm(), lin, ang, cw.head<3>().norm());
}

TEST(Stiffness, ComplianceMatchesDeflectedFkKr600) {
  const RobotModel m(kr600());
  Vector6d w;
  w << 30.0, -12.0, 25.0, 1.5, -2.0, 0.8;  // small: |Δq| ≈ 1e-5 rad
  expect_compliance_matches_fk(m, posture_000(), w);
  Vector6d f_only = Vector6d::Zero();
  f_only.head<3>() << -20.0, 35.0, 10.0;
  expect_compliance_matches_fk(m, posture_000(), f_only);
}

TEST(Stiffness, ComplianceMatchesDeflectedFk004) {
  const RobotModel m(robot_004());
  Vector6d w;
  w << 2.0, -1.5, 3.0, 0.2, -0.1, 0.3;
  expect_compliance_matches_fk(m, Eigen::Vector3d(0.4, -0.6, 0.8), w);
}

// 000 Eq 3 with Jc ≠ Je: a load hung 0.25 m off the tip, a target ball
// 0.1 m up the tool. The joints deflect by Δq = Kq⁻¹ Jeᵀ w; the measured
// point moves by what FK of the point says, central differences.
TEST(Stiffness, DeflectionBetweenTwoPointsMatchesDeflectedFk) {
  const RobotModel m(kr600());
  const Eigen::VectorXd q = posture_000();
  const Eigen::Vector3d measured(0.0, 0.02, 0.1), loaded(0.25, -0.05, 0.0);
  Vector6d w;
  w << 30.0, -12.0, 25.0, 1.5, -2.0, 0.8;
  const Eigen::VectorXd dq = m.joint_stiffness().cwiseInverse().asDiagonal() *
                             (point_jacobian(m, q, loaded).transpose() * w);
  auto point = [&](const Eigen::VectorXd& qq) { return tool_pose(m, qq) * measured; };
  const Eigen::Vector3d fk = (point(q + dq) - point(q - dq)) / 2;
  const Vector6d ours = deflection_between(m, q, measured, loaded, w);
  const double relative = (fk - ours.head<3>()).norm() / ours.head<3>().norm();
  EXPECT_LT(relative, 1e-6);
  std::printf(
      "[validation] KR600 Jc Kq⁻¹ Jeᵀ w vs deflected FK of the measured point: %.2e "
      "relative (%.3e m)\n",
      relative, ours.head<3>().norm());
  // Zero offsets: Eq 3 with Jc = Je, the tip compliance.
  EXPECT_LT((deflection_between(m, q, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), w) -
             deflection(m, q, w))
                .norm(),
            1e-15);
  // Maxwell-Betti: the force-to-displacement block from e to c is the
  // transpose of the one from c to e.
  Eigen::Matrix3d c_from_e, e_from_c;
  for (int k = 0; k < 3; ++k) {
    Vector6d f = Vector6d::Zero();
    f[k] = 1.0;
    c_from_e.col(k) = deflection_between(m, q, measured, loaded, f).head<3>();
    e_from_c.col(k) = deflection_between(m, q, loaded, measured, f).head<3>();
  }
  EXPECT_LT((c_from_e - e_from_c.transpose()).norm(), 1e-12 * c_from_e.norm());
}

TEST(Stiffness, PointJacobianMatchesFiniteDifferences) {
  const RobotModel m(kr600());
  const Eigen::VectorXd q = posture_000();
  const Eigen::Vector3d offset(0.05, -0.1, 0.2);
  const Eigen::MatrixXd j = point_jacobian(m, q, offset);
  const double h = 1e-6;
  for (int i = 0; i < m.dof(); ++i) {
    Eigen::VectorXd qp = q, qm = q;
    qp[i] += h;
    qm[i] -= h;
    const Eigen::Vector3d column =
        (tool_pose(m, qp) * offset - tool_pose(m, qm) * offset) / (2 * h);
    EXPECT_LT((column - j.block<3, 1>(0, i)).norm(), 1e-6 * column.norm()) << "joint " << i + 1;
  }
  EXPECT_THROW(point_jacobian(m, q, Eigen::Vector3d(NAN, 0, 0)), std::invalid_argument);
}

TEST(Stiffness, ComplianceIsJKinvJt) {
  const RobotModel m(kr600());
  const Eigen::VectorXd q = posture_000();
  const Eigen::MatrixXd j = tool_jacobian(m, q);
  Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(6, 6);
  for (int i = 0; i < 6; ++i)
    expected += j.col(i) * j.col(i).transpose() / m.joint_stiffness()[i];
  const Matrix6d c = cartesian_compliance(m, q);
  EXPECT_LT((c - expected).norm(), 1e-14 * expected.norm());
  EXPECT_EQ(c, c.transpose());
  const Eigen::Matrix3d block = c.topLeftCorner<3, 3>();
  EXPECT_EQ(translational_compliance(m, q), block);
}

TEST(Stiffness, StiffnessInvertsComplianceKr600) {
  const RobotModel m(kr600());
  const Eigen::VectorXd q = posture_000();
  const Matrix6d c = cartesian_compliance(m, q);
  const Matrix6d k = cartesian_stiffness(m, q);
  EXPECT_LT((k * c - Matrix6d::Identity()).norm(), 1e-9);
  const Eigen::Matrix3d kt = translational_stiffness(m, q);
  EXPECT_LT((kt * c.topLeftCorner<3, 3>() - Eigen::Matrix3d::Identity()).norm(), 1e-9);

  const PrincipalStiffness p = principal_stiffness(m, q);
  EXPECT_LE(p.stiffness_n_per_m[0], p.stiffness_n_per_m[1]);
  EXPECT_LE(p.stiffness_n_per_m[1], p.stiffness_n_per_m[2]);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(p.directions.col(i).norm(), 1.0, 1e-12);
    EXPECT_LT((kt * p.directions.col(i) - p.stiffness_n_per_m[i] * p.directions.col(i)).norm(),
              1e-9 * p.stiffness_n_per_m[2]);
  }
  EXPECT_NEAR(p.condition_number, p.stiffness_n_per_m[2] / p.stiffness_n_per_m[0], 1e-12);
  std::printf(
      "[validation] KR600-class at 000 §6.3 posture: principal stiffness %.4g, %.4g, %.4g N/m "
      "(condition %.3g)\n",
      p.stiffness_n_per_m[0], p.stiffness_n_per_m[1], p.stiffness_n_per_m[2], p.condition_number);
}

TEST(Stiffness, FewerThanSixJointsOfferTranslationalStiffness) {
  const RobotModel m(robot_004());
  const Eigen::Vector3d q(0.4, -0.6, 0.8);
  try {
    cartesian_stiffness(m, q);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("has 3 joints (< 6)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("translational stiffness"), std::string::npos);
  }
  const Eigen::Matrix3d kt = translational_stiffness(m, q);
  EXPECT_LT((kt * translational_compliance(m, q) - Eigen::Matrix3d::Identity()).norm(), 1e-9);
}

TEST(Stiffness, SingularPostureThrows) {
  // 004 stretched out (q3 = 0): the tip cannot move along the arm.
  const RobotModel m(robot_004());
  EXPECT_THROW(translational_stiffness(m, Eigen::Vector3d(0.2, 0.3, 0.0)), std::invalid_argument);
  EXPECT_THROW(principal_stiffness(m, Eigen::Vector3d(0.2, 0.3, 0.0)), std::invalid_argument);
  // KR600 with the wrist straight (q5 = 0): axes 4 and 6 align.
  const RobotModel kr(kr600());
  Eigen::VectorXd q = posture_000();
  q[4] = 0.0;
  try {
    cartesian_stiffness(kr, q);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("singular"), std::string::npos) << e.what();
  }
  Vector6d w = Vector6d::Zero();
  w[0] = NAN;
  EXPECT_THROW(deflection(kr, posture_000(), w), std::invalid_argument);
}

}  // namespace

}  // namespace test_stiffness_cpp
