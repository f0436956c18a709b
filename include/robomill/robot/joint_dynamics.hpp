#pragma once
// Joint-space vibration model of a robot with rigid links and elastic joints
// (004 §3.1 Eq 1-2, 002 §2):
//
//   M(q) Δq̈ + C Δq̇ + K Δq = Jvᵀ F,    Δd = Jv Δq             (004 Eq 1, 2)
//
// M(q) is the joint-space mass matrix (KDL ChainDynParam::JntToMass), K =
// diag(Kq), Jv the linear-velocity Jacobian at the tool tip (cell frame).
//
// Damping C. Joints with an explicit damping c_j (N·m·s/rad) contribute
// c_j on the diagonal. Joints with the "derive" marker (-1) take modal
// damping with the
// description's modal_damping_ratio ζ: with the mass-normalized modes Φ
// (Φᵀ M Φ = I, Φᵀ K Φ = Ω²), C_modal = M Φ diag(2 ζ ω_i) Φᵀ M, so that
// Φᵀ C_modal Φ = diag(2 ζ ω_i): every mode gets exactly ζ. When only some
// joints derive, C = diag(explicit c_j) + (rows and columns of C_modal that
// belong to the deriving joints); this is then non-proportional.
//
// Modal damping ratios reported for any C: ζ_i = φ_iᵀ C φ_i / (2 ω_i), the
// diagonal of Φᵀ C Φ (off-diagonal coupling ignored; exact when C is modal or
// diagonalized by Φ, an approximation otherwise).
//
// Dependency note: tool_tip_modal_model returns a dynamics::ModalModel (the
// stability engine's input), so robot/ depends on dynamics/modal_model here.

#include <Eigen/Core>
#include <complex>
#include <vector>

#include "robomill/dynamics/modal_model.hpp"
#include "robomill/robot/robot_model.hpp"

namespace robomill::robot {

/// M(q) (n×n, kg·m², symmetric), KDL ChainDynParam (gravity plays no part).
Eigen::MatrixXd mass_matrix(const RobotModel& model, const Eigen::VectorXd& q);

/// K = diag(Kq) (n×n, N·m/rad), 004 Eq 1.
Eigen::MatrixXd joint_stiffness_matrix(const RobotModel& model);

/// C (n×n, N·m·s/rad) as described above. Throws std::invalid_argument like
/// robot_modes when modal damping is needed and M is not positive definite.
Eigen::MatrixXd joint_damping_matrix(const RobotModel& model, const Eigen::VectorXd& q);

/// The undamped modes of 004 Eq 1 at posture q: K φ = ω² M φ.
struct RobotModes {
  Eigen::VectorXd natural_frequencies_hz;  ///< ascending
  Eigen::VectorXd natural_rad_s;           ///< the same in rad/s
  /// Joint shapes as columns, mass-normalized (Φᵀ M Φ = I), rad/√(kg·m²);
  /// each column's largest-magnitude entry is positive.
  Eigen::MatrixXd joint_shapes;
  /// Tool-tip translational shapes Jv φ_i as columns (3×n, cell frame, 1/√kg).
  Eigen::Matrix<double, 3, Eigen::Dynamic> tip_shapes;
  /// ζ_i = φ_iᵀ C φ_i / (2 ω_i).
  Eigen::VectorXd damping_ratios;
};

/// Generalized eigen-solve of (K, M) (Eigen::GeneralizedSelfAdjointEigenSolver).
/// Throws std::invalid_argument if M(q) is not positive definite (a joint
/// that moves no mass: give the links' masses and inertias).
RobotModes robot_modes(const RobotModel& model, const Eigen::VectorXd& q);

/// Tool-tip receptance (m/N, 3×3, cell frame) at ω (rad/s):
/// H(ω) = Jv (K − ω² M + iω C)⁻¹ Jvᵀ (004 Eq 1-2 in the frequency domain).
/// At ω = 0 it is the translational compliance Jv Kq⁻¹ Jvᵀ. Throws
/// std::invalid_argument for a non-finite ω or an undamped resonance.
Eigen::Matrix3cd tool_tip_receptance(const RobotModel& model, const Eigen::VectorXd& q,
                                     double omega_rad_s);

/// The robot's modes as a dynamics::ModalModel at the tool tip in the milling
/// tool frame (x feed, z tool axis): shape_i = R · Jv φ_i with R =
/// cell_to_tool_frame (v_tool = R v_cell, orthonormal), frequency ω_i,
/// damping ratio ζ_i as above. Throws std::invalid_argument if R is not a
/// rotation or a mode's damping ratio is outside (0, 1) (e.g. no damping).
dynamics::ModalModel tool_tip_modal_model(const RobotModel& model, const Eigen::VectorXd& q,
                                          const Eigen::Matrix3d& cell_to_tool_frame);

/// One mode seen along one axis of the tool frame, as a single-DOF
/// oscillator: k_d = ω_i² / φ_d², m_d = 1 / φ_d² (φ_d the tool-frame tip
/// shape component along d).
struct DirectionalModalParameters {
  int mode = 0;  ///< 0-based, ascending frequency
  int axis = 0;  ///< 0 = x, 1 = y, 2 = z (tool frame)
  double natural_frequency_hz = 0.0;
  double damping_ratio = 0.0;
  double stiffness_n_per_m = 0.0;
  double mass_kg = 0.0;
};

/// For every mode and tool-frame axis where the mode moves the tip
/// (|φ_d| > 1e-9 · max_d |φ_d| of that mode; others would have infinite k
/// and are left out), ordered by mode then axis.
std::vector<DirectionalModalParameters> directional_modal_parameters(
    const RobotModel& model, const Eigen::VectorXd& q, const Eigen::Matrix3d& cell_to_tool_frame);

}  // namespace robomill::robot
