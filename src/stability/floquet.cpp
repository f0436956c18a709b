#include "robomill/stability/floquet.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <unsupported/Eigen/MatrixFunctions>

namespace robomill::stability {
namespace {

// Van Loan: the exponential of an upper block-triangular generator yields the
// convolution integrals of e^{A s} with polynomials in s.
//   exp([[A, I, 0, 0], [0, 0, I, 0], [0, 0, 0, I], [0, 0, 0, 0]] h), top row:
//   [e^{Ah}, ∫e^{A(h−s)} ds, ∫e^{A(h−s)} s ds, ∫e^{A(h−s)} s²/2 ds].
void polynomial_integrals(const Eigen::MatrixXd& a, double h, Eigen::MatrixXd& exponential,
                          Eigen::MatrixXd& f1, Eigen::MatrixXd& f2, Eigen::MatrixXd& f3) {
  const Eigen::Index d = a.rows();
  Eigen::MatrixXd generator = Eigen::MatrixXd::Zero(4 * d, 4 * d);
  generator.topLeftCorner(d, d) = a;
  for (int b = 0; b < 3; ++b) {
    generator.block(b * d, (b + 1) * d, d, d) = Eigen::MatrixXd::Identity(d, d);
  }
  const Eigen::MatrixXd result = (generator * h).exp();
  exponential = result.block(0, 0, d, d);
  f1 = result.block(0, d, d, d);
  f2 = result.block(0, 2 * d, d, d);
  f3 = 2.0 * result.block(0, 3 * d, d, d);  // ∫ e^{A(h−s)} s² ds
}

}  // namespace

FloquetSolver::FloquetSolver(FloquetMethod method, const ModalDynamics& dynamics, int steps)
    : method_(method), modes_(static_cast<int>(dynamics.natural_rad_s.size())), steps_(steps) {
  if (modes_ < 1 || dynamics.damping_ratio.size() != modes_) {
    throw std::invalid_argument("modal dynamics need matching frequencies and damping ratios");
  }
  if (steps_ < 1)
    throw std::invalid_argument("discretization needs at least one step");
  const int n = modes_;
  state_size_ = 2 * n + steps_ * n + (method_ == FloquetMethod::fdm2 ? n : 0);
  a0_ = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  a0_.topRightCorner(n, n) = Eigen::MatrixXd::Identity(n, n);
  a0_.bottomLeftCorner(n, n) = (-dynamics.natural_rad_s.array().square()).matrix().asDiagonal();
  a0_.bottomRightCorner(n, n) =
      (-2.0 * dynamics.damping_ratio.array() * dynamics.natural_rad_s.array())
          .matrix()
          .asDiagonal();
  active_slots_.reserve(static_cast<std::size_t>(steps_));
  rows_x_.resize(2 * n, state_size_);
  rows_x_prev_.resize(n, state_size_);
  new_rows_.resize(2 * n, state_size_);
  solved_rows_.resize(2 * n, state_size_);
  lhs_.resize(2 * n, 2 * n);
  rhs_block_.resize(2 * n, 2 * n);
}

void FloquetSolver::set_delay(double delay_s) {
  if (!(delay_s > 0.0) || !std::isfinite(delay_s))
    throw std::invalid_argument("delay must be positive");
  delay_s_ = delay_s;
  const double h = delay_s / steps_;
  Eigen::MatrixXd f1, f2, f3;
  polynomial_integrals(a0_, h, phi0_, f1, f2, f3);
  // Linear interpolation between nodes k (weight 1 − s/h) and k+1 (s/h).
  delay_now_ = f1 - f2 / h;
  delay_next_ = f2 / h;
  if (method_ == FloquetMethod::fdm2) {
    // Lagrange parabola through s = −h, 0, h (nodes k−1, k, k+1).
    phi_prev_ = f3 / (h * h) - f2 / (2.0 * h);
    phi_now_ = f1 - 2.0 * f3 / (h * h);
    phi_next_ = f3 / (h * h) + f2 / (2.0 * h);
  } else {
    phi_prev_.resize(0, 0);
    phi_now_ = delay_now_;
    phi_next_ = delay_next_;
  }
}

void FloquetSolver::sdm_step_matrices(const Eigen::MatrixXd& mean_coupling,
                                      const Eigen::MatrixXd* mean_damping, double scale,
                                      double damping_scale) {
  // Semi-discretization: exact solution of ẋ = (A0 + Ā_k) x + B̄_k η_lin(t − τ)
  // on the step, with η_lin linear between η_{k−m} and η_{k−m+1}.
  const int n = modes_;
  const double h = delay_s_ / steps_;
  Eigen::MatrixXd a = a0_;
  a.bottomLeftCorner(n, n) += scale * mean_coupling;
  if (mean_damping != nullptr)
    a.bottomRightCorner(n, n) -= damping_scale * *mean_damping;
  Eigen::MatrixXd f1, f2, f3;
  polynomial_integrals(a, h, sdm_exp_, f1, f2, f3);
  // B̄ = [0; −P̄]: only the right half of the integrals matters.
  sdm_delay_a_ = -(f1 - f2 / h).rightCols(n) * (scale * mean_coupling);
  sdm_delay_b_ = -(f2 / h).rightCols(n) * (scale * mean_coupling);
}

FloquetResult FloquetSolver::solve(const CouplingSamples& coupling, double scale,
                                   const CouplingSamples* damping, double damping_scale) {
  const Eigen::MatrixXd& psi = monodromy(coupling, scale, damping, damping_scale);
  eigen_.compute(psi, /*computeEigenvectors=*/false);
  FloquetResult result;
  const auto& values = eigen_.eigenvalues();
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    if (std::abs(values[i]) > result.spectral_radius) {
      result.spectral_radius = std::abs(values[i]);
      result.critical_multiplier = values[i];
    }
  }
  return result;
}

