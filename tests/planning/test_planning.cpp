// Planning (004 §3.1-3.3): path placement, the force's Fourier series, the
// harmonic steady state of Eq 1-2 against direct time integration, d_m, and
// unreachable points reported with the joint at fault.

#include <gtest/gtest.h>

#include <numbers>

#include "robomill/job/job.hpp"
#include "robomill/planning/path_performance.hpp"
#include "robomill/planning/pose_optimization.hpp"
#include "support/case004.hpp"

namespace test_planning_cpp {

namespace {

using namespace robomill;
constexpr double kPi = std::numbers::pi;

// The example job's case with the peak offset (the tests' measure).
struct Case004 : test::Case004 {
  planning::PlacementProblem problem() const {
    return test::Case004::problem(planning::OffsetMeasure::peak);
  }
};

TEST(Path, RectangleHasEqualStepsAndFeedsAlongItsSides) {
  const auto path = planning::rectangular_path({0.12, 0, 0}, 0.16, 0.08, 20, true);
  ASSERT_EQ(path.size(), 20u);
  EXPECT_TRUE(path[0].position_m.isApprox(Eigen::Vector3d(0.12, 0, 0)));
  EXPECT_TRUE(path[0].feed_direction.isApprox(Eigen::Vector3d::UnitX()));
  // 0.48 m perimeter in 20 steps: point 8 (s = 0.168) is on the second side.
  EXPECT_TRUE(path[7].position_m.isApprox(Eigen::Vector3d(0.28, 0.008, 0)));
  EXPECT_TRUE(path[7].feed_direction.isApprox(Eigen::Vector3d::UnitY()));
  // Point 11 (s = 0.24) is the opposite corner and leaves along −x.
  EXPECT_TRUE(path[10].position_m.isApprox(Eigen::Vector3d(0.28, 0.08, 0)));
  EXPECT_TRUE(path[10].feed_direction.isApprox(-Eigen::Vector3d::UnitX()));
  const auto cw = planning::rectangular_path({0, 0, 0}, 0.16, 0.08, 4, false);
  EXPECT_TRUE(cw[0].feed_direction.isApprox(Eigen::Vector3d::UnitY()));
  EXPECT_THROW(planning::rectangular_path({0, 0, 0}, 0.0, 0.08, 4, true), std::invalid_argument);
}

TEST(Path, PlacementFollowsEq7AndTiltRaisesTheEdge) {
  planning::Workcell cell;
  cell.table_origin_m = {0.6, 0.0, 0.5};
  const planning::PathPoint point{{0.2, 0.05, 0.0}, Eigen::Vector3d::UnitX()};
  const auto flat = planning::place(cell, {0.1, -0.2, 0.0}, point);
  EXPECT_TRUE(flat.position_m.isApprox(Eigen::Vector3d(0.9, -0.15, 0.5)));
  EXPECT_TRUE(flat.tool_to_cell.isApprox(Eigen::Matrix3d::Identity()));
  const auto tilted = planning::place(cell, {0.0, 0.0, kPi / 3}, point);
  EXPECT_NEAR(tilted.position_m.z(), 0.5 + 0.2 * std::sin(kPi / 3), 1e-12);
  EXPECT_NEAR(tilted.tool_to_cell.col(0).z(), std::sin(kPi / 3), 1e-12);  // feed rises
  EXPECT_NEAR(tilted.tool_to_cell.determinant(), 1.0, 1e-12);
  cell.tilt_axis = planning::TiltAxis::x;
  const auto about_x = planning::place(cell, {0.0, 0.0, kPi / 3}, point);
  EXPECT_NEAR(about_x.position_m.z(), 0.5 + 0.05 * std::sin(kPi / 3), 1e-12);
}

TEST(ForceHarmonics, MeanIsTheSampleMeanAndTheSeriesReproducesTheForce) {
  const Case004 c;
  const auto h = planning::force_harmonics(c.force, 512, 200);
  EXPECT_NEAR(h.period_s, 0.03, 1e-12);  // 1000 rpm, 2 teeth (004 Figure 6: 33.33 Hz)
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double largest = 0.0, worst = 0.0;
  for (int m = 0; m < 512; ++m) {
    const Eigen::Vector3d f = c.force.at(kPi * m / 512).force_n;
    mean += f / 512.0;
    largest = std::max(largest, f.norm());
    worst = std::max(worst, (planning::force_at(h, h.period_s * m / 512) - f).norm());
  }
  EXPECT_TRUE(h.coefficients[0].real().isApprox(mean, 1e-12));
  EXPECT_LT(worst, 0.01 * largest);  // 200 of 256 harmonics: within 1 % of the peak force
}

// The acceptance check of the frequency-domain steady state: the same linear
// model (004 Eq 1 at the posture of path point 1 of Table 2's pose 1),
// integrated in time by RK4 with the exact force until two periods agree to
// 1e-9, gives the same peak, vibration and mean offsets within 1 %; and the
// start-up maximum equals that of an integration from rest.
TEST(SteadyState, HarmonicSolutionMatchesTimeIntegration) {
  const Case004 c;
  const planning::PlacementProblem p = c.problem();
  const auto path = planning::evaluate_path(c.robot, p, {0.6, 0.2, kPi / 3});
  ASSERT_TRUE(path.reachable());
  const auto& point = path.points.front();
  const auto dynamics = planning::posture_dynamics(c.robot, point.q);
  planning::OffsetWorkspace workspace;
  const auto harmonic =
      planning::steady_state_offset(dynamics, point.placed.tool_to_cell, p.force, workspace, true);
  int periods = 0;
  const auto integrated = planning::steady_state_offset_time_domain(
      dynamics, point.placed.tool_to_cell, c.force, p.force.period_s, 1024, 3000, 1e-9, &periods);
  EXPECT_LT(periods, 3000) << "the time integration did not settle";
  EXPECT_NEAR(harmonic.peak_m, integrated.peak_m, 0.01 * integrated.peak_m);
  EXPECT_NEAR(harmonic.vibration_m, integrated.vibration_m, 0.01 * integrated.vibration_m);
  EXPECT_NEAR(harmonic.mean_m, integrated.mean_m, 0.01 * integrated.mean_m);
  EXPECT_NEAR(harmonic.rms_m, integrated.rms_m, 0.01 * integrated.rms_m);
  // The static part matches the compliance J Kq⁻¹ Jᵀ under the mean force.
  const Eigen::Vector3d mean_force = point.placed.tool_to_cell * p.force.coefficients[0].real();
  const Eigen::Vector3d static_offset =
      dynamics.jacobian *
      dynamics.stiffness.ldlt().solve(dynamics.jacobian.transpose() * mean_force);
  EXPECT_TRUE(harmonic.mean_offset_m.isApprox(static_offset, 1e-9));
  const auto from_rest =
      planning::steady_state_offset_time_domain(dynamics, point.placed.tool_to_cell, c.force,
                                                p.force.period_s, 1024, 3000, 1e-9, nullptr, true);
  EXPECT_NEAR(harmonic.startup_m, from_rest.startup_m, 0.01 * from_rest.startup_m);
  EXPECT_GT(harmonic.startup_m, harmonic.peak_m);  // the start overshoots the steady state
  std::cout << "[planning] steady state: harmonic peak " << harmonic.peak_m * 1e3
            << " mm, time domain " << integrated.peak_m * 1e3 << " mm (" << periods
            << " periods); start-up " << harmonic.startup_m * 1e3 << " vs "
            << from_rest.startup_m * 1e3 << " mm\n";
}

TEST(PathPerformance, DmIsTheMeanOfThePointsAndIndependentOfThreads) {
  const Case004 c;
  const auto p = c.problem();
  const auto one = planning::evaluate_path(c.robot, p, {0.0, -0.46, 0.0}, 1);
  const auto two = planning::evaluate_path(c.robot, p, {0.0, -0.46, 0.0}, 2);
  ASSERT_TRUE(one.reachable());
  double sum = 0.0;
  for (const auto& point : one.points)
    sum += point.d_m;
  EXPECT_NEAR(one.dm_m, sum / 20.0, 1e-15);  // 004 Eq 6
  EXPECT_EQ(one.dm_m, two.dm_m);
}

TEST(PathPerformance, UnreachablePointsAreReportedWithTheJointAtFault) {
  const Case004 c;
  auto p = c.problem();
  // Far beyond the 1.6 m arm: outside the workspace, whatever the limits.
  const auto far = planning::evaluate_path(c.robot, p, {2.0, 0.0, 0.0}, 1, true);
  EXPECT_EQ(far.unreachable, 20);
  EXPECT_EQ(far.dm_m, 0.0);
  ASSERT_TRUE(far.points[0].why);
  EXPECT_EQ(far.points[0].why->joint, -1);
  // Close to the base the arm must fold past a joint's range (the elbow's
  // −60°, or the shoulder beyond vertical, whichever the unlimited IK finds).
  p.cell.table_origin_m = {0.0, 0.0, 0.5};
  const auto near = planning::evaluate_path(c.robot, p, {0.2, 0.0, 0.0}, 1, true);
  EXPECT_GT(near.unreachable, 0);
  for (const auto& point : near.points) {
    if (!point.reachable) {
      ASSERT_TRUE(point.why);
      ASSERT_GE(point.why->joint, 0) << "a joint range, not the workspace, is at fault";
      const auto& joint = c.robot.joints()[std::size_t(point.why->joint)];
      EXPECT_TRUE(point.why->needed_angle_rad < joint.lower_rad ||
                  point.why->needed_angle_rad > joint.upper_rad);
    }
  }
}

TEST(PoseOptimization, DirectIsDeterministicAndNeverReturnsAnUnreachablePose) {
  const Case004 c;
  const auto p = c.problem();
  planning::PoseBounds bounds;
  bounds.lower = {0.0, -0.5, 0.0};
  bounds.upper = {0.6, 0.5, 0.0};
  bounds.fixed = {0.0, 0.0, 0.0};
  bounds.free = {true, true, false};
  planning::PoseOptimizationOptions options;
  options.global_evaluations = 40;  // determinism needs no long search
  options.local_evaluations = 20;
  const auto a = planning::optimize_workpiece_pose(c.robot, p, bounds, options);
  const auto b = planning::optimize_workpiece_pose(c.robot, p, bounds, options);
  ASSERT_TRUE(a.found);
  EXPECT_EQ(a.best.x_m, b.best.x_m);
  EXPECT_EQ(a.best.y_m, b.best.y_m);
  EXPECT_EQ(a.dm_m, b.dm_m);
  EXPECT_EQ(a.best.theta_rad, 0.0);  // fixed
  EXPECT_TRUE(planning::evaluate_path(c.robot, p, a.best).reachable());
  for (const auto& e : a.evaluations) {
    if (e.reachable) {
      EXPECT_GE(e.dm_m, a.dm_m);
    }
  }
  // A box the robot cannot reach anywhere: nothing found, nothing invented.
  bounds.lower = {1.5, -0.5, 0.0};
  bounds.upper = {2.0, 0.5, 0.0};
  options.global_evaluations = 20;
  const auto none = planning::optimize_workpiece_pose(c.robot, p, bounds, options);
  EXPECT_FALSE(none.found);
}

}  // namespace

}  // namespace test_planning_cpp
