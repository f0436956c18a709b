#include "robomill/stability/floquet.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <unsupported/Eigen/MatrixFunctions>

namespace robomill::stability {

/// The step algebra of one discretization for n modes. Everything that
/// depends only on the structure and the step (e^{A0 h}, its powers, the FDM
/// integrals) is computed in set_delay(), once per speed; monodromy() then
/// spends its work on the steps where the tooth cuts.
class FloquetSolver::Kernel {
 public:
  virtual ~Kernel() = default;
  virtual void set_delay(double delay_s) = 0;
  virtual const Eigen::MatrixXd& monodromy(const CouplingSamples& coupling, double scale,
                                           const CouplingSamples* damping,
                                           double damping_scale) = 0;
};

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

/// Fixed sizes for N modes (Eigen::Dynamic: any number, sized at run time).
template <int N>
struct Dims {
  static constexpr int modes = N;
  static constexpr int state = N == Eigen::Dynamic ? Eigen::Dynamic : 2 * N;
  static constexpr int generator = N == Eigen::Dynamic ? Eigen::Dynamic : 4 * N;
};

bool is_zero(const Eigen::MatrixXd& m) {
  return m.isZero(0.0);
}

template <int N>
class FloquetKernel final : public FloquetSolver::Kernel {
  using Square = Eigen::Matrix<double, Dims<N>::state, Dims<N>::state>;    // 2n x 2n
  using Tall = Eigen::Matrix<double, Dims<N>::state, Dims<N>::modes>;      // 2n x n
  using Small = Eigen::Matrix<double, Dims<N>::modes, Dims<N>::modes>;     // n x n
  using Rows = Eigen::Matrix<double, Dims<N>::state, Eigen::Dynamic>;      // 2n x D
  using HalfRows = Eigen::Matrix<double, Dims<N>::modes, Eigen::Dynamic>;  // n x D
  using Generator = Eigen::Matrix<double, Dims<N>::generator, Dims<N>::generator>;

 public:
  FloquetKernel(FloquetMethod method, const ModalDynamics& dynamics, int steps)
      : method_(method), n_(static_cast<int>(dynamics.natural_rad_s.size())), m_(steps) {
    const int n = n_;
    a0_.setZero(2 * n, 2 * n);
    a0_.topRightCorner(n, n).setIdentity();
    a0_.bottomLeftCorner(n, n).diagonal() = -dynamics.natural_rad_s.array().square();
    a0_.bottomRightCorner(n, n).diagonal() =
        -2.0 * dynamics.damping_ratio.array() * dynamics.natural_rad_s.array();
    free_powers_.resize(static_cast<std::size_t>(m_ + 1));
    active_slots_.reserve(static_cast<std::size_t>(m_));
    slot_column_.resize(static_cast<std::size_t>(m_));
    free_step_.resize(static_cast<std::size_t>(m_));
    record_.resize(static_cast<std::size_t>(m_ + 1));
  }

  void set_delay(double delay_s) override {
    delay_s_ = delay_s;
    const double h = delay_s / m_;
    const int n = n_;
    Eigen::MatrixXd phi0, f1, f2, f3;
    polynomial_integrals(a0_, h, phi0, f1, f2, f3);
    // Free flight over r steps: (e^{A0 h})^r, r = 0 … m.
    free_powers_[0] = Square::Identity(2 * n, 2 * n);
    free_powers_[1] = phi0;
    for (int r = 2; r <= m_; ++r)
      free_powers_[static_cast<std::size_t>(r)].noalias() =
          free_powers_[1] * free_powers_[static_cast<std::size_t>(r - 1)];
    // Only the right n columns of the integrals act: the periodic and delayed
    // terms enter the accelerations, [0; ·]. Linear interpolation between
    // nodes k (weight 1 − s/h) and k+1 (s/h).
    delay_now_ = (f1 - f2 / h).rightCols(n);
    delay_next_ = (f2 / h).rightCols(n);
    if (method_ == FloquetMethod::fdm2) {
      // Lagrange parabola through s = −h, 0, h (nodes k−1, k, k+1).
      weight_prev_ = (f3 / (h * h) - f2 / (2.0 * h)).rightCols(n);
      weight_now_ = (f1 - 2.0 * f3 / (h * h)).rightCols(n);
      weight_next_ = (f3 / (h * h) + f2 / (2.0 * h)).rightCols(n);
    } else {
      weight_now_ = delay_now_;
      weight_next_ = delay_next_;
    }
  }

