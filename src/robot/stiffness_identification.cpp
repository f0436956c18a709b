#include "robomill/robot/stiffness_identification.hpp"

#include <Eigen/SVD>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace robomill::robot {
namespace {

// A column whose norm is below this fraction of the largest carries no
// information: that joint is never loaded (or never moves a measured point).
constexpr double kZeroColumn = 1e-12;
// Singular values of the column-scaled A below this are treated as zero
// (exact rank deficiency, as opposed to mere ill-conditioning).
constexpr double kRankTolerance = 1e-10;
// A joint "takes part" in a null or weak direction when its component of the
// (unit) right singular vector exceeds this.
constexpr double kInvolvedComponent = 0.1;

std::string sample_name(std::size_t i) {
  return "stiffness sample " + std::to_string(i + 1);
}

std::string joint_list(const std::vector<int>& joints) {
  std::string text;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    if (i > 0)
      text += i + 1 == joints.size() ? " and " : ", ";
    text += std::to_string(joints[i] + 1);
  }
  return text;
}

std::vector<int> involved_joints(const Eigen::VectorXd& direction) {
  std::vector<int> joints;
  for (Eigen::Index j = 0; j < direction.size(); ++j) {
    if (std::abs(direction[j]) > kInvolvedComponent)
      joints.push_back(static_cast<int>(j));
  }
  return joints;
}

// Checks one sample and returns the Je actually used.
const Eigen::MatrixXd& check_sample(const StiffnessSample& s, std::size_t i, Eigen::Index n) {
  const std::string which = sample_name(i) + ": ";
  const Eigen::MatrixXd& je = s.force_jacobian.size() == 0 ? s.jacobian : s.force_jacobian;
  if (s.jacobian.rows() != 3 && s.jacobian.rows() != 6)
    throw std::invalid_argument(which + "Jacobian must have 3 or 6 rows");
  if (je.rows() != 3 && je.rows() != 6)
    throw std::invalid_argument(which + "force Jacobian must have 3 or 6 rows");
  if (s.jacobian.cols() != n || je.cols() != n) {
    throw std::invalid_argument(which + "Jacobians must have " + std::to_string(n) +
                                " columns (one per joint, as in sample 1)");
  }
  if (s.load.size() != 3 && s.load.size() != 6)
    throw std::invalid_argument(which + "load must be a force (3) or a wrench (6)");
  if (s.load.size() > je.rows())
    throw std::invalid_argument(which + "a wrench needs a 6-row (force) Jacobian");
  if (s.displacement_m.size() != 3 && s.displacement_m.size() != 6)
    throw std::invalid_argument(which + "displacement must have 3 or 6 components");
  if (s.displacement_m.size() > s.jacobian.rows())
    throw std::invalid_argument(which + "a 6-component displacement needs a 6-row Jacobian");
  if (!s.jacobian.allFinite() || !je.allFinite() || !s.load.allFinite() ||
      !s.displacement_m.allFinite())
    throw std::invalid_argument(which + "has non-finite values");
  return je;
}

}  // namespace