const Eigen::MatrixXd& FloquetSolver::monodromy(const CouplingSamples& coupling, double scale,
                                                const CouplingSamples* damping,
                                                double damping_scale) {
  if (delay_s_ <= 0.0)
    throw std::logic_error("FloquetSolver::set_delay must be called first");
  if (static_cast<int>(coupling.means.size()) != steps_ ||
      static_cast<int>(coupling.nodes.size()) != steps_ + 1) {
    throw std::invalid_argument("coupling samples do not match the discretization");
  }
  const int n = modes_;
  const int m = steps_;
  const bool fdm2 = method_ == FloquetMethod::fdm2;

  // Delayed position η_{−1−j} (history slot j) acts only through the coupling
  // of the steps that read it: node m−1−j for the full discretization, the
  // step means m−1−j and m−2−j for the semi-discretization. A slot whose
  // coupling is zero (the tooth is out of the cut) is a zero column of the
  // monodromy matrix, i.e. a zero multiplier: leaving those slots out of the
  // state keeps every non-zero multiplier and shrinks the eigenproblem (to a
  // few slots at low radial immersion).
  active_slots_.clear();
  for (int j = 0; j < m; ++j) {
    bool active;
    if (method_ == FloquetMethod::sdm) {
      active = !coupling.means[static_cast<std::size_t>(m - 1 - j)].isZero(0.0) ||
               (m - 2 - j >= 0 && !coupling.means[static_cast<std::size_t>(m - 2 - j)].isZero(0.0));
    } else {
      active = !coupling.nodes[static_cast<std::size_t>(m - 1 - j)].isZero(0.0) ||
               (j == m - 1 && !coupling.nodes[static_cast<std::size_t>(m)].isZero(0.0));
    }
    // FDM2's parabola reads η_{k−1} (slot 0) at every step.
    if (active || (fdm2 && j == 0))
      active_slots_.push_back(j);
  }
  const int slot_count = static_cast<int>(active_slots_.size());
  const int columns = 2 * n + (fdm2 ? n : 0) + slot_count * n;
  const int history_column = 2 * n + (fdm2 ? n : 0);

  // Initial state = identity over the kept components: x_0, (η'_{−1}), and
  // the active history slots. history_ holds slot j (η_{−1−j}) at physical
  // block (head + j) mod m.
  rows_x_.setZero(2 * n, columns);
  rows_x_.leftCols(2 * n).setIdentity();
  history_.setZero(m * n, columns);
  for (int a = 0; a < slot_count; ++a) {
    history_.block(active_slots_[static_cast<std::size_t>(a)] * n, history_column + a * n, n, n)
        .setIdentity();
  }
  if (fdm2) {
    rows_x_prev_.setZero(n, columns);
    rows_x_prev_.middleCols(2 * n, n).setIdentity();
  }
  new_rows_.resize(2 * n, columns);
  solved_rows_.resize(2 * n, columns);
  int head = 0;
  auto history_rows = [&](int logical) {
    const int physical = (head + logical) % m;
    return history_.middleRows(physical * n, n);
  };

  for (int k = 0; k < m; ++k) {
    const Eigen::MatrixXd& p_now = coupling.nodes[static_cast<std::size_t>(k)];
    const Eigen::MatrixXd& p_next = coupling.nodes[static_cast<std::size_t>(k + 1)];
    // Delayed positions: η_{k−m} (slot m−1) and η_{k+1−m} (slot m−2, or η_k when m = 1).
    const auto delayed_old = history_rows(m - 1);
    if (method_ == FloquetMethod::sdm) {
      const Eigen::MatrixXd* mean_damping =
          damping ? &damping->means[static_cast<std::size_t>(k)] : nullptr;
      sdm_step_matrices(coupling.means[static_cast<std::size_t>(k)], mean_damping, scale,
                        damping_scale);
      new_rows_.noalias() = sdm_exp_ * rows_x_;
      new_rows_.noalias() += sdm_delay_a_ * delayed_old;
      if (m > 1) {
        new_rows_.noalias() += sdm_delay_b_ * history_rows(m - 2);
      } else {
        new_rows_.noalias() += sdm_delay_b_ * rows_x_.topRows(n);
      }
    } else {
      // Full discretization: x_{k+1} = Φ0 x_k + Σ_nodes W_i Â_i x_i + delayed terms,
      // implicit in x_{k+1} through W_next Â_{k+1}.
      // Â_i x = [0; P_i η − C_i η'], so W Â_i x = W[:, n:] (P_i η − C_i η').
      rhs_block_ = phi0_;
      rhs_block_.leftCols(n).noalias() += scale * phi_now_.rightCols(n) * p_now;
      if (damping) {
        rhs_block_.rightCols(n).noalias() -=
            damping_scale * phi_now_.rightCols(n) * damping->nodes[static_cast<std::size_t>(k)];
      }
      new_rows_.noalias() = rhs_block_ * rows_x_;
      if (fdm2) {
        const int previous = (k + m - 1) % m;  // node k−1, periodic
        const auto eta_prev = history_rows(0);
        new_rows_.noalias() += scale * phi_prev_.rightCols(n) *
                               coupling.nodes[static_cast<std::size_t>(previous)] * eta_prev;
        if (damping) {
          new_rows_.noalias() -= damping_scale * phi_prev_.rightCols(n) *
                                 damping->nodes[static_cast<std::size_t>(previous)] * rows_x_prev_;
        }
      }
      // Delayed term B̂ η = [0; −P η], linear between nodes k and k+1.
      new_rows_.noalias() -= scale * delay_now_.rightCols(n) * p_now * delayed_old;
      if (m > 1) {
        new_rows_.noalias() -= scale * delay_next_.rightCols(n) * p_next * history_rows(m - 2);
      } else {
        new_rows_.noalias() -= scale * delay_next_.rightCols(n) * p_next * rows_x_.topRows(n);
      }
      lhs_.setIdentity();
      lhs_.leftCols(n).noalias() -= scale * phi_next_.rightCols(n) * p_next;
      if (damping) {
        lhs_.rightCols(n).noalias() += damping_scale * phi_next_.rightCols(n) *
                                       damping->nodes[static_cast<std::size_t>(k + 1)];
      }
      lu_.compute(lhs_);
      solved_rows_.noalias() = lu_.solve(new_rows_);
      new_rows_.swap(solved_rows_);
    }
    // Shift: η_k enters the history, η_{k−m} leaves (its block is reused).
    head = (head + m - 1) % m;
    history_rows(0) = rows_x_.topRows(n);
    if (fdm2)
      rows_x_prev_ = rows_x_.bottomRows(n);
    rows_x_.swap(new_rows_);
  }

  // Ψ restricted to the kept components, rows in the order of the columns.
  psi_.resize(columns, columns);
  psi_.topRows(2 * n) = rows_x_;
  if (fdm2)
    psi_.middleRows(2 * n, n) = rows_x_prev_;
  for (int a = 0; a < slot_count; ++a) {
    psi_.middleRows(history_column + a * n, n) =
        history_rows(active_slots_[static_cast<std::size_t>(a)]);
  }
  return psi_;
}

