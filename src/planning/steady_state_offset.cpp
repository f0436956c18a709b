#include "robomill/planning/steady_state_offset.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "robomill/robot/joint_dynamics.hpp"
#include "robomill/robot/kinematics.hpp"

namespace robomill::planning {

std::string_view to_string(OffsetMeasure measure) noexcept {
  switch (measure) {
    case OffsetMeasure::peak:
      return "peak";
    case OffsetMeasure::vibration:
      return "vibration";
    case OffsetMeasure::rms:
      return "rms";
    case OffsetMeasure::mean:
      return "mean";
    case OffsetMeasure::startup:
      return "startup";
  }
  return "peak";
}

double OffsetResponse::measure(OffsetMeasure which) const noexcept {
  switch (which) {
    case OffsetMeasure::peak:
      return peak_m;
    case OffsetMeasure::vibration:
      return vibration_m;
    case OffsetMeasure::rms:
      return rms_m;
    case OffsetMeasure::mean:
      return mean_m;
    case OffsetMeasure::startup:
      return startup_m;
  }
  return peak_m;
}

void OffsetWorkspace::resize(int dof, const ForceHarmonics& harmonics) {
  if (dynamic_stiffness.rows() != dof) {
    dynamic_stiffness.resize(dof, dof);
    lu = Eigen::PartialPivLU<Eigen::MatrixXcd>(dof);
    generalized_force.resize(dof);
    joint_response.resize(dof);
  }
  const auto k = harmonics.coefficients.size();
  const auto m = static_cast<std::size_t>(harmonics.samples);
  if (tip_harmonics.size() != k)
    tip_harmonics.assign(k, Eigen::Vector3cd::Zero());
  if (joint_harmonics.rows() != dof || joint_harmonics.cols() != Eigen::Index(k))
    joint_harmonics.resize(dof, Eigen::Index(k));
  if (twiddle.size() != m) {
    twiddle.resize(m);
    for (std::size_t j = 0; j < m; ++j)
      twiddle[j] =
          std::polar(1.0, 2.0 * std::numbers::pi * static_cast<double>(j) / static_cast<double>(m));
    trajectory.assign(m, Eigen::Vector3d::Zero());
  }
}

PostureDynamics posture_dynamics(const robot::RobotModel& model, const Eigen::VectorXd& q) {
  PostureDynamics d;
  d.mass = robot::mass_matrix(model, q);
  d.damping = robot::joint_damping_matrix(model, q);
  d.stiffness = robot::joint_stiffness_matrix(model);
  d.jacobian = robot::tool_jacobian(model, q).topRows<3>();
  return d;
}

namespace {

// Measures of a sampled period of Δd(t).
OffsetResponse measures_of(const std::vector<Eigen::Vector3d>& trajectory,
                           const Eigen::Vector3d& mean_offset) {
  OffsetResponse r;
  r.mean_offset_m = mean_offset;
  r.mean_m = mean_offset.norm();
  double sum_squares = 0.0;
  for (const Eigen::Vector3d& d : trajectory) {
    r.peak_m = std::max(r.peak_m, d.norm());
    r.vibration_m = std::max(r.vibration_m, (d - mean_offset).norm());
    sum_squares += d.squaredNorm();
  }
  r.rms_m = std::sqrt(sum_squares / static_cast<double>(trajectory.size()));
  return r;
}

}  // namespace

namespace {

// The largest |Δd(t)|, t ≥ 0, when the cut starts on a robot at rest: the
// periodic steady state (workspace.trajectory, one period) plus the free
// response that cancels the steady state's initial joint deflection and rate.
// In state form z = (Δq, Δq̇), ż = A z, A = [0 I; −M⁻¹K −M⁻¹C], so the free
// response is V e^{Λt} V⁻¹ z0 with z0 = −(Δq_ss(0), Δq̇_ss(0)).
void startup_maximum(const PostureDynamics& dynamics, const ForceHarmonics& harmonics,
                     const OffsetWorkspace& workspace, OffsetResponse& response) {
  const int n = static_cast<int>(dynamics.mass.rows());
  const Eigen::LLT<Eigen::MatrixXd> mass(dynamics.mass);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  a.topRightCorner(n, n).setIdentity();
  a.bottomLeftCorner(n, n) = -mass.solve(dynamics.stiffness);
  a.bottomRightCorner(n, n) = -mass.solve(dynamics.damping);
  const Eigen::EigenSolver<Eigen::MatrixXd> eigen(a);
  if (eigen.info() != Eigen::Success)
    throw std::runtime_error("start-up offset: the state matrix's eigen-solve failed");
  // Steady-state joint deflection and rate at t = 0.
  Eigen::VectorXcd z0(2 * n);
  const int harmonic_count = harmonics.harmonics();
  for (int j = 0; j < n; ++j) {
    std::complex<double> q = workspace.joint_harmonics(j, 0), v = 0.0;
    for (int k = 1; k <= harmonic_count; ++k) {
      q += 2.0 * workspace.joint_harmonics(j, k).real();
      v += 2.0 * (std::complex<double>(0.0, k * harmonics.fundamental_rad_s) *
                  workspace.joint_harmonics(j, k))
                     .real();
    }
    z0[j] = -q.real();
    z0[n + j] = -v.real();
  }
  const Eigen::MatrixXcd& vectors = eigen.eigenvectors();
  const Eigen::VectorXcd weights = vectors.partialPivLu().solve(z0);
  const Eigen::VectorXcd& lambda = eigen.eigenvalues();
  // g_r = Jv V[0:n, r] w_r: the tip's share of each eigenvalue.
  std::vector<Eigen::Vector3cd> g(std::size_t(2 * n));
  std::vector<std::complex<double>> decay(std::size_t(2 * n)), step(std::size_t(2 * n));
  const double h = harmonics.period_s / harmonics.samples;
  for (int r = 0; r < 2 * n; ++r) {
    g[std::size_t(r)] =
        dynamics.jacobian.cast<std::complex<double>>() * vectors.col(r).head(n) * weights[r];
    decay[std::size_t(r)] = 1.0;
    step[std::size_t(r)] = std::exp(lambda[r] * h);
  }
  double best = 0.0, best_time = 0.0;
  const auto samples = static_cast<long>(harmonics.samples);
  // Stop when even the transient's envelope cannot lift the steady peak above
  // the maximum found (or after 10^7 samples, a guard for undamped models).
  for (long i = 0; i < 10'000'000; ++i) {
    Eigen::Vector3cd transient = Eigen::Vector3cd::Zero();
    double envelope = 0.0;
    for (int r = 0; r < 2 * n; ++r) {
      transient += g[std::size_t(r)] * decay[std::size_t(r)];
      envelope += g[std::size_t(r)].norm() * std::abs(decay[std::size_t(r)]);
      decay[std::size_t(r)] *= step[std::size_t(r)];
    }
    const double offset =
        (workspace.trajectory[std::size_t(i % samples)] + transient.real()).norm();
    if (offset > best) {
      best = offset;
      best_time = static_cast<double>(i) * h;
    }
    if (i >= samples && response.peak_m + envelope < best)
      break;
  }
  response.startup_m = best;
  response.startup_time_s = best_time;
}

}  // namespace

OffsetResponse steady_state_offset(const PostureDynamics& dynamics,
                                   const Eigen::Matrix3d& tool_to_cell,
                                   const ForceHarmonics& harmonics, OffsetWorkspace& workspace,
                                   bool with_startup) {
  const int n = static_cast<int>(dynamics.mass.rows());
  workspace.resize(n, harmonics);
  const auto& jv = dynamics.jacobian;
  const int harmonic_count = harmonics.harmonics();
  for (int k = 0; k <= harmonic_count; ++k) {
    const double omega = k * harmonics.fundamental_rad_s;
    // Eq 1 at the harmonic: (K − ω² M + iω C) ΔQ_k = Jvᵀ F_k.
    workspace.dynamic_stiffness.real() = dynamics.stiffness - omega * omega * dynamics.mass;
    workspace.dynamic_stiffness.imag() = omega * dynamics.damping;
    workspace.lu.compute(workspace.dynamic_stiffness);
    // F_k = R c_k in the cell frame (004 Eq 7: F_Ei = R_ni F').
    const Eigen::Vector3cd force =
        tool_to_cell.cast<std::complex<double>>() * harmonics.coefficients[std::size_t(k)];
    for (int j = 0; j < n; ++j)
      workspace.generalized_force[j] =
          jv(0, j) * force[0] + jv(1, j) * force[1] + jv(2, j) * force[2];
    workspace.joint_response = workspace.lu.solve(workspace.generalized_force);
    workspace.joint_harmonics.col(k) = workspace.joint_response;
    // Eq 2: Δd_k = Jv ΔQ_k.
    Eigen::Vector3cd tip = Eigen::Vector3cd::Zero();
    for (int j = 0; j < n; ++j)
      tip += jv.col(j).cast<std::complex<double>>() * workspace.joint_response[j];
    workspace.tip_harmonics[std::size_t(k)] = tip;
  }
  // One period at M instants: Δd(t_m) = Re Δd_0 + Σ 2 Re(Δd_k e^{2πi k m / M}).
  const int samples = harmonics.samples;
  const Eigen::Vector3d mean_offset = workspace.tip_harmonics[0].real();
  for (int m = 0; m < samples; ++m) {
    Eigen::Vector3d d = mean_offset;
    for (int k = 1; k <= harmonic_count; ++k) {
      const std::complex<double> e =
          workspace.twiddle[static_cast<std::size_t>((static_cast<long>(k) * m) % samples)];
      d += 2.0 * (workspace.tip_harmonics[std::size_t(k)] * e).real();
    }
    workspace.trajectory[std::size_t(m)] = d;
  }
  OffsetResponse response = measures_of(workspace.trajectory, mean_offset);
  if (with_startup)
    startup_maximum(dynamics, harmonics, workspace, response);
  return response;
}

OffsetResponse steady_state_offset_time_domain(const PostureDynamics& dynamics,
                                               const Eigen::Matrix3d& tool_to_cell,
                                               const cutting::MillingForceModel& force_model,
                                               double period_s, int steps_per_period,
                                               int max_periods, double tolerance, int* periods_used,
                                               bool from_rest) {
  if (steps_per_period < 4 || max_periods < 2 || !(period_s > 0.0))
    throw std::invalid_argument("steady_state_offset_time_domain: bad step or period count");
  const int n = static_cast<int>(dynamics.mass.rows());
  const Eigen::LLT<Eigen::MatrixXd> mass(dynamics.mass);
  const Eigen::MatrixXd mass_inverse = mass.solve(Eigen::MatrixXd::Identity(n, n));
  const auto& jv = dynamics.jacobian;
  const double spindle = force_model.process().spindle_rad_s;
  const double h = period_s / steps_per_period;
  auto generalized = [&](double t) -> Eigen::VectorXd {
    const Eigen::Vector3d f = tool_to_cell * force_model.at(spindle * t).force_n;
    return jv.transpose() * f;
  };
  auto acceleration = [&](double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
    return Eigen::VectorXd(mass_inverse *
                           (generalized(t) - dynamics.damping * v - dynamics.stiffness * q));
  };
  // Start from the static deflection under the mean force (fewer periods of
  // transient; the steady state does not depend on the start).
  Eigen::VectorXd mean_generalized = Eigen::VectorXd::Zero(n);
  for (int m = 0; m < steps_per_period; ++m)
    mean_generalized += generalized(m * h);
  mean_generalized /= steps_per_period;
  Eigen::VectorXd q = from_rest
                          ? Eigen::VectorXd(Eigen::VectorXd::Zero(n))
                          : Eigen::VectorXd(dynamics.stiffness.ldlt().solve(mean_generalized));
  Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
  double startup = 0.0, startup_time = 0.0;

  const auto samples = static_cast<std::size_t>(steps_per_period);
  std::vector<Eigen::Vector3d> previous(samples), current(samples);
  double t = 0.0;
  int period = 0;
  bool converged = false;
  for (; period < max_periods; ++period) {
    for (int m = 0; m < steps_per_period; ++m) {
      current[std::size_t(m)] = jv * q;
      if (current[std::size_t(m)].norm() > startup) {
        startup = current[std::size_t(m)].norm();
        startup_time = t;
      }
      // Classical fourth-order Runge-Kutta on (q, v).
      const Eigen::VectorXd k1q = v, k1v = acceleration(t, q, v);
      const Eigen::VectorXd k2q = v + 0.5 * h * k1v,
                            k2v = acceleration(t + 0.5 * h, q + 0.5 * h * k1q, k2q);
      const Eigen::VectorXd k3q = v + 0.5 * h * k2v,
                            k3v = acceleration(t + 0.5 * h, q + 0.5 * h * k2q, k3q);
      const Eigen::VectorXd k4q = v + h * k3v, k4v = acceleration(t + h, q + h * k3q, k4q);
      q += h / 6.0 * (k1q + 2.0 * k2q + 2.0 * k3q + k4q);
      v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
      t = (period * steps_per_period + m + 1) * h;
    }
    if (period > 0) {
      double change = 0.0, size = 0.0;
      for (std::size_t m = 0; m < current.size(); ++m) {
        change = std::max(change, (current[m] - previous[m]).norm());
        size = std::max(size, current[m].norm());
      }
      if (change <= tolerance * size) {
        converged = true;
        ++period;
        break;
      }
    }
    std::swap(previous, current);
  }
  if (periods_used)
    *periods_used = period;
  const std::vector<Eigen::Vector3d>& last = converged ? current : previous;
  Eigen::Vector3d mean_offset = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& d : last)
    mean_offset += d;
  mean_offset /= static_cast<double>(last.size());
  OffsetResponse response = measures_of(last, mean_offset);
  if (from_rest) {
    response.startup_m = startup;
    response.startup_time_s = startup_time;
  }
  return response;
}

}  // namespace robomill::planning