StiffnessIdentification identify_joint_stiffness(const std::vector<StiffnessSample>& samples,
                                                 const StiffnessIdentificationOptions& options) {
  if (samples.empty())
    throw std::invalid_argument("stiffness identification needs at least one loading sample");
  if (!(options.max_condition_number >= 1.0))
    throw std::invalid_argument("condition-number limit must be at least 1");
  const Eigen::Index n = samples.front().jacobian.cols();
  if (n == 0)
    throw std::invalid_argument(sample_name(0) + ": Jacobian has no columns (joints)");
  Eigen::Index m = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    check_sample(samples[i], i, n);
    m += samples[i].displacement_m.size();
  }
  if (m < n) {
    throw std::invalid_argument("stiffness identification: " + std::to_string(m) +
                                " measured displacement components for " + std::to_string(n) +
                                " unknown joint stiffnesses; add postures or load directions");
  }

  // 000 Eq 3: Δx = Σ_j Jc,j (Je,jᵀ F) c_j — one row block per sample.
  Eigen::MatrixXd a(m, n);
  Eigen::VectorXd b(m);
  Eigen::Index row = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const StiffnessSample& s = samples[i];
    const Eigen::MatrixXd& je = check_sample(s, i, n);
    const Eigen::Index rows = s.displacement_m.size();
    const Eigen::VectorXd torque_nm = je.topRows(s.load.size()).transpose() * s.load;
    a.middleRows(row, rows) = s.jacobian.topRows(rows) * torque_nm.asDiagonal();
    b.segment(row, rows) = s.displacement_m;
    row += rows;
  }

  // Column scaling: the compliances are ~1e-7 and the columns carry m·N·m;
  // unit columns make the condition number and rank test unit-free.
  const Eigen::VectorXd column_norm = a.colwise().norm().transpose();
  const double largest_column = column_norm.maxCoeff();
  std::vector<int> unloaded;
  for (Eigen::Index j = 0; j < n; ++j) {
    if (!(column_norm[j] > kZeroColumn * largest_column))
      unloaded.push_back(static_cast<int>(j));
  }
  if (!unloaded.empty()) {
    throw std::invalid_argument(
        "stiffness identification: " + std::string(unloaded.size() > 1 ? "joints " : "joint ") +
        joint_list(unloaded) + (unloaded.size() > 1 ? " are" : " is") +
        " not observable: no load in these data produces a torque on " +
        (unloaded.size() > 1 ? "them" : "it") +
        " (or its rotation moves no measured coordinate); add load directions or postures");
  }
  const Eigen::VectorXd scale = column_norm.cwiseInverse();
  const Eigen::MatrixXd scaled = a * scale.asDiagonal();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& sigma = svd.singularValues();  // descending
  const double s_max = sigma[0];
  const double s_min = sigma[n - 1];
  if (!(s_min > kRankTolerance * s_max)) {
    // Name the joints of the null space: their compliances enter the data only
    // in fixed combinations.
    std::vector<bool> in_null(static_cast<std::size_t>(n), false);
    int nullity = 0;
    for (Eigen::Index l = 0; l < n; ++l) {
      if (sigma[l] > kRankTolerance * s_max)
        continue;
      ++nullity;
      for (int j : involved_joints(svd.matrixV().col(l)))
        in_null[static_cast<std::size_t>(j)] = true;
    }
    std::vector<int> joints;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (in_null[static_cast<std::size_t>(j)])
        joints.push_back(static_cast<int>(j));
    }
    throw std::invalid_argument(
        "stiffness identification: rank-deficient data (rank " + std::to_string(n - nullity) +
        " of " + std::to_string(n) + "): joints " + joint_list(joints) +
        " are not observable separately — these loads and postures move them only in a fixed "
        "combination; vary the postures and load directions");
  }
  const double condition = s_max / s_min;
  if (condition > options.max_condition_number) {
    std::ostringstream message;
    message << "stiffness identification: ill-conditioned data (condition number " << condition
            << " of the column-scaled system, limit " << options.max_condition_number
            << "); joints " << joint_list(involved_joints(svd.matrixV().col(n - 1)))
            << " are barely distinguishable: vary the postures and load directions";
    throw std::invalid_argument(message.str());
  }

  // Least squares on the scaled system, c = D y.
  const Eigen::VectorXd y = svd.solve(b);
  const Eigen::VectorXd c = scale.cwiseProduct(y);
  for (Eigen::Index j = 0; j < n; ++j) {
    if (!(c[j] > 0.0)) {
      std::ostringstream message;
      message << "joint " << j + 1
              << "'s stiffness is not identifiable from these data (fitted compliance " << c[j]
              << " rad/(N·m) is not positive)";
      throw std::invalid_argument(message.str());
    }
  }

  StiffnessIdentification result;
  result.compliance_rad_per_nm = c;
  result.stiffness_nm_per_rad = c.cwiseInverse();
  const Eigen::VectorXd residual = b - a * c;
  const double ss_residual = residual.squaredNorm();
  result.equations = static_cast<int>(m);
  result.degrees_of_freedom = static_cast<int>(m - n);
  result.rms_residual_m = std::sqrt(ss_residual / static_cast<double>(m));
  const double ss_total = b.squaredNorm();
  result.r_squared = ss_total > 0.0 ? 1.0 - ss_residual / ss_total : 0.0;
  result.condition_number = condition;
  result.residual_norm_m.resize(static_cast<Eigen::Index>(samples.size()));
  row = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Eigen::Index rows = samples[i].displacement_m.size();
    result.residual_norm_m[static_cast<Eigen::Index>(i)] = residual.segment(row, rows).norm();
    row += rows;
  }
  // Cov(c) = σ² D (A_sᵀ A_s)⁻¹ D = σ² D V Σ⁻² Vᵀ D; se(k) = se(c) / c² (delta method).
  result.stiffness_standard_error_nm_per_rad = Eigen::VectorXd::Zero(n);
  if (m > n) {
    const double sigma2 = ss_residual / static_cast<double>(m - n);
    const Eigen::MatrixXd v_over_s = svd.matrixV() * sigma.cwiseInverse().asDiagonal();
    for (Eigen::Index j = 0; j < n; ++j) {
      const double se_c = std::sqrt(sigma2) * scale[j] * v_over_s.row(j).norm();
      result.stiffness_standard_error_nm_per_rad[j] = se_c / (c[j] * c[j]);
    }
  }
  return result;
}

}  // namespace robomill::robot
