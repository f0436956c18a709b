#include "robomill/robot/reduced_model.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace robomill::robot {
namespace {

// Above this diagonally scaled condition number C is treated as singular:
// Kr = C⁻¹ would carry fewer than 4 significant digits.
constexpr double kMaxComplianceCondition = 1e12;
// Relative asymmetry tolerated in a mass or damping matrix (round-off from
// the caller's dynamics code), before symmetrizing.
constexpr double kSymmetryTolerance = 1e-9;

void check_joint_stiffness(const Eigen::VectorXd& kq) {
  if (kq.size() == 0)
    throw std::invalid_argument("joint stiffness: at least one joint is needed");
  for (Eigen::Index i = 0; i < kq.size(); ++i) {
    if (!std::isfinite(kq[i]) || !(kq[i] > 0.0)) {
      throw std::invalid_argument("joint stiffness: joint " + std::to_string(i + 1) +
                                  " must be positive and finite (N·m/rad)");
    }
  }
}

// Validates a symmetric matrix of the joint space and returns its symmetric part.
Eigen::MatrixXd symmetric_joint_matrix(const Eigen::MatrixXd& a, Eigen::Index n,
                                       const std::string& what) {
  if (a.rows() != n || a.cols() != n) {
    throw std::invalid_argument(what + " must be " + std::to_string(n) + "x" + std::to_string(n) +
                                " (one row and column per joint), got " + std::to_string(a.rows()) +
                                "x" + std::to_string(a.cols()));
  }
  if (!a.allFinite())
    throw std::invalid_argument(what + " has non-finite entries");
  const double scale = a.cwiseAbs().maxCoeff();
  if ((a - a.transpose()).cwiseAbs().maxCoeff() > kSymmetryTolerance * scale)
    throw std::invalid_argument(what + " must be symmetric");
  return 0.5 * (a + a.transpose());
}

Eigen::MatrixXd checked_mass(const Eigen::MatrixXd& m, Eigen::Index n) {
  Eigen::MatrixXd mass = symmetric_joint_matrix(m, n, "joint mass matrix");
  if (Eigen::LLT<Eigen::MatrixXd>(mass).info() != Eigen::Success)
    throw std::invalid_argument("joint mass matrix must be positive definite");
  return mass;
}

double to_hz(double omega_squared) {
  // Round-off may leave a tiny negative eigenvalue of a PSD pencil: clamp it.
  return std::sqrt(std::max(omega_squared, 0.0)) / (2.0 * std::numbers::pi);
}

}  // namespace

Eigen::MatrixXd linear_jacobian(const Eigen::MatrixXd& jacobian) {
  if (jacobian.rows() != 6) {
    throw std::invalid_argument("linear_jacobian needs a 6×n geometric Jacobian, got " +
                                std::to_string(jacobian.rows()) + " rows");
  }
  return jacobian.topRows(3);
}

Eigen::MatrixXd compliance_from_jacobian(const Eigen::MatrixXd& jacobian,
                                         const Eigen::VectorXd& joint_stiffness_nm_per_rad) {
  check_joint_stiffness(joint_stiffness_nm_per_rad);
  if (jacobian.cols() != joint_stiffness_nm_per_rad.size()) {
    throw std::invalid_argument(
        "Jacobian has " + std::to_string(jacobian.cols()) + " columns but " +
        std::to_string(joint_stiffness_nm_per_rad.size()) + " joint stiffnesses were given");
  }
  if (jacobian.rows() == 0)
    throw std::invalid_argument("Jacobian has no rows");
  if (!jacobian.allFinite())
    throw std::invalid_argument("Jacobian has non-finite entries");
  // 000 Eq 3 / 002 §2.1: δt = J θ, θ = Kq⁻¹ τ, τ = Jᵀ F  ⇒  δt = J Kq⁻¹ Jᵀ F.
  const Eigen::MatrixXd scaled = jacobian * joint_stiffness_nm_per_rad.cwiseInverse().asDiagonal();
  const Eigen::MatrixXd c = scaled * jacobian.transpose();
  return 0.5 * (c + c.transpose());
}

Eigen::MatrixXd stiffness_from_compliance(const Eigen::MatrixXd& compliance) {
  const Eigen::Index d = compliance.rows();
  if (d == 0 || compliance.cols() != d)
    throw std::invalid_argument("compliance must be a non-empty square matrix");
  if (!compliance.allFinite())
    throw std::invalid_argument("compliance has non-finite entries");
  // C mixes m/N and rad/(N·m): scale by its diagonal so the singularity test
  // does not depend on the units (S C S has a unit diagonal).
  const Eigen::VectorXd diagonal = compliance.diagonal();
  if ((diagonal.array() <= 0.0).any()) {
    throw std::invalid_argument(
        "Cartesian compliance is singular: some tip direction is not moved by any joint");
  }
  const Eigen::VectorXd s = diagonal.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = s.asDiagonal() * compliance * s.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scaled, Eigen::EigenvaluesOnly);
  const double lowest = eigen.eigenvalues().minCoeff();
  const double highest = eigen.eigenvalues().maxCoeff();
  if (!(lowest > highest / kMaxComplianceCondition)) {
    throw std::invalid_argument(
        "Cartesian compliance is singular (scaled condition number above 1e12): the joints "
        "cannot move the tip in every direction of the reduction (fewer than " +
        std::to_string(d) + " joints, or a singular posture)");
  }
  Eigen::MatrixXd kr = Eigen::LLT<Eigen::MatrixXd>(scaled).solve(Eigen::MatrixXd::Identity(d, d));
  kr = s.asDiagonal() * kr * s.asDiagonal();  // C⁻¹ = S (S C S)⁻¹ S
  return 0.5 * (kr + kr.transpose());
}