double chatter_frequency_hz(std::complex<double> multiplier, double delay_s,
                            const dynamics::ModalModel& modes) {
  // μ = exp(iωτ) fixes ω only modulo the tooth-passing frequency, and a real
  // vibration carries the multiplier and its conjugate, so the candidates are
  // (n ± |arg μ|/2π)/τ for n = 0, 1, 2, …; the one where the structure is most
  // flexible dominates the vibration.
  const double base = std::abs(std::arg(multiplier)) / (2.0 * std::numbers::pi);  // [0, 0.5]
  const double tooth_hz = 1.0 / delay_s;
  const double highest = 1.5 * modes.highest_frequency_hz();
  double best_hz = base * tooth_hz;
  double best_flexibility = -1.0;
  for (int n = 0; (n - base) * tooth_hz <= highest || n < 2; ++n) {
    for (const double cycles : {n + base, n + 1 - base}) {
      const double candidate = cycles * tooth_hz;
      if (candidate <= 0.0)
        continue;
      const double flexibility =
          modes.receptance(2.0 * std::numbers::pi * candidate).cwiseAbs().maxCoeff();
      if (flexibility > best_flexibility) {
        best_flexibility = flexibility;
        best_hz = candidate;
      }
    }
  }
  return best_hz;
}

const char* bifurcation_name(std::complex<double> multiplier) noexcept {
  const double modulus = std::abs(multiplier);
  if (std::abs(multiplier.imag()) <= 1e-6 * modulus) {
    return multiplier.real() < 0.0 ? "flip" : "fold";
  }
  return "hopf";
}

}  // namespace robomill::stability
