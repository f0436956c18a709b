#include "robomill/planning/path_performance.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "robomill/core/parallel.hpp"
#include "robomill/robot/kinematics.hpp"

namespace robomill::planning {
namespace {

robot::IkOptions ik_options(const robot::RobotModel& robot) {
  robot::IkOptions ik;
  // Robots with fewer than six joints (004's three) place the tip only; the
  // tool frame then comes from the path, not from the wrist (004 Eq 7).
  ik.position_only = robot.dof() < 6;
  ik.position_tolerance_m = 1e-10;
  ik.orientation_tolerance_rad = 1e-10;
  return ik;
}

robot::IkResult solve(const robot::RobotModel& robot, const PlacedPoint& placed,
                      const Eigen::VectorXd& seed) {
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.translation() = placed.position_m;
  target.linear() = placed.tool_to_cell;
  return robot::inverse_kinematics(robot, target, seed, ik_options(robot));
}

// Which joint keeps a point out of reach: the IK again with every range
// opened to ±2π; if that reaches the point, the joint furthest past its
// range is at fault, otherwise the point is outside the workspace.
Unreachable diagnose_point(const robot::RobotModel& robot, const robot::RobotModel& unlimited,
                           const PlacedPoint& placed, const Eigen::VectorXd& seed,
                           double residual_m, double tolerance_m) {
  Unreachable why;
  why.residual_m = residual_m;
  const robot::IkResult free = solve(unlimited, placed, seed);
  if (!free.converged || free.position_residual_m > tolerance_m)
    return why;
  double worst = 0.0;
  for (int j = 0; j < robot.dof(); ++j) {
    const auto& joint = robot.joints()[std::size_t(j)];
    const double past = std::max(joint.lower_rad - free.q[j], free.q[j] - joint.upper_rad);
    if (past > worst) {
      worst = past;
      why.joint = j;
      why.needed_angle_rad = free.q[j];
    }
  }
  return why;
}

}  // namespace

PathPerformance evaluate_path(const robot::RobotModel& robot, const PlacementProblem& problem,
                              const WorkpiecePose& pose, int threads, bool diagnose) {
  if (problem.seed_posture_rad.size() != robot.dof())
    throw std::invalid_argument("evaluate_path: the seed posture needs one angle per joint");
  PathPerformance result;
  result.pose = pose;
  result.points.resize(problem.path.size());
  core::parallel_blocks(problem.path.size(), threads, [&](std::size_t begin, std::size_t end) {
    OffsetWorkspace workspace;
    for (std::size_t i = begin; i < end; ++i) {
      PointPerformance& point = result.points[i];
      point.placed = place(problem.cell, pose, problem.path[i]);
      // Every point starts from the same seed posture: the branch (elbow up
      // or down) is the seed's, whatever the order or thread of evaluation.
      const robot::IkResult ik = solve(robot, point.placed, problem.seed_posture_rad);
      point.q = ik.q;
      point.ik_residual_m = ik.position_residual_m;
      point.reachable = ik.converged && ik.position_residual_m <= problem.position_tolerance_m &&
                        robot.within_limits(ik.q);
      if (!point.reachable)
        continue;
      const PostureDynamics dynamics = posture_dynamics(robot, ik.q);
      point.offset = steady_state_offset(dynamics, point.placed.tool_to_cell, problem.force,
                                         workspace, problem.measure == OffsetMeasure::startup);
      point.d_m = point.offset.measure(problem.measure);
      const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> modes(
          dynamics.stiffness, dynamics.mass, Eigen::EigenvaluesOnly | Eigen::Ax_lBx);
      point.natural_frequencies_hz =
          modes.eigenvalues().cwiseMax(0.0).cwiseSqrt() / (2.0 * std::numbers::pi);
    }
  });
  double sum = 0.0;
  for (const PointPerformance& point : result.points) {
    if (!point.reachable) {
      ++result.unreachable;
      result.residual_m += std::max(point.ik_residual_m, problem.position_tolerance_m);
      continue;
    }
    sum += point.d_m;
    result.max_m = std::max(result.max_m, point.d_m);
  }
  if (result.unreachable == 0 && !result.points.empty())
    result.dm_m = sum / static_cast<double>(result.points.size());  // 004 Eq 6
  if (diagnose && result.unreachable > 0) {
    robot::RobotDescription open = robot.description();
    for (auto& joint : open.joints) {
      joint.lower_rad = -2.0 * std::numbers::pi;
      joint.upper_rad = 2.0 * std::numbers::pi;
    }
    open.use_urdf_limits = false;
    const robot::RobotModel unlimited(open);
    for (PointPerformance& point : result.points) {
      if (!point.reachable)
        point.why = diagnose_point(robot, unlimited, point.placed, problem.seed_posture_rad,
                                   point.ik_residual_m, problem.position_tolerance_m);
    }
  }
  return result;
}

}  // namespace robomill::planning
