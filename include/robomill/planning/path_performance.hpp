#pragma once
// Quasi-static performance of a robot along a tool path for one workpiece
// pose (004 §3.3, Figure 4): place the path (Eq 7), find the posture at every
// point by inverse kinematics, take the steady-state tool-tip offset there
// (Eq 1-2, steady_state_offset.hpp) and average (Eq 6):
//
//   d_m = (1/n_p) Σ_i d_i                                          (004 Eq 6)
//
// A point the robot cannot reach, or reaches only past a joint limit, is
// never skipped: the evaluation reports it (and, on request, names the joint
// that would have to pass its limit), and d_m is then undefined.

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "robomill/planning/force_harmonics.hpp"
#include "robomill/planning/steady_state_offset.hpp"
#include "robomill/planning/workpiece_placement.hpp"
#include "robomill/robot/robot_model.hpp"

namespace robomill::planning {

/// Everything but the pose: the cell, the path, the cut's force series, the
/// posture the inverse kinematics starts from (it selects the branch, e.g.
/// elbow up) and the measure taken as d_i.
struct PlacementProblem {
  Workcell cell;
  std::vector<PathPoint> path;
  ForceHarmonics force;
  Eigen::VectorXd seed_posture_rad;
  OffsetMeasure measure = OffsetMeasure::peak;
  /// A point counts as reached when the IK residual is below this.
  double position_tolerance_m = 1e-7;
};

/// Why a point was not reached.
struct Unreachable {
  /// 0-based joint the point needs beyond its range, −1 when the point is
  /// outside the workspace whatever the limits.
  int joint = -1;
  double needed_angle_rad = 0.0;  ///< that joint's angle without limits
  double residual_m = 0.0;        ///< distance left by the IK within the limits
};

struct PointPerformance {
  PlacedPoint placed;
  bool reachable = false;
  Eigen::VectorXd q;  ///< posture (rad); the best attempt when not reachable
  double ik_residual_m = 0.0;
  std::optional<Unreachable> why;          ///< filled by evaluate_path(…, diagnose = true)
  OffsetResponse offset;                   ///< zero when not reachable
  Eigen::VectorXd natural_frequencies_hz;  ///< at q (empty when not reachable)
  double d_m = 0.0;                        ///< offset.measure(problem.measure)
};

struct PathPerformance {
  WorkpiecePose pose;
  std::vector<PointPerformance> points;
  int unreachable = 0;
  double dm_m = 0.0;        ///< Eq 6 (0 when a point is unreachable)
  double max_m = 0.0;       ///< largest d_i
  double residual_m = 0.0;  ///< sum of IK residuals (0 when all reached)
  bool reachable() const noexcept { return unreachable == 0; }
};

/// Evaluates one pose. Points are independent and run on `threads` threads
/// (each IK starts from the problem's seed posture, so the result does not
/// depend on the thread count). With `diagnose`, unreachable points are
/// examined with the joint limits removed to name the joint at fault.
PathPerformance evaluate_path(const robot::RobotModel& robot, const PlacementProblem& problem,
                              const WorkpiecePose& pose, int threads = 1, bool diagnose = false);

}  // namespace robomill::planning
