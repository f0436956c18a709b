// Linear structures for the time-domain simulation and their exact
// discretization (see structure.hpp).

#include "robomill/simulation/structure.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>

#include "robomill/core/error.hpp"

namespace robomill::simulation {
namespace {

bool symmetric(const Eigen::MatrixXd& matrix) {
  const double scale = matrix.cwiseAbs().maxCoeff();
  return (matrix - matrix.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * (scale > 0 ? scale : 1.0);
}

void require_definite(const Eigen::MatrixXd& matrix, const char* name, bool semi) {
  if (!matrix.allFinite())
    throw std::invalid_argument(std::string(name) + " has a non-finite entry");
  if (!symmetric(matrix))
    throw std::invalid_argument(std::string(name) + " is not symmetric");
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(matrix, Eigen::EigenvaluesOnly);
  const double smallest = eigen.eigenvalues().minCoeff();
  const double largest = eigen.eigenvalues().cwiseAbs().maxCoeff();
  if (semi ? smallest < -1e-12 * largest : !(smallest > 1e-12 * largest)) {
    throw std::invalid_argument(std::string(name) + " is not positive " +
                                (semi ? "semi-definite" : "definite") + " (smallest eigenvalue " +
                                std::to_string(smallest) + ")");
  }
}

}  // namespace

LinearStructure rigid_structure() {
  LinearStructure s;
  s.mass.resize(0, 0);
  s.damping.resize(0, 0);
  s.stiffness.resize(0, 0);
  s.force_input.resize(0, 3);
  s.description = "rigid";
  return s;
}

LinearStructure modal_structure(const dynamics::ModalModel& modes) {
  const int n = modes.size();
  const Eigen::VectorXd omega = modes.natural_rad_s();
  const Eigen::VectorXd zeta = modes.damping_ratios();
  LinearStructure s;
  s.mass = Eigen::MatrixXd::Identity(n, n);
  s.stiffness = omega.cwiseAbs2().asDiagonal();
  s.damping = (2.0 * zeta.cwiseProduct(omega)).asDiagonal();
  s.force_input = modes.shape_matrix().transpose();
  s.description = std::to_string(n) + (n == 1 ? " mode" : " modes");
  return s;
}

LinearStructure fixation_structure(const Eigen::MatrixXd& mass, const Eigen::MatrixXd& damping,
                                   const Eigen::MatrixXd& stiffness) {
  const Eigen::Index n = mass.rows();
  if (n < 1 || n > 3 || mass.cols() != n || damping.rows() != n || damping.cols() != n ||
      stiffness.rows() != n || stiffness.cols() != n) {
    throw std::invalid_argument("a fixation needs square M, C, K of the same size 1, 2 or 3");
  }
  require_definite(mass, "M", false);
  require_definite(stiffness, "K", false);
  require_definite(damping, "C", true);
  LinearStructure s;
  s.mass = mass;
  s.damping = damping;
  s.stiffness = stiffness;
  s.force_input = Eigen::MatrixXd::Identity(n, 3);
  s.description = n == 1   ? "1-DOF fixation along x (002 Eq 32)"
                  : n == 2 ? "2-DOF fixation in x, y (002 Eq 33)"
                           : "3-DOF fixation in x, y, z";
  return s;
}

Eigen::VectorXd natural_frequencies_hz(const LinearStructure& structure) {
  if (structure.rigid())
    return Eigen::VectorXd();
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eigen(
      structure.stiffness, structure.mass, Eigen::EigenvaluesOnly);
  return eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt() / (2.0 * std::numbers::pi);
}

DiscreteStructure discretize(const LinearStructure& structure, double step_s) {
  if (!(step_s > 0.0) || !std::isfinite(step_s))
    throw std::invalid_argument("the time step must be positive and finite");
  const int n = structure.size();
  DiscreteStructure d;
  d.step_s = step_s;
  d.displacement = Eigen::MatrixXd::Zero(3, 2 * n);
  d.velocity = Eigen::MatrixXd::Zero(3, 2 * n);
  if (n == 0) {
    d.transition.resize(0, 0);
    d.hold.resize(0, 3);
    d.ramp.resize(0, 3);
    return d;
  }
  // First-order form ż = A z + B F with z = (q, q̇).
  const Eigen::MatrixXd mass_inverse = structure.mass.llt().solve(Eigen::MatrixXd::Identity(n, n));
  const int m = 2 * n;
  // Van Loan block: exp([[A, B, 0], [0, 0, I], [0, 0, 0]] Δt) holds
  // e^{AΔt}, ∫e^{Aσ}dσ B and ∫(Δt − σ) e^{Aσ}dσ B in its first block row.
  Eigen::MatrixXd block = Eigen::MatrixXd::Zero(m + 6, m + 6);
  block.block(0, n, n, n).setIdentity();
  block.block(n, 0, n, n) = -mass_inverse * structure.stiffness;
  block.block(n, n, n, n) = -mass_inverse * structure.damping;
  block.block(n, m, n, 3) = mass_inverse * structure.force_input;
  block.block(m, m + 3, 3, 3).setIdentity();
  const Eigen::MatrixXd exponential = (block * step_s).exp();
  if (!exponential.allFinite())
    throw NumericalError("the discretized structure is not finite (step too large?)");
  d.transition = exponential.block(0, 0, m, m);
  d.hold = exponential.block(0, m, m, 3);
  d.ramp = exponential.block(0, m + 3, m, 3) / step_s;
  d.displacement.leftCols(n) = structure.force_input.transpose();
  d.velocity.rightCols(n) = structure.force_input.transpose();
  return d;
}

Eigen::Matrix3d static_compliance(const LinearStructure& structure) {
  if (structure.rigid())
    return Eigen::Matrix3d::Zero();
  return structure.force_input.transpose() *
         structure.stiffness.ldlt().solve(structure.force_input);
}

}  // namespace robomill::simulation
