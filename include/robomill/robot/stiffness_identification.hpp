#pragma once
// Identification of the diagonal joint stiffness Kq from static loading tests
// (000 §6.1, model 000 Eq 3): a known load F at the tool tip, the tip
// displacement between the loaded and the unloaded state measured (laser
// tracker), at several postures and load directions. With joint compliances
// c_j = 1/k_j the displacement is
//
//   Δx = Jc diag(c) Jeᵀ F = Σ_j Jc,j (Je,jᵀ F) c_j                 (000 Eq 3)
//
// (Jc the Jacobian of the measured point, Je that of the loaded point; the
// same point in most tests), linear in c. Stacking all samples gives A c = b
// with A's column j = [Jc,j (Je,jᵀ F)] over the samples, b = [Δx]. It is
// solved by least squares on the column-scaled A (column-pivoting QR), after
// checking that every joint is observable and the problem well conditioned.

#include <Eigen/Core>
#include <vector>

namespace robomill::robot {

/// One loading test: one posture, one load, one measured displacement.
struct StiffnessSample {
  /// Jacobian of the measured point at the posture (Jc): 6×n geometric
  /// ([linear; angular] rows, m/rad and rad/rad) or its 3×n linear rows.
  Eigen::MatrixXd jacobian;
  /// Jacobian of the loaded point (Je) when it differs from the measured
  /// one; empty: the same as `jacobian`.
  Eigen::MatrixXd force_jacobian;
  /// Applied force (3, N) or wrench (6: force N, then moment N·m), base frame.
  /// A force loads the joints through the linear rows, τ = Je[0:3]ᵀ F.
  Eigen::VectorXd load;
  /// Measured loaded − unloaded displacement: 3 (m) or 6 (m, then rad) — the
  /// first rows of `jacobian`. Six-row samples mix m and rad in one norm:
  /// prefer positions unless the rotations are as well measured.
  Eigen::VectorXd displacement_m;
};

struct StiffnessIdentificationOptions {
  /// Refuse when the condition number of the column-scaled A exceeds this:
  /// noise in b is amplified up to that factor in the relative error of c,
  /// so 1e6 leaves nothing of a 0.1 % measurement.
  double max_condition_number = 1e6;
};

struct StiffnessIdentification {
  Eigen::VectorXd stiffness_nm_per_rad;   ///< k_j = 1/c_j, N·m/rad
  Eigen::VectorXd compliance_rad_per_nm;  ///< c_j, rad/(N·m)
  /// Standard error of each k_j by the delta method, se(k) = se(c) / c²,
  /// with Cov(c) = σ² (AᵀA)⁻¹, σ² = ‖r‖² / (m − n). Zero when m = n (no
  /// redundancy, unknown): see `degrees_of_freedom`.
  Eigen::VectorXd stiffness_standard_error_nm_per_rad;
  Eigen::VectorXd residual_norm_m;  ///< ‖Δx_measured − Δx_model‖ per sample
  double rms_residual_m = 0.0;      ///< √(‖r‖² / m) over all m equations
  /// Uncentered R² = 1 − ‖r‖² / ‖b‖² (the model has no intercept).
  double r_squared = 0.0;
  double condition_number = 0.0;  ///< of A with unit-norm columns
  int equations = 0;              ///< m, rows of A
  int degrees_of_freedom = 0;     ///< m − n
};

/// Identifies Kq (000 §6.1). Throws std::invalid_argument, with a message
/// naming the sample or joint, for: no samples; inconsistent sizes or
/// non-finite values; fewer equations than joints; a joint that no load
/// moves or joints that cannot be told apart (rank deficiency, named from the
/// null space); a scaled condition number above the limit; or a fitted
/// compliance ≤ 0 ("joint j's stiffness is not identifiable from these data").
StiffnessIdentification identify_joint_stiffness(
    const std::vector<StiffnessSample>& samples,
    const StiffnessIdentificationOptions& options = {});

}  // namespace robomill::robot
