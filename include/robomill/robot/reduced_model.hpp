#pragma once
// Reduced elasto-dynamic model of a robot at the tool tip (002 §2, Eq 8-23).
//
// A serial robot with n elastic joints (stiffness Kq, joint-space mass matrix
// M) is replaced by a d-dimensional mass-spring(-damper) system at the tool
// tip, d = 6 (translation + rotation) or d = 3 (translation only):
//
//   Mr δẗ + Dr δṫ + Kr δt = F                                    (002 Eq 23)
//
// Kr is the Cartesian stiffness seen at the tip, Kr = C⁻¹ with the compliance
// C = J Kq⁻¹ Jᵀ. Mr follows from the Rayleigh-Ritz approximation (002 §2.2):
// the vibration shapes are taken to be the static deformation shapes under a
// tip load, q = Jq δt (002 Eq 8/19), with Jq = Kq⁻¹ Jᵀ Kr (joint rotation per
// unit tip displacement), and Mr = Jqᵀ M Jq (002 Eq 10). Then Jqᵀ Kq Jq = Kr,
// as 002 states below Eq 9. The frequencies solve det(ω² Mr − Kr) = 0 (Eq 21).
//
// Where J is square and invertible the reduction is exact (Jq = J⁻¹, a change
// of coordinates); otherwise it restricts the motion to a d-dimensional
// subspace, so each reduced frequency is an upper bound of the same-rank full
// frequency (Rayleigh-Ritz / Cauchy interlacing).
//
// Units: J maps joint rad to tip [m; rad] (geometric Jacobian, linear rows
// first, as KDL and most texts order it); Kq in N·m/rad; M in kg·m²
// (rotational joints). Kr mixes N/m, N/rad and N·m/rad blocks; Mr mixes kg,
// kg·m and kg·m². Only Eigen is used: the caller supplies the matrices from
// whatever robot model it has.

#include <Eigen/Core>

namespace robomill::robot {

/// The reduced model at one posture. d = rows of the Jacobian (6 or 3).
struct ReducedModel {
  /// C = J Kq⁻¹ Jᵀ (d×d): tip displacement per unit tip load.
  Eigen::MatrixXd compliance;
  /// Kr = C⁻¹ (d×d), 002 Eq 10/23.
  Eigen::MatrixXd stiffness;
  /// Jq = Kq⁻¹ Jᵀ Kr (n×d): joint deflection (rad) per unit tip displacement,
  /// the static deformation shapes of 002 Eq 8/19.
  Eigen::MatrixXd deformation_shapes;
  /// Mr = Jqᵀ M Jq (d×d), 002 Eq 10.
  Eigen::MatrixXd mass;
  /// Dr = Jqᵀ Dq Jq (d×d); zero when no joint damping was given.
  Eigen::MatrixXd damping;
  /// Solutions of det(ω² Mr − Kr) = 0 (002 Eq 21), ascending, Hz.
  Eigen::VectorXd natural_frequencies_hz;
  /// Tip mode shapes (d×d), columns mass-normalized: Φᵀ Mr Φ = I, Φᵀ Kr Φ = diag(ω²).
  Eigen::MatrixXd mode_shapes;
  /// The same modes in joint space, Jq Φ (n×d), rad per unit modal coordinate.
  Eigen::MatrixXd joint_mode_shapes;
  /// ζ_i = φ_iᵀ Dr φ_i / (2 ω_i): the diagonal of the modal damping matrix
  /// (off-diagonal coupling ignored, exact for proportional damping); zero
  /// when no joint damping was given.
  Eigen::VectorXd damping_ratios;
};

/// The translational rows (first three) of a 6×n geometric Jacobian, for the
/// 3-D reduction. Throws std::invalid_argument unless the Jacobian has 6 rows.
Eigen::MatrixXd linear_jacobian(const Eigen::MatrixXd& jacobian);

/// C = J Kq⁻¹ Jᵀ (000 Eq 3 with Jc = Je, 002 §2.1). J is d×n, Kq the n
/// diagonal joint stiffnesses (N·m/rad). Throws std::invalid_argument on
/// mismatched sizes, non-finite entries or a stiffness that is not positive.
Eigen::MatrixXd compliance_from_jacobian(const Eigen::MatrixXd& jacobian,
                                         const Eigen::VectorXd& joint_stiffness_nm_per_rad);

/// Kr = C⁻¹. Throws std::invalid_argument when C is singular: its
/// diagonally scaled condition number (units-invariant) exceeds 1e12, as for
/// fewer than 6 joints in a 6-D reduction or a singular posture.
Eigen::MatrixXd stiffness_from_compliance(const Eigen::MatrixXd& compliance);

/// The reduced model of 002 §2 (Eq 8-23). `jacobian` is 6×n (6-D reduction)
/// or 3×n (translational reduction, see linear_jacobian); `joint_mass` the
/// n×n joint-space mass matrix, symmetric positive definite; `joint_damping`
/// an n×n symmetric positive semi-definite joint damping matrix (N·m·s/rad),
/// or empty for none. Throws std::invalid_argument on invalid input or a
/// singular compliance (the message suggests the 3-D reduction when n < 6).
ReducedModel reduce_model(const Eigen::MatrixXd& jacobian,
                          const Eigen::VectorXd& joint_stiffness_nm_per_rad,
                          const Eigen::MatrixXd& joint_mass,
                          const Eigen::MatrixXd& joint_damping = Eigen::MatrixXd());

/// Natural frequencies (Hz, ascending) of the full joint-space model
/// det(ω² M − diag(Kq)) = 0 (002 Eq 2/5 with Ktot = diag(Kq), Mtot = M).
Eigen::VectorXd joint_space_frequencies_hz(const Eigen::VectorXd& joint_stiffness_nm_per_rad,
                                           const Eigen::MatrixXd& joint_mass);

/// The reduced frequencies against the lowest d frequencies of the full model.
struct FrequencyComparison {
  Eigen::VectorXd reduced_hz;  ///< d reduced frequencies, ascending
  Eigen::VectorXd full_hz;     ///< the d lowest full-model frequencies
  /// (reduced − full) / full per mode; ≥ 0 up to round-off by Rayleigh-Ritz.
  Eigen::VectorXd relative_difference;
  double max_abs_relative_difference = 0.0;
};

/// Compares a reduced model with the full joint-space eigenproblem it came
/// from (same Kq and M). Throws std::invalid_argument on mismatched sizes.
FrequencyComparison compare_with_full_model(const ReducedModel& reduced,
                                            const Eigen::VectorXd& joint_stiffness_nm_per_rad,
                                            const Eigen::MatrixXd& joint_mass);

}  // namespace robomill::robot
