#pragma once
// The redundancy angle along a path (issue 9 item 4): a 6-joint robot
// holding a spindle has one free rotation, about the tool axis, because the
// cut does not change when the spindle turns about its own axis (001
// §2.1.4). The angle changes the posture, and with it the robot's modes at
// the tool tip (004 Eq 1-2, joint_dynamics.hpp) and so the stability limit.
//
// For every path point i and candidate angle ψ the robot is placed by
// inverse kinematics at the tool orientation R_i Rz(ψ) (R_i the cutting
// frame of the point: x feed, z tool axis; ψ = 0 puts the robot's tool x
// along the feed), its tool-tip modes are taken in the cutting frame, and the
// minimum stable depth
//
//   a_min(i, ψ) = min over the speeds Ω of a_lim(Ω)
//
// is computed by the stability engine (cutting_advice.hpp's limit_curve;
// with one speed, the limit at that speed). Reported: per point the ψ that
// maximizes a_min, and the one constant ψ for the whole path that maximizes
// min_i a_min(i, ψ) (the path's weakest point), among angles every point
// reaches within the joint limits. Unreachable (point, ψ) pairs are marked,
// never skipped.

#include <Eigen/Core>
#include <vector>

#include "robomill/planning/cutting_advice.hpp"
#include "robomill/planning/workpiece_placement.hpp"
#include "robomill/robot/robot_model.hpp"

namespace robomill::planning {

struct RedundancyOptions {
  std::vector<double> angles_rad;     ///< candidate ψ
  std::vector<double> spindle_rad_s;  ///< a_min is the lowest limit over these speeds
  LimitSettings limit;
  /// A posture counts as reached when the IK leaves less than these.
  double position_tolerance_m = 1e-7;
  double orientation_tolerance_rad = 1e-6;
  int threads = 0;  ///< (point, angle) pairs are independent work items
};

struct RedundancySample {
  double angle_rad = 0.0;
  bool reachable = false;
  Eigen::VectorXd q;              ///< posture (rad); the best IK attempt when not reachable
  double min_limit_m = 0.0;       ///< a_min (0 when not reachable)
  double at_spindle_rad_s = 0.0;  ///< the speed of that minimum
  double lowest_fn_hz = 0.0;      ///< the robot's lowest natural frequency there
};

struct PointRedundancy {
  PlacedPoint placed;
  std::vector<RedundancySample> samples;  ///< one per angle, in order
  int best = -1;                          ///< index of the largest a_min; −1: none reachable
};

struct RedundancyStudy {
  std::vector<PointRedundancy> points;
  int best_constant = -1;             ///< angle index; −1: no angle reaches every point
  double constant_min_limit_m = 0.0;  ///< min over points of a_min at that angle
  int constant_weakest_point = -1;    ///< the point that sets it
  double elapsed_s = 0.0;
};

/// Runs the study. `seed_posture_rad` starts every IK (it picks the branch).
/// Throws std::invalid_argument for a robot with fewer than 6 joints (no
/// rotation about the tool axis is free: the 3-joint robot of 004 positions
/// the tip only), no points, no angles or no speeds.
RedundancyStudy redundancy_study(const robot::RobotModel& robot,
                                 const std::vector<PlacedPoint>& points,
                                 const Eigen::VectorXd& seed_posture_rad, const tool::Tool& tool,
                                 const cutting::CuttingLaw& law,
                                 const cutting::MillingProcess& process,
                                 const RedundancyOptions& options);

}  // namespace robomill::planning
