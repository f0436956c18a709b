// Forward kinematics, the tool-tip Jacobian (against central differences of
// FK) and inverse kinematics (round trips, redundancy angle, limits,
// unreachable poses) on a KR600-class 6-joint robot and 004's 3-joint robot.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "example_robots.hpp"
#include "robomill/robot/kinematics.hpp"
#include "robomill/robot/robot_model.hpp"

namespace test_kinematics_cpp {

namespace {

using namespace robomill::robot;
using namespace robomill::test;

// Central differences of FK: linear part from the tip position, angular part
// from the rotation between the two perturbed orientations.
Eigen::Matrix<double, 6, Eigen::Dynamic> fd_jacobian(const RobotModel& m, const Eigen::VectorXd& q,
                                                     double h) {
  Eigen::Matrix<double, 6, Eigen::Dynamic> j(6, q.size());
  for (int i = 0; i < q.size(); ++i) {
    Eigen::VectorXd qp = q, qm = q;
    qp[i] += h;
    qm[i] -= h;
    const Eigen::Isometry3d tp = tool_pose(m, qp), tm = tool_pose(m, qm);
    j.col(i).head<3>() = (tp.translation() - tm.translation()) / (2 * h);
    j.col(i).tail<3>() = rotation_vector(tp.linear() * tm.linear().transpose()) / (2 * h);
  }
  return j;
}

void expect_jacobian_matches_fd(const RobotModel& m, const Eigen::VectorXd& q) {
  const Eigen::Matrix<double, 6, Eigen::Dynamic> j = tool_jacobian(m, q);
  const Eigen::Matrix<double, 6, Eigen::Dynamic> fd = fd_jacobian(m, q, 1e-6);
  const double lin = (j.topRows<3>() - fd.topRows<3>()).norm() / j.topRows<3>().norm();
  const double ang = (j.bottomRows<3>() - fd.bottomRows<3>()).norm() / j.bottomRows<3>().norm();
  EXPECT_LT(lin, 1e-6);
  EXPECT_LT(ang, 1e-6);
  std::printf("[validation] %s Jacobian vs central FD: linear %.2e, angular %.2e relative\n",
              m.name().c_str(), lin, ang);
}

TEST(Kinematics, JacobianMatchesFiniteDifferencesKr600) {
  const RobotModel m(kr600());
  expect_jacobian_matches_fd(m, posture_000());
  Eigen::VectorXd q(6);
  q << 0.3, -0.9, 0.7, 1.1, 0.8, -0.5;
  expect_jacobian_matches_fd(m, q);
}

TEST(Kinematics, JacobianMatchesFiniteDifferences004) {
  const RobotModel m(robot_004());
  expect_jacobian_matches_fd(m, Eigen::Vector3d(0.4, -0.6, 0.8));
  expect_jacobian_matches_fd(m, Eigen::Vector3d(-1.2, 0.3, -0.2));
}

TEST(Kinematics, WrongSizeOrNonFinitePostureThrows) {
  const RobotModel m(robot_004());
  EXPECT_THROW(tool_pose(m, Eigen::Vector2d(0, 0)), std::invalid_argument);
  EXPECT_THROW(tool_jacobian(m, Eigen::Vector3d(0, NAN, 0)), std::invalid_argument);
}

TEST(InverseKinematics, FullPoseRoundTripKr600) {
  const RobotModel m(kr600());
  const Eigen::VectorXd q_ref = posture_000();
  const Eigen::Isometry3d target = tool_pose(m, q_ref);
  Eigen::VectorXd seed = q_ref;
  seed += Eigen::VectorXd::Constant(6, 0.15);
  const IkResult r = inverse_kinematics(m, target, seed);
  ASSERT_TRUE(r.converged);
  const Eigen::Isometry3d t = tool_pose(m, r.q);
  EXPECT_LT((t.translation() - target.translation()).norm(), 1e-9);
  EXPECT_LT(rotation_vector(t.linear() * target.linear().transpose()).norm(), 1e-9);
  EXPECT_TRUE(m.within_limits(r.q));
  EXPECT_LT((r.q - q_ref).norm(), 1e-6);  // the branch of the seed
  std::printf("[validation] KR600 IK round trip: %.2e m, %.2e rad in %d iterations\n",
              r.position_residual_m, r.orientation_residual_rad, r.iterations);
}

TEST(InverseKinematics, PositionOnlyRoundTrip004) {
  const RobotModel m(robot_004());
  IkOptions opt;
  opt.position_only = true;
  for (const Eigen::Vector3d& q_ref :
       {Eigen::Vector3d(0.5, 0.4, -0.7), Eigen::Vector3d(-2.0, -1.0, 0.9)}) {
    const Eigen::Vector3d p = tool_pose(m, q_ref).translation();
    const IkResult r = inverse_kinematics_about_axis(m, p, Eigen::Vector3d::UnitZ(), 0.0,
                                                     q_ref.array() + 0.2, opt);
    ASSERT_TRUE(r.converged);
    EXPECT_LT((tool_pose(m, r.q).translation() - p).norm(), 1e-9);
    EXPECT_TRUE(m.within_limits(r.q));
  }
}

TEST(InverseKinematics, RedundancyAngleIsHonoured) {
  const RobotModel m(kr600());
  const Eigen::Isometry3d ref = tool_pose(m, posture_000());
  const Eigen::Vector3d axis =
      (ref.linear().col(2) + Eigen::Vector3d(0.1, -0.05, 0.08)).normalized();
  const Eigen::Matrix3d frame0 = tool_orientation_about_axis(axis, 0.0);
  Eigen::VectorXd seed = posture_000();
  for (const double angle : {0.0, 0.35, -0.5}) {
    const IkResult r = inverse_kinematics_about_axis(m, ref.translation(), axis, angle, seed);
    ASSERT_TRUE(r.converged) << "angle " << angle;
    const Eigen::Isometry3d t = tool_pose(m, r.q);
    EXPECT_LT((t.translation() - ref.translation()).norm(), 1e-9);
    EXPECT_LT((t.linear().col(2) - axis).norm(), 1e-9);
    const double measured =
        std::atan2(t.linear().col(0).dot(frame0.col(1)), t.linear().col(0).dot(frame0.col(0)));
    EXPECT_NEAR(measured, angle, 1e-9);
    seed = r.q;  // continuation along the redundancy angle
  }
  // Angle 0: tool x is the cell x projected normal to the axis.
  const Eigen::Vector3d x0 = (Eigen::Vector3d::UnitX() - axis.x() * axis).normalized();
  EXPECT_LT((frame0.col(0) - x0).norm(), 1e-15);
}

TEST(InverseKinematics, JointLimitsAreHonoured) {
  RobotDescription d = robot_004();
  d.joints[2].upper_rad = 0.5;  // the elbow may bend only one way beyond 0.5
  const RobotModel m(d);
  IkOptions opt;
  opt.position_only = true;
  // Target reached with q3 = +1.0 (outside); the mirror branch q3 = −1.0 is inside.
  const Eigen::Vector3d p = tool_pose(m, Eigen::Vector3d(0.2, 0.1, 1.0)).translation();
  const IkResult r = inverse_kinematics_about_axis(m, p, Eigen::Vector3d::UnitZ(), 0.0,
                                                   Eigen::Vector3d(0.2, 0.1, 0.4), opt);
  ASSERT_TRUE(r.converged);
  EXPECT_TRUE(m.within_limits(r.q));
  EXPECT_NEAR(r.q[2], -1.0, 1e-8);
  EXPECT_LT((tool_pose(m, r.q).translation() - p).norm(), 1e-9);
  // A point 1.6·cos(0.65) m in front of joint 2 needs |q3| = 1.3 rad on both
  // branches, beyond the paper's π/3: no solution; the closest reachable
  // distance is 1.6·cos(π/6).
  const RobotModel paper(robot_004());
  const Eigen::Vector3d p2(1.6 * std::cos(0.65), 0.0, 0.2);
  const IkResult r2 = inverse_kinematics_about_axis(paper, p2, Eigen::Vector3d::UnitZ(), 0.0,
                                                    Eigen::Vector3d::Zero(), opt);
  EXPECT_FALSE(r2.converged);
  EXPECT_TRUE(paper.within_limits(r2.q));
  EXPECT_TRUE(std::isfinite(r2.position_residual_m));
  EXPECT_NEAR(r2.position_residual_m, 1.6 * (std::cos(kPi / 6) - std::cos(0.65)), 1e-6);
}

TEST(InverseKinematics, UnreachablePoseReturnsNotConvergedWithFiniteResidual) {
  const RobotModel m(kr600());
  Eigen::Isometry3d target = tool_pose(m, posture_000());
  target.translation() += Eigen::Vector3d(10.0, 0.0, 0.0);
  const IkResult r = inverse_kinematics(m, target, posture_000());
  EXPECT_FALSE(r.converged);
  EXPECT_TRUE(std::isfinite(r.position_residual_m));
  EXPECT_TRUE(std::isfinite(r.orientation_residual_rad));
  EXPECT_TRUE(r.q.allFinite());
  EXPECT_GT(r.position_residual_m, 5.0);
  EXPECT_TRUE(m.within_limits(r.q));
  EXPECT_EQ(r.attempts, 1 + IkOptions{}.restarts);

  const RobotModel m3(robot_004());
  IkOptions opt;
  opt.position_only = true;
  const IkResult r3 = inverse_kinematics_about_axis(
      m3, Eigen::Vector3d(10, 0, 0), Eigen::Vector3d::UnitZ(), 0.0, Eigen::Vector3d::Zero(), opt);
  EXPECT_FALSE(r3.converged);
  // Arm stretched from joint 2 at (0, 0, 0.2) towards the target.
  EXPECT_NEAR(r3.position_residual_m, std::hypot(10.0, 0.2) - 1.6, 1e-6);
}

}  // namespace

}  // namespace test_kinematics_cpp