  const Eigen::MatrixXd& monodromy(const CouplingSamples& coupling, double scale,
                                   const CouplingSamples* damping, double damping_scale) override {
    const int n = n_;
    const int m = m_;
    const bool fdm2 = method_ == FloquetMethod::fdm2;
    const bool sdm = method_ == FloquetMethod::sdm;
    auto node = [&](const CouplingSamples& samples, int k) -> const Eigen::MatrixXd& {
      return samples.nodes[static_cast<std::size_t>(k)];
    };
    auto mean = [&](const CouplingSamples& samples, int k) -> const Eigen::MatrixXd& {
      return samples.means[static_cast<std::size_t>(k)];
    };
    // A node or step mean acts when its coupling or its damping is non-zero.
    auto node_acts = [&](int k) {
      return !is_zero(node(coupling, k)) || (damping && !is_zero(node(*damping, k)));
    };
    auto mean_acts = [&](int k) {
      return !is_zero(mean(coupling, k)) || (damping && !is_zero(mean(*damping, k)));
    };

    // Delayed position η_{−1−j} (history slot j) acts only through the
    // coupling of the steps that read it: node m−1−j for the full
    // discretization, the step means m−1−j and m−2−j for the semi-
    // discretization. A slot whose coupling is zero (the tooth is out of the
    // cut) is a zero column of the monodromy matrix, i.e. a zero multiplier:
    // leaving it out of the state keeps every non-zero multiplier and shrinks
    // the eigenproblem (to a few slots at low radial immersion).
    active_slots_.clear();
    for (int j = 0; j < m; ++j) {
      bool active;
      if (sdm) {
        active = !is_zero(mean(coupling, m - 1 - j)) ||
                 (m - 2 - j >= 0 && !is_zero(mean(coupling, m - 2 - j)));
      } else {
        active = !is_zero(node(coupling, m - 1 - j)) || (j == m - 1 && !is_zero(node(coupling, m)));
      }
      // FDM2's parabola reads η_{k−1} (slot 0) at every step.
      slot_column_[static_cast<std::size_t>(j)] = -1;
      if (active || (fdm2 && j == 0))
        active_slots_.push_back(j);
    }
    const int slot_count = static_cast<int>(active_slots_.size());
    const int history_column = 2 * n + (fdm2 ? n : 0);
    const int columns = history_column + slot_count * n;
    for (int a = 0; a < slot_count; ++a)
      slot_column_[static_cast<std::size_t>(active_slots_[static_cast<std::size_t>(a)])] =
          history_column + a * n;

    // A free step is e^{A0 h}: nothing it reads is coupled. Steps whose
    // position the final history keeps (η_{m−1−j} for an active slot j) end
    // a run of free steps.
    for (int k = 0; k < m; ++k) {
      bool acts;
      if (sdm) {
        acts = mean_acts(k);
      } else {
        acts = node_acts(k) || node_acts(k + 1) || (fdm2 && node_acts((k + m - 1) % m));
      }
      free_step_[static_cast<std::size_t>(k)] = !acts;
    }
    std::fill(record_.begin(), record_.end(), false);
    for (const int j : active_slots_)
      record_[static_cast<std::size_t>(m - 1 - j)] = true;

    // The state's rows over the kept initial components: x_0 = identity on
    // (η_0, η'_0); (η'_{−1} for FDM2); the active history slots.
    x_.setZero(2 * n, columns);
    x_.leftCols(2 * n).setIdentity();
    psi_.resize(columns, columns);
    // FDM2 reads the previous node's position and velocity: initially the
    // history slot 0 and the extra η'_{−1} component.
    if (fdm2) {
      previous_position_.setZero(n, columns);
      previous_position_.middleCols(slot_column_[0], n).setIdentity();
      previous_velocity_.setZero(n, columns);
      previous_velocity_.middleCols(2 * n, n).setIdentity();
    }
    bool previous_valid = true;

    auto record = [&](int k) {
      if (!record_[static_cast<std::size_t>(k)])
        return;
      // η_k becomes history slot m−1−k of the next period.
      psi_.middleRows(slot_column_[static_cast<std::size_t>(m - 1 - k)], n) = x_.topRows(n);
    };
    // The delayed term of step k: η_{k−m} is initial slot m−1−k and
    // η_{k+1−m} initial slot m−2−k (η_0, the first n columns, at k = m−1),
    // each an identity block, so a term W η is W added to that slot's columns.
    auto add_delayed = [&](int k, const Tall& old_weight, const Tall& new_weight) {
      const int old_column = slot_column_[static_cast<std::size_t>(m - 1 - k)];
      if (old_column >= 0)
        next_.middleCols(old_column, n) += old_weight;
      const int new_column = k == m - 1 ? 0 : slot_column_[static_cast<std::size_t>(m - 2 - k)];
      if (new_column >= 0)
        next_.middleCols(new_column, n) += new_weight;
    };

    int k = 0;
    while (k < m) {
      record(k);
      if (free_step_[static_cast<std::size_t>(k)]) {
        // A run of free steps up to the next step that acts or is kept.
        int r = 1;
        while (k + r < m && free_step_[static_cast<std::size_t>(k + r)] &&
               !record_[static_cast<std::size_t>(k + r)])
          ++r;
        if (fdm2) {
          previous_position_ = x_.topRows(n);
          previous_velocity_ = x_.bottomRows(n);
          previous_valid = r == 1;
        }
        next_.noalias() = free_powers_[static_cast<std::size_t>(r)] * x_;
        x_.swap(next_);
        k += r;
        continue;
      }
      if (sdm) {
        sdm_step(k, coupling, scale, damping, damping_scale, add_delayed);
      } else {
        // After a run of free steps node k−1 is uncoupled (the last free step
        // read it), so FDM2 does not need the skipped state x_{k−1}.
        if (fdm2 && !previous_valid && node_acts((k + m - 1) % m))
          throw std::logic_error("FloquetSolver: FDM2 step after a free run reads node k−1");
        fdm_step(k, coupling, scale, damping, damping_scale, add_delayed);
        previous_valid = true;
      }
      x_.swap(next_);
      ++k;
    }

    // Ψ restricted to the kept components, rows in the order of the columns.
    psi_.topRows(2 * n) = x_;
    if (fdm2)
      psi_.middleRows(2 * n, n) = previous_velocity_;  // η'_{m−1}
    return psi_;
  }

