#pragma once
// Kinematics of a RobotModel (000 §2, 004 §3.1): forward kinematics and the
// geometric Jacobian at the tool tip (Orocos KDL), and inverse kinematics by
// damped least squares (Levenberg-Marquardt) within the joint limits,
// including the 5-axis form of 001 §2.1.4 where the tool axis is given and
// the rotation about it is the free (redundant) sixth direction.
//
// Everything is expressed in the cell frame: the chain's base frame moved by
// RobotDescription::base.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "robomill/robot/robot_model.hpp"

namespace robomill::robot {

/// Tool pose in the cell frame: base ∘ FK(q) (the chain ends at the tool tip).
/// Throws std::invalid_argument if q has the wrong size or is not finite.
Eigen::Isometry3d tool_pose(const RobotModel& model, const Eigen::VectorXd& q);

/// Geometric Jacobian at the tool tip, rows [linear velocity (m/s);
/// angular velocity (rad/s)] per joint rate, expressed in the cell frame.
Eigen::Matrix<double, 6, Eigen::Dynamic> tool_jacobian(const RobotModel& model,
                                                       const Eigen::VectorXd& q);

/// Geometric Jacobian of a point fixed to the tool, `offset_tool_m` from the
/// tool tip in the tool frame (a node up the cutter, a target ball, the point
/// a test load hangs from): the linear rows move with the rigid-body
/// transfer v_p = v_tip + ω × r, r = R_tool · offset (cell frame); the
/// angular rows are the tool's. These are 000 Eq 3's Jc and Je when the
/// measured and the loaded points differ.
Eigen::Matrix<double, 6, Eigen::Dynamic> point_jacobian(const RobotModel& model,
                                                        const Eigen::VectorXd& q,
                                                        const Eigen::Vector3d& offset_tool_m);

struct IkOptions {
  /// Convergence: ‖p_target − p‖ ≤ position_tolerance_m and, unless
  /// position_only, the rotation angle between the target and the reached
  /// orientation ≤ orientation_tolerance_rad.
  double position_tolerance_m = 1e-10;
  double orientation_tolerance_rad = 1e-10;
  /// Solve for the tool-tip position only (robots with fewer than 6 joints,
  /// e.g. the 3-joint robot of 004 §4.1).
  bool position_only = false;
  int max_iterations = 200;  ///< per attempt
  /// Further attempts from seeds spread over the joint limits when the attempt
  /// from q_seed does not converge; the converged solution closest to q_seed
  /// (Euclidean joint distance) is kept.
  int restarts = 8;
  /// Length that weighs orientation errors against position errors in the
  /// least-squares cost (m per rad).
  double orientation_weight_m = 1.0;
};

struct IkResult {
  Eigen::VectorXd q;  ///< joint angles (rad), within the limits; best attempt when not converged
  bool converged = false;
  double position_residual_m = 0.0;       ///< ‖p_target − p(q)‖
  double orientation_residual_rad = 0.0;  ///< angle of R_target R(q)ᵀ (0 when position_only)
  int iterations = 0;                     ///< over all attempts
  int attempts = 0;                       ///< 1 + restarts used
};

/// Inverse kinematics for a tool pose in the cell frame. Joint limits are
/// honoured by clamping every step; unreachable poses return converged =
/// false with finite residuals (never NaN). Throws std::invalid_argument for
/// a q_seed of the wrong size or non-finite inputs.
IkResult inverse_kinematics(const RobotModel& model, const Eigen::Isometry3d& target_tool_pose,
                            const Eigen::VectorXd& q_seed, const IkOptions& options = {});

/// Tool orientation (cell frame) whose z is `tool_axis` (normalized) and whose
/// rotation about it is `redundancy_angle_rad` (001 §2.1.4): at angle 0 the
/// tool x is the cell x projected onto the plane normal to the axis (the cell
/// y when the axis is within 1e-6 rad of parallel to cell x), and the angle
/// turns it about the tool axis by the right-hand rule. Throws
/// std::invalid_argument for a zero or non-finite axis.
Eigen::Matrix3d tool_orientation_about_axis(const Eigen::Vector3d& tool_axis,
                                            double redundancy_angle_rad);

/// IK for a tip position and a tool axis (5-axis cut) with the redundancy
/// angle fixing the sixth direction (tool_orientation_about_axis). With
/// options.position_only, the axis and angle are ignored.
IkResult inverse_kinematics_about_axis(const RobotModel& model,
                                       const Eigen::Vector3d& tip_position_m,
                                       const Eigen::Vector3d& tool_axis,
                                       double redundancy_angle_rad, const Eigen::VectorXd& q_seed,
                                       const IkOptions& options = {});

}  // namespace robomill::robot
