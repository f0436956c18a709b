#include "robomill/robot/joint_dynamics.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <kdl/chaindynparam.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/jntspaceinertiamatrix.hpp>
#include <numbers>
#include <stdexcept>
#include <string>

#include "robomill/robot/kinematics.hpp"

namespace robomill::robot {
namespace {

constexpr double kDeriveMarker = -1.0;  // JointProperties::damping_nms_per_rad

struct UndampedModes {
  Eigen::VectorXd omega2;  // ω_i², ascending
  Eigen::MatrixXd phi;     // mass-normalized columns
};

// K φ = ω² M φ with Φᵀ M Φ = I (Eigen normalizes the eigenvectors so for Ax_lBx).
UndampedModes undamped_modes(const RobotModel& model, const Eigen::MatrixXd& m) {
  const Eigen::LLT<Eigen::MatrixXd> llt(m);
  if (llt.info() != Eigen::Success || !(m.diagonal().minCoeff() > 0.0)) {
    throw std::invalid_argument(
        "robot modes: the joint-space mass matrix is not positive definite at this posture (a "
        "joint moves no mass or inertia); give the links' masses and inertias");
  }
  const Eigen::MatrixXd k = joint_stiffness_matrix(model);
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(
      k, m, Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
  if (ges.info() != Eigen::Success)
    throw std::runtime_error("robot modes: the generalized eigen-solve did not converge");
  UndampedModes u{ges.eigenvalues(), ges.eigenvectors()};
  for (int i = 0; i < u.phi.cols(); ++i) {
    Eigen::Index imax = 0;
    u.phi.col(i).cwiseAbs().maxCoeff(&imax);
    if (u.phi(imax, i) < 0.0)
      u.phi.col(i) *= -1.0;  // deterministic sign
  }
  return u;
}

bool any_derived(const RobotModel& model) {
  for (const JointProperties& j : model.joints())
    if (j.damping_nms_per_rad == kDeriveMarker)
      return true;
  return false;
}

// C from M (needed only when some joint derives its damping) and the modes.
Eigen::MatrixXd damping_from(const RobotModel& model, const Eigen::MatrixXd& m,
                             const UndampedModes* modes) {
  const int n = model.dof();
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n, n);
  Eigen::MatrixXd c_modal;
  if (modes != nullptr) {
    // C_modal = M Φ diag(2 ζ ω_i) Φᵀ M, so Φᵀ C_modal Φ = diag(2 ζ ω_i).
    const double zeta = model.description().modal_damping_ratio;
    const Eigen::VectorXd two_zeta_omega = 2.0 * zeta * modes->omega2.cwiseSqrt();
    const Eigen::MatrixXd mphi = m * modes->phi;
    c_modal = mphi * two_zeta_omega.asDiagonal() * mphi.transpose();
  }
  for (int i = 0; i < n; ++i) {
    const double ci = model.joints()[static_cast<std::size_t>(i)].damping_nms_per_rad;
    if (ci != kDeriveMarker) {
      c(i, i) += ci;
      continue;
    }
    for (int j = 0; j < n; ++j) {
      if (model.joints()[static_cast<std::size_t>(j)].damping_nms_per_rad == kDeriveMarker)
        c(i, j) = c_modal(i, j);
    }
  }
  return 0.5 * (c + c.transpose());
}

Eigen::Matrix<double, 3, Eigen::Dynamic> tip_linear_jacobian(const RobotModel& model,
                                                             const Eigen::VectorXd& q) {
  return tool_jacobian(model, q).topRows<3>();
}

void check_rotation(const Eigen::Matrix3d& r) {
  if (!r.allFinite() || (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() > 1e-9 ||
      r.determinant() < 0.0) {
    throw std::invalid_argument(
        "cell_to_tool_frame must be a rotation matrix (orthonormal, det +1)");
  }
}

}  // namespace

Eigen::MatrixXd mass_matrix(const RobotModel& model, const Eigen::VectorXd& q) {
  if (q.size() != model.dof() || !q.allFinite())
    throw std::invalid_argument("mass_matrix: expected " + std::to_string(model.dof()) +
                                " finite joint values");
  KDL::ChainDynParam dyn(model.chain(), KDL::Vector::Zero());
  KDL::JntArray jq(static_cast<unsigned>(q.size()));
  jq.data = q;
  KDL::JntSpaceInertiaMatrix h(static_cast<unsigned>(q.size()));
  if (dyn.JntToMass(jq, h) < 0)
    throw std::runtime_error("mass_matrix: KDL ChainDynParam::JntToMass failed");
  const Eigen::MatrixXd m = h.data;
  return 0.5 * (m + m.transpose());
}

Eigen::MatrixXd joint_stiffness_matrix(const RobotModel& model) {
  return model.joint_stiffness().asDiagonal();
}

Eigen::MatrixXd joint_damping_matrix(const RobotModel& model, const Eigen::VectorXd& q) {
  const Eigen::MatrixXd m = mass_matrix(model, q);
  if (!any_derived(model))
    return damping_from(model, m, nullptr);
  const UndampedModes modes = undamped_modes(model, m);
  return damping_from(model, m, &modes);
}

RobotModes robot_modes(const RobotModel& model, const Eigen::VectorXd& q) {
  const Eigen::MatrixXd m = mass_matrix(model, q);
  const UndampedModes u = undamped_modes(model, m);
  const Eigen::MatrixXd c = damping_from(model, m, any_derived(model) ? &u : nullptr);
  RobotModes r;
  r.natural_rad_s = u.omega2.cwiseMax(0.0).cwiseSqrt();
  r.natural_frequencies_hz = r.natural_rad_s / (2.0 * std::numbers::pi);
  r.joint_shapes = u.phi;
  r.tip_shapes = tip_linear_jacobian(model, q) * u.phi;
  // ζ_i = φ_iᵀ C φ_i / (2 ω_i): diagonal of the modal damping matrix.
  r.damping_ratios =
      (u.phi.transpose() * c * u.phi).diagonal().cwiseQuotient(2.0 * r.natural_rad_s);
  return r;
}

Eigen::Matrix3cd tool_tip_receptance(const RobotModel& model, const Eigen::VectorXd& q,
                                     double omega_rad_s) {
  if (!std::isfinite(omega_rad_s))
    throw std::invalid_argument("tool_tip_receptance: ω must be finite");
  const Eigen::MatrixXd m = mass_matrix(model, q);
  Eigen::MatrixXd c;
  if (any_derived(model)) {
    const UndampedModes u = undamped_modes(model, m);
    c = damping_from(model, m, &u);
  } else {
    c = damping_from(model, m, nullptr);
  }
  // Dynamic stiffness of 004 Eq 1 under Δq = Δq̂ e^{iωt}; Eq 2 maps to the tip.
  const Eigen::MatrixXcd z =
      (joint_stiffness_matrix(model) - omega_rad_s * omega_rad_s * m).cast<std::complex<double>>() +
      std::complex<double>(0.0, omega_rad_s) * c.cast<std::complex<double>>();
  const Eigen::Matrix<double, 3, Eigen::Dynamic> jv = tip_linear_jacobian(model, q);
  const Eigen::MatrixXcd jvt = jv.transpose().cast<std::complex<double>>();
  const Eigen::MatrixXcd x = z.fullPivLu().solve(jvt);
  const Eigen::Matrix3cd h = jv.cast<std::complex<double>>() * x;
  if (!h.allFinite())
    throw std::invalid_argument(
        "tool_tip_receptance: undamped resonance at ω = " + std::to_string(omega_rad_s) + " rad/s");
  return h;
}

dynamics::ModalModel tool_tip_modal_model(const RobotModel& model, const Eigen::VectorXd& q,
                                          const Eigen::Matrix3d& cell_to_tool_frame) {
  check_rotation(cell_to_tool_frame);
  const RobotModes modes = robot_modes(model, q);
  std::vector<dynamics::Mode> out;
  for (int i = 0; i < modes.natural_rad_s.size(); ++i) {
    const double zeta = modes.damping_ratios[i];
    if (!(zeta > 0.0 && zeta < 1.0)) {
      throw std::invalid_argument("robot mode " + std::to_string(i + 1) + " (" +
                                  std::to_string(modes.natural_frequencies_hz[i]) +
                                  " Hz): damping ratio " + std::to_string(zeta) +
                                  " is outside (0, 1); give joint damping or modal_damping_ratio");
    }
    dynamics::Mode mode;
    mode.natural_frequency_hz = modes.natural_frequencies_hz[i];
    mode.damping_ratio = zeta;
    mode.shape = cell_to_tool_frame * modes.tip_shapes.col(i);
    out.push_back(mode);
  }
  return dynamics::ModalModel(std::move(out));
}

std::vector<DirectionalModalParameters> directional_modal_parameters(
    const RobotModel& model, const Eigen::VectorXd& q, const Eigen::Matrix3d& cell_to_tool_frame) {
  check_rotation(cell_to_tool_frame);
  const RobotModes modes = robot_modes(model, q);
  std::vector<DirectionalModalParameters> out;
  for (int i = 0; i < modes.natural_rad_s.size(); ++i) {
    const Eigen::Vector3d phi = cell_to_tool_frame * modes.tip_shapes.col(i);
    const double largest = phi.cwiseAbs().maxCoeff();
    for (int d = 0; d < 3; ++d) {
      if (!(std::abs(phi[d]) > 1e-9 * largest))
        continue;
      DirectionalModalParameters p;
      p.mode = i;
      p.axis = d;
      p.natural_frequency_hz = modes.natural_frequencies_hz[i];
      p.damping_ratio = modes.damping_ratios[i];
      p.mass_kg = 1.0 / (phi[d] * phi[d]);
      p.stiffness_n_per_m = modes.natural_rad_s[i] * modes.natural_rad_s[i] * p.mass_kg;
      out.push_back(p);
    }
  }
  return out;
}

}  // namespace robomill::robot