 private:
  // Full discretization (first or second order) of step k: x_{k+1} =
  // Φ0 x_k + Σ_nodes W_i Â_i x_i + delayed terms, implicit in x_{k+1} through
  // W_next Â_{k+1}. Â_i x = [0; P_i η − C_i η'], so W Â_i x = W[:, n:] (P_i η − C_i η').
  template <class AddDelayed>
  void fdm_step(int k, const CouplingSamples& coupling, double scale,
                const CouplingSamples* damping, double damping_scale, AddDelayed& add_delayed) {
    const int n = n_;
    const int m = m_;
    auto nodes = [](const CouplingSamples& samples, int i) -> const Eigen::MatrixXd& {
      return samples.nodes[static_cast<std::size_t>(i)];
    };
    p_now_ = scale * nodes(coupling, k);
    p_next_ = scale * nodes(coupling, k + 1);
    step_ = free_powers_[1];
    step_.leftCols(n).noalias() += weight_now_ * p_now_;
    if (damping)
      step_.rightCols(n).noalias() -= damping_scale * weight_now_ * nodes(*damping, k);
    next_.noalias() = step_ * x_;
    if (method_ == FloquetMethod::fdm2) {
      const int previous = (k + m - 1) % m;  // node k−1, periodic
      small_ = scale * nodes(coupling, previous);
      if (!small_.isZero(0.0)) {
        tall_.noalias() = weight_prev_ * small_;
        next_.noalias() += tall_ * previous_position_;
      }
      if (damping && !is_zero(nodes(*damping, previous))) {
        tall_.noalias() = damping_scale * weight_prev_ * nodes(*damping, previous);
        next_.noalias() -= tall_ * previous_velocity_;
      }
      previous_position_ = x_.topRows(n);
      previous_velocity_ = x_.bottomRows(n);
    }
    // Delayed term B̂ η = [0; −P η], linear between nodes k and k+1.
    tall_.noalias() = -delay_now_ * p_now_;
    tall2_.noalias() = -delay_next_ * p_next_;
    add_delayed(k, tall_, tall2_);
    lhs_.setIdentity(2 * n, 2 * n);
    lhs_.leftCols(n).noalias() -= weight_next_ * p_next_;
    if (damping)
      lhs_.rightCols(n).noalias() += damping_scale * weight_next_ * nodes(*damping, k + 1);
    lu_.compute(lhs_);
    x_.noalias() = lu_.solve(next_);  // x_ is free: the caller swaps next_ in
    next_.swap(x_);
  }