ReducedModel reduce_model(const Eigen::MatrixXd& jacobian,
                          const Eigen::VectorXd& joint_stiffness_nm_per_rad,
                          const Eigen::MatrixXd& joint_mass, const Eigen::MatrixXd& joint_damping) {
  const Eigen::Index d = jacobian.rows();
  const Eigen::Index n = jacobian.cols();
  if (d != 6 && d != 3) {
    throw std::invalid_argument(
        "reduce_model needs a 6×n Jacobian (6-D reduction) or its 3×n "
        "linear rows (translational reduction), got " +
        std::to_string(d) + " rows");
  }
  ReducedModel model;
  model.compliance = compliance_from_jacobian(jacobian, joint_stiffness_nm_per_rad);
  const Eigen::MatrixXd mass = checked_mass(joint_mass, n);
  Eigen::MatrixXd damping = Eigen::MatrixXd::Zero(n, n);
  if (joint_damping.size() != 0)
    damping = symmetric_joint_matrix(joint_damping, n, "joint damping matrix");

  if (n < d) {
    throw std::invalid_argument(
        "a " + std::to_string(d) + "-D reduction needs at least " + std::to_string(d) +
        " joints, got " + std::to_string(n) +
        ": the Cartesian compliance is singular; use the translational 3-D reduction "
        "(linear_jacobian) for a robot with 3 to 5 joints");
  }
  model.stiffness = stiffness_from_compliance(model.compliance);

  // 002 Eq 8/19: the Rayleigh-Ritz shapes are the static deformations under a
  // tip load F = Kr δt: θ = Kq⁻¹ Jᵀ F = Kq⁻¹ Jᵀ Kr δt, so Jq = Kq⁻¹ Jᵀ Kr.
  model.deformation_shapes = joint_stiffness_nm_per_rad.cwiseInverse().asDiagonal() *
                             (jacobian.transpose() * model.stiffness);
  const Eigen::MatrixXd& jq = model.deformation_shapes;
  // 002 Eq 10: Mr = Jqᵀ Mtot Jq (and Jqᵀ Ktot Jq = Kr C Kr = Kr); damping alike.
  model.mass = jq.transpose() * mass * jq;
  model.mass = 0.5 * (model.mass + model.mass.transpose());
  model.damping = jq.transpose() * damping * jq;
  model.damping = 0.5 * (model.damping + model.damping.transpose());

  // 002 Eq 21: det(ω² Mr − Kr) = 0 as the symmetric-definite pencil Kr φ = ω² Mr φ.
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eigen(
      model.stiffness, model.mass, Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
  if (eigen.info() != Eigen::Success)
    throw std::invalid_argument("reduced mass matrix is not positive definite");
  model.natural_frequencies_hz = eigen.eigenvalues().unaryExpr(&to_hz);
  model.mode_shapes = eigen.eigenvectors();  // Φᵀ Mr Φ = I by construction
  model.joint_mode_shapes = jq * model.mode_shapes;
  model.damping_ratios = Eigen::VectorXd::Zero(d);
  for (Eigen::Index i = 0; i < d; ++i) {
    const double omega = 2.0 * std::numbers::pi * model.natural_frequencies_hz[i];
    if (omega > 0.0) {
      const auto phi = model.mode_shapes.col(i);
      model.damping_ratios[i] = phi.dot(model.damping * phi) / (2.0 * omega);
    }
  }
  return model;
}

Eigen::VectorXd joint_space_frequencies_hz(const Eigen::VectorXd& joint_stiffness_nm_per_rad,
                                           const Eigen::MatrixXd& joint_mass) {
  check_joint_stiffness(joint_stiffness_nm_per_rad);
  const Eigen::Index n = joint_stiffness_nm_per_rad.size();
  const Eigen::MatrixXd mass = checked_mass(joint_mass, n);
  // 002 Eq 2/5 with Ktot = diag(Kq), Mtot = M.
  const Eigen::MatrixXd k = joint_stiffness_nm_per_rad.asDiagonal();
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eigen(
      k, mass, Eigen::EigenvaluesOnly | Eigen::Ax_lBx);
  if (eigen.info() != Eigen::Success)
    throw std::invalid_argument("joint-space eigenproblem failed");
  return eigen.eigenvalues().unaryExpr(&to_hz);
}

FrequencyComparison compare_with_full_model(const ReducedModel& reduced,
                                            const Eigen::VectorXd& joint_stiffness_nm_per_rad,
                                            const Eigen::MatrixXd& joint_mass) {
  const Eigen::Index d = reduced.natural_frequencies_hz.size();
  if (reduced.deformation_shapes.rows() != joint_stiffness_nm_per_rad.size()) {
    throw std::invalid_argument("the reduced model has " +
                                std::to_string(reduced.deformation_shapes.rows()) + " joints but " +
                                std::to_string(joint_stiffness_nm_per_rad.size()) +
                                " joint stiffnesses were given");
  }
  const Eigen::VectorXd full = joint_space_frequencies_hz(joint_stiffness_nm_per_rad, joint_mass);
  if (full.size() < d)
    throw std::invalid_argument("the full model has fewer modes than the reduced one");
  FrequencyComparison comparison;
  comparison.reduced_hz = reduced.natural_frequencies_hz;
  comparison.full_hz = full.head(d);
  comparison.relative_difference = Eigen::VectorXd::Zero(d);
  for (Eigen::Index i = 0; i < d; ++i) {
    const double f = comparison.full_hz[i];
    comparison.relative_difference[i] = f > 0.0 ? (comparison.reduced_hz[i] - f) / f : 0.0;
  }
  comparison.max_abs_relative_difference =
      d > 0 ? comparison.relative_difference.cwiseAbs().maxCoeff() : 0.0;
  return comparison;
}

}  // namespace robomill::robot
