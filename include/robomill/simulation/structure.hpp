#pragma once
// The structure a simulation moves: a linear second-order system driven by
// the cutting force at the tool tip,
//
//   M q̈ + C q̇ + K q = L F,     u = Lᵀ q,                        (S)
//
// with q the generalized coordinates (n), F the force on the tool (3, tool
// frame) and u the tool-tip displacement (3). It covers every structural
// model of the issue:
//  * a modal model (dynamics/modal_model.hpp, several modes per direction or
//    general shapes): q the modal coordinates, M = I, K = diag(ωn²),
//    C = diag(2 ζ ωn), L = Φᵀ (mass-normalized shapes as rows);
//  * the 1-DOF and 2-DOF tool fixations of 002 Eq 32-33 (and a 3-DOF one):
//    q = (δx[, δy[, δz]]), the paper's M, C, K, L = [I 0]ᵀ;
//  * the joint-space robot (004 Eq 1) and the reduced 6-D model (002 Eq 23)
//    through their modal decomposition (io builds their ModalModel);
//  * a rigid fixation (002 Case A): n = 0, u ≡ 0.
//
// Time stepping uses the exact discretization of (S) over a step Δt with the
// force linearly interpolated inside the step (first-order hold):
//   z_{n+1} = Φ z_n + Γ0 F_n + Γ1 (F_{n+1} − F_n),   z = (q, q̇),
//   Φ = e^{AΔt}, Γ0 = ∫₀^Δt e^{Aσ} dσ B, Γ1 = (1/Δt) ∫₀^Δt (Δt − σ) e^{Aσ} dσ B,
// from one block matrix exponential (Van Loan 1978). For a force that is
// linear in time over the step this is exact whatever Δt: the accuracy of the
// linear part does not depend on the step.

#include <Eigen/Core>
#include <string>

#include "robomill/dynamics/modal_model.hpp"

namespace robomill::simulation {

/// (S) as matrices. Immutable once built by one of the factories below.
struct LinearStructure {
  Eigen::MatrixXd mass;         ///< M (n×n), symmetric positive definite
  Eigen::MatrixXd damping;      ///< C (n×n)
  Eigen::MatrixXd stiffness;    ///< K (n×n)
  Eigen::MatrixXd force_input;  ///< L (n×3): generalized force per tool-tip force
  std::string description;      ///< "rigid", "3 modes", "2-DOF fixation (002 Eq 33)"
  int size() const noexcept { return static_cast<int>(mass.rows()); }
  bool rigid() const noexcept { return mass.rows() == 0; }
};

/// 002 Case A: no structural compliance.
LinearStructure rigid_structure();

/// The modes of a modal model as (S) in modal coordinates.
LinearStructure modal_structure(const dynamics::ModalModel& modes);

/// 002 Eq 32 (n = 1, along x), Eq 33 (n = 2, x and y) or its 3-D extension:
/// M q̈ + C q̇ + K q = F restricted to the first n axes of the tool frame.
/// Throws std::invalid_argument when the sizes differ, n ∉ {1, 2, 3}, an
/// entry is not finite, M or K is not symmetric positive definite, or C is
/// not symmetric positive semi-definite.
LinearStructure fixation_structure(const Eigen::MatrixXd& mass, const Eigen::MatrixXd& damping,
                                   const Eigen::MatrixXd& stiffness);

/// Undamped natural frequencies of (S), det(K − ω² M) = 0, ascending, Hz.
Eigen::VectorXd natural_frequencies_hz(const LinearStructure& structure);

/// (S) discretized exactly over one step with a first-order hold of F.
struct DiscreteStructure {
  double step_s = 0.0;
  Eigen::MatrixXd transition;    ///< Φ (2n×2n)
  Eigen::MatrixXd hold;          ///< Γ0 (2n×3)
  Eigen::MatrixXd ramp;          ///< Γ1 (2n×3)
  Eigen::MatrixXd displacement;  ///< [Lᵀ 0] (3×2n): u = this · z
  Eigen::MatrixXd velocity;      ///< [0 Lᵀ] (3×2n): u̇ = this · z
  int state_size() const noexcept { return static_cast<int>(transition.rows()); }
};

/// Throws std::invalid_argument for a non-positive step, NumericalError if
/// the exponential is not finite.
DiscreteStructure discretize(const LinearStructure& structure, double step_s);

/// The static tool-tip compliance Lᵀ K⁻¹ L (3×3, m/N); zero for a rigid one.
Eigen::Matrix3d static_compliance(const LinearStructure& structure);

}  // namespace robomill::simulation