  // Semi-discretization of step k: exact solution of ẋ = (A0 + Ā_k) x +
  // B̄_k η_lin(t − τ) on the step, with η_lin linear between η_{k−m} and
  // η_{k−m+1}; B̄ = [0; −P̄].
  template <class AddDelayed>
  void sdm_step(int k, const CouplingSamples& coupling, double scale,
                const CouplingSamples* damping, double damping_scale, AddDelayed& add_delayed) {
    const int n = n_;
    const double h = delay_s_ / m_;
    p_now_ = scale * coupling.means[static_cast<std::size_t>(k)];
    // Van Loan with only the input columns B = [0; I]: the exponential of
    // [[A, B, 0], [0, 0, I], [0, 0, 0]] h has the top row
    // [e^{Ah}, ∫e^{A(h−s)} B ds, ∫e^{A(h−s)} B s ds].
    generator_.setZero(4 * n, 4 * n);
    auto a = generator_.topLeftCorner(2 * n, 2 * n);
    a = a0_;
    a.bottomLeftCorner(n, n) += p_now_;
    if (damping)
      a.bottomRightCorner(n, n) -= damping_scale * damping->means[static_cast<std::size_t>(k)];
    generator_.block(n, 2 * n, n, n).setIdentity();
    generator_.block(2 * n, 3 * n, n, n).setIdentity();
    generator_ *= h;
    exponential_ = generator_.exp();
    step_ = exponential_.topLeftCorner(2 * n, 2 * n);
    tall_.noalias() =
        -(exponential_.block(0, 2 * n, 2 * n, n) - exponential_.block(0, 3 * n, 2 * n, n) / h) *
        p_now_;
    tall2_.noalias() = -(exponential_.block(0, 3 * n, 2 * n, n) / h) * p_now_;
    next_.noalias() = step_ * x_;
    add_delayed(k, tall_, tall2_);
  }

  FloquetMethod method_;
  int n_;
  int m_;
  double delay_s_ = 0.0;
  Square a0_;
  std::vector<Square> free_powers_;
  Tall delay_now_, delay_next_, weight_prev_, weight_now_, weight_next_;
  // Workspace (sized on first use; reused while the state size stays).
  Rows x_, next_;
  HalfRows previous_position_, previous_velocity_;
  Square step_, lhs_;
  Tall tall_, tall2_;
  Small p_now_, p_next_, small_;
  Generator generator_, exponential_;
  Eigen::PartialPivLU<Square> lu_;
  Eigen::MatrixXd psi_;
  std::vector<int> active_slots_;
  std::vector<int> slot_column_;  // column of history slot j in the state, −1 when left out
  std::vector<bool> free_step_, record_;
};

/// The kernel with fixed-size matrices for the common mode counts.
std::unique_ptr<FloquetSolver::Kernel> make_kernel(FloquetMethod method,
                                                   const ModalDynamics& dynamics, int steps) {
  switch (dynamics.natural_rad_s.size()) {
    case 1:
      return std::make_unique<FloquetKernel<1>>(method, dynamics, steps);
    case 2:
      return std::make_unique<FloquetKernel<2>>(method, dynamics, steps);
    case 3:
      return std::make_unique<FloquetKernel<3>>(method, dynamics, steps);
    case 4:
      return std::make_unique<FloquetKernel<4>>(method, dynamics, steps);
    default:
      return std::make_unique<FloquetKernel<Eigen::Dynamic>>(method, dynamics, steps);
  }
}

}  // namespace

FloquetSolver::FloquetSolver(FloquetMethod method, const ModalDynamics& dynamics, int steps)
    : method_(method) {
  const auto modes = dynamics.natural_rad_s.size();
  if (modes < 1 || dynamics.damping_ratio.size() != modes) {
    throw std::invalid_argument("modal dynamics need matching frequencies and damping ratios");
  }
  if (steps < 1)
    throw std::invalid_argument("discretization needs at least one step");
  const int n = static_cast<int>(modes);
  state_size_ = 2 * n + steps * n + (method_ == FloquetMethod::fdm2 ? n : 0);
  steps_ = steps;
  kernel_ = make_kernel(method, dynamics, steps);
}

FloquetSolver::~FloquetSolver() = default;
FloquetSolver::FloquetSolver(FloquetSolver&&) noexcept = default;
FloquetSolver& FloquetSolver::operator=(FloquetSolver&&) noexcept = default;

void FloquetSolver::set_delay(double delay_s) {
  if (!(delay_s > 0.0) || !std::isfinite(delay_s))
    throw std::invalid_argument("delay must be positive");
  delay_set_ = true;
  kernel_->set_delay(delay_s);
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
  if (!delay_set_)
    throw std::logic_error("FloquetSolver::set_delay must be called first");
  if (static_cast<int>(coupling.means.size()) != steps_ ||
      static_cast<int>(coupling.nodes.size()) != steps_ + 1 ||
      (damping && (static_cast<int>(damping->means.size()) != steps_ ||
                   static_cast<int>(damping->nodes.size()) != steps_ + 1))) {
    throw std::invalid_argument("coupling samples do not match the discretization");
  }
  return kernel_->monodromy(coupling, scale, damping, damping_scale);
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
