#include "robomill/robot/stiffness.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <stdexcept>
#include <string>

#include "robomill/robot/kinematics.hpp"

namespace robomill::robot {
namespace {

// Relative thresholds below which a Jacobian (singular values) or a
// compliance block (eigenvalues) counts as singular.
constexpr double kJacobianRankTolerance = 1e-10;
constexpr double kComplianceRankTolerance = 1e-12;

// Symmetric 3×3 eigen decomposition of the translational compliance, with a
// rank check; the stiffness shares its eigenvectors, with inverted values.
Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> decompose_translational(const RobotModel& model,
                                                                       const Eigen::VectorXd& q) {
  const Eigen::Matrix3d c = translational_compliance(model, q);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(c);
  const Eigen::Vector3d lambda = eig.eigenvalues();  // ascending
  if (!(lambda[0] > kComplianceRankTolerance * lambda[2])) {
    throw std::invalid_argument(
        "translational stiffness: the posture is singular (the tool tip cannot move in every "
        "direction); the compliance block has eigenvalues " +
        std::to_string(lambda[0]) + ", " + std::to_string(lambda[1]) + ", " +
        std::to_string(lambda[2]) + " m/N");
  }
  return eig;
}

}  // namespace

Matrix6d cartesian_compliance(const RobotModel& model, const Eigen::VectorXd& q) {
  const Eigen::Matrix<double, 6, Eigen::Dynamic> j = tool_jacobian(model, q);
  const Eigen::VectorXd kq_inv = model.joint_stiffness().cwiseInverse();
  Matrix6d c = j * kq_inv.asDiagonal() * j.transpose();
  return 0.5 * (c + c.transpose());  // exactly symmetric
}

Eigen::Matrix3d translational_compliance(const RobotModel& model, const Eigen::VectorXd& q) {
  return cartesian_compliance(model, q).topLeftCorner<3, 3>();
}

Vector6d deflection(const RobotModel& model, const Eigen::VectorXd& q, const Vector6d& wrench) {
  if (!wrench.allFinite())
    throw std::invalid_argument("deflection: the wrench must be finite");
  return cartesian_compliance(model, q) * wrench;
}

Vector6d deflection_between(const RobotModel& model, const Eigen::VectorXd& q,
                            const Eigen::Vector3d& measured_offset_tool_m,
                            const Eigen::Vector3d& loaded_offset_tool_m, const Vector6d& wrench) {
  if (!wrench.allFinite())
    throw std::invalid_argument("deflection: the wrench must be finite");
  const Eigen::MatrixXd jc = point_jacobian(model, q, measured_offset_tool_m);
  const Eigen::MatrixXd je = point_jacobian(model, q, loaded_offset_tool_m);
  return jc * (model.joint_stiffness().cwiseInverse().asDiagonal() * (je.transpose() * wrench));
}

Matrix6d cartesian_stiffness(const RobotModel& model, const Eigen::VectorXd& q) {
  if (model.dof() < 6) {
    throw std::invalid_argument(
        "cartesian stiffness: the robot has " + std::to_string(model.dof()) +
        " joints (< 6), so its 6x6 compliance is singular; use the translational stiffness");
  }
  const Eigen::Matrix<double, 6, Eigen::Dynamic> j = tool_jacobian(model, q);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(j);
  const Eigen::VectorXd s = svd.singularValues();
  if (!(s[5] > kJacobianRankTolerance * s[0])) {
    throw std::invalid_argument(
        "cartesian stiffness: the posture is singular (Jacobian singular values " +
        std::to_string(s[0]) + " ... " + std::to_string(s[5]) +
        "); use the translational stiffness");
  }
  if (model.dof() > 6) {
    // Redundant robot: C is still invertible when J has rank 6.
    Matrix6d c = cartesian_compliance(model, q);
    return c.ldlt().solve(Matrix6d::Identity());
  }
  // Square J: C⁻¹ = J⁻ᵀ Kq J⁻¹ without forming C (000 Eq 4).
  const Matrix6d js = j;
  const Eigen::PartialPivLU<Matrix6d> lu(js);
  const Matrix6d j_inv = lu.inverse();
  Matrix6d k = j_inv.transpose() * model.joint_stiffness().asDiagonal() * j_inv;
  return 0.5 * (k + k.transpose());
}

Eigen::Matrix3d translational_stiffness(const RobotModel& model, const Eigen::VectorXd& q) {
  const auto eig = decompose_translational(model, q);
  return eig.eigenvectors() * eig.eigenvalues().cwiseInverse().asDiagonal() *
         eig.eigenvectors().transpose();
}

PrincipalStiffness principal_stiffness(const RobotModel& model, const Eigen::VectorXd& q) {
  const auto eig = decompose_translational(model, q);
  PrincipalStiffness p;
  // Compliance eigenvalues ascending → stiffness eigenvalues descending:
  // reverse both to report stiffness ascending.
  for (int i = 0; i < 3; ++i) {
    p.stiffness_n_per_m[i] = 1.0 / eig.eigenvalues()[2 - i];
    p.directions.col(i) = eig.eigenvectors().col(2 - i);
  }
  p.condition_number = p.stiffness_n_per_m[2] / p.stiffness_n_per_m[0];
  return p;
}

}  // namespace robomill::robot
