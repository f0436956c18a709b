#pragma once
// Static stiffness of a robot at the tool tip (000 §2 Eq 3-4; 002 §2).
//
// With rigid links and torsional joint springs Kq = diag(k_i), a wrench
// w = [F; M] at the tool tip (cell frame) loads the joints with τ = Jᵀ w,
// deflects them by Δq = Kq⁻¹ Jᵀ w, and moves the tip by J Δq, so the
// Cartesian compliance is
//
//   C = J Kq⁻¹ Jᵀ                               (000 Eq 3 with Jc = Je = J)
//
// with J the geometric Jacobian at the tool tip in the cell frame
// (kinematics.hpp). C is 6×6, blocks [m/N, m/(N·m); rad/N, rad/(N·m)]. The
// Cartesian stiffness K = C⁻¹ exists only for 6 joints away from
// singularities; the translational stiffness (inverse of C's 3×3 block) for
// any robot whose linear-velocity Jacobian has rank 3.

#include <Eigen/Core>

#include "robomill/robot/robot_model.hpp"

namespace robomill::robot {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

/// C = J Kq⁻¹ Jᵀ (6×6) at the tool tip, cell frame (000 Eq 3).
Matrix6d cartesian_compliance(const RobotModel& model, const Eigen::VectorXd& q);

/// The translational block Jv Kq⁻¹ Jvᵀ (3×3, m/N).
Eigen::Matrix3d translational_compliance(const RobotModel& model, const Eigen::VectorXd& q);

/// Tip deflection [δp (m); δθ (rad)] = C w for a wrench w = [F (N); M (N·m)]
/// at the tool tip, cell frame (000 Eq 3, small deflections).
Vector6d deflection(const RobotModel& model, const Eigen::VectorXd& q, const Vector6d& wrench);

/// 000 Eq 3 in full: the deflection [δp; δθ] of a point c fixed to the tool
/// under a wrench w applied at another point e, Jc Kq⁻¹ Jeᵀ w, both points
/// given as offsets from the tool tip in the tool frame (point_jacobian).
/// With both offsets zero this is deflection(). The wrench's moment is about
/// e; cell frame throughout.
Vector6d deflection_between(const RobotModel& model, const Eigen::VectorXd& q,
                            const Eigen::Vector3d& measured_offset_tool_m,
                            const Eigen::Vector3d& loaded_offset_tool_m, const Vector6d& wrench);

/// K = C⁻¹ = J⁻ᵀ Kq J⁻¹ (000 Eq 4). Throws std::invalid_argument when the
/// robot has fewer than 6 joints or J is singular at q (smallest singular
/// value below 1e-10 of the largest), pointing to translational_stiffness.
Matrix6d cartesian_stiffness(const RobotModel& model, const Eigen::VectorXd& q);

/// (Jv Kq⁻¹ Jvᵀ)⁻¹ (3×3, N/m). Throws std::invalid_argument when Jv has rank
/// below 3 (eigenvalue of the compliance block below 1e-12 of the largest).
Eigen::Matrix3d translational_stiffness(const RobotModel& model, const Eigen::VectorXd& q);

/// Principal stiffnesses of the translational stiffness (000 §2): the
/// eigenvalues (N/m, ascending) with unit eigenvectors as columns, and their
/// condition number max/min (≥ 1).
struct PrincipalStiffness {
  Eigen::Vector3d stiffness_n_per_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d directions = Eigen::Matrix3d::Identity();
  double condition_number = 1.0;
};

/// Throws like translational_stiffness.
PrincipalStiffness principal_stiffness(const RobotModel& model, const Eigen::VectorXd& q);

}  // namespace robomill::robot
