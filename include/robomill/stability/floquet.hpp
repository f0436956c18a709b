#pragma once
// Time-domain stability of the regenerative delay model by discretizing one
// tooth period into m steps and building the Floquet transition (monodromy)
// matrix of the augmented state; the cut is stable when every characteristic
// multiplier lies inside the unit circle.
//
// State x = (η, η') of the n modal coordinates; with h = τ/m and A0 the
// constant modal dynamics [[0, I], [−Ω², −2ζΩ]], the periodic part
// A(t) x = [0; P(t) η − Cp(t) η'] and the delayed part B(t) η(t − τ) = [0; −P(t) η(t − τ)]:
//  * SDM  — first-order semi-discretization (Insperger & Stépán 2004): on each
//           step A(t) is replaced by its mean and solved exactly (matrix
//           exponential of A0 + Ā_k); the delayed state is interpolated
//           linearly between η_{k−m} and η_{k−m+1}.
//  * FDM  — first-order full-discretization (Ding et al. 2010): the constant
//           part is solved exactly; A(t)x(t) and B(t)η(t−τ) are interpolated
//           linearly between the step's nodes.
//  * FDM2 — second-order full-discretization (Ding et al. 2010): A(t)x(t) is
//           interpolated by the Lagrange parabola through nodes k−1, k, k+1.
// Only positions are delayed, so the augmented state holds x_k (2n), for FDM2
// also x_{k−1}, and the m delayed positions η_{k−1} … η_{k−m}. The monodromy
// matrix is assembled block row by block row: each step computes only the new
// state's rows and shifts the history by index (no multiplication of the
// identity blocks of the shift).

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <complex>
#include <memory>
#include <vector>

#include "robomill/stability/regenerative_model.hpp"

namespace robomill::stability {

enum class FloquetMethod { sdm, fdm, fdm2 };

struct FloquetResult {
  double spectral_radius = 0.0;
  std::complex<double> critical_multiplier;  ///< the multiplier of largest modulus
};

/// Modal dynamics of the structure: ωn and ζ per mode, plus optional constant
/// extra viscous damping in modal coordinates (process damping, n x n).
struct ModalDynamics {
  Eigen::VectorXd natural_rad_s;
  Eigen::VectorXd damping_ratio;
};

/// A reusable workspace for one thread: sized once for n modes and m steps.
///
/// Cost (the stability issue's speed work, docs/stability-speed.md): a step
/// whose coupling (and process damping) is zero — the tooth out of the cut —
/// is the free flight x_{k+1} = e^{A0 h} x_k, so a run of r such steps is one
/// product with (e^{A0 h})^r, precomputed per speed; the delayed positions a
/// step reads are columns of the identity in the initial state, so their terms
/// are added to two column blocks instead of multiplying the history; and the
/// per-step algebra runs on fixed-size matrices for 1 … 4 modes (dynamic
/// beyond). The multipliers are those of the step-by-step product to round-off.
class FloquetSolver {
 public:
  FloquetSolver(FloquetMethod method, const ModalDynamics& dynamics, int steps);
  ~FloquetSolver();
  FloquetSolver(FloquetSolver&&) noexcept;
  FloquetSolver& operator=(FloquetSolver&&) noexcept;

  /// Prepares the step integrals for a tooth period τ (call once per speed).
  void set_delay(double delay_s);

  /// Spectral radius of the monodromy matrix for coupling samples scaled by
  /// `scale` (the depth, when the samples are per unit depth). `damping`
  /// (optional) holds samples of the extra modal damping C(t) (the equation
  /// reads η'' + 2ζΩη' + Ω²η = P (η − η_τ) − C η'), scaled by `damping_scale`.
  FloquetResult solve(const CouplingSamples& coupling, double scale,
                      const CouplingSamples* damping = nullptr, double damping_scale = 1.0);

  /// The monodromy matrix restricted to the components that carry non-zero
  /// multipliers (the state x, and the delayed positions some step actually
  /// reads), as solve() builds it; valid until the next call. Its size is at
  /// most state_size().
  const Eigen::MatrixXd& monodromy(const CouplingSamples& coupling, double scale,
                                   const CouplingSamples* damping = nullptr,
                                   double damping_scale = 1.0);

  int state_size() const noexcept { return state_size_; }
  FloquetMethod method() const noexcept { return method_; }

  /// The step algebra for a number of modes (fixed-size or dynamic), defined
  /// in floquet.cpp.
  class Kernel;

 private:
  FloquetMethod method_;
  int steps_;
  int state_size_;
  bool delay_set_ = false;
  std::unique_ptr<Kernel> kernel_;
  Eigen::EigenSolver<Eigen::MatrixXd> eigen_;
};

/// Chatter frequency from a critical multiplier μ: f = (k ± |arg μ|/2π)/τ (the
/// multiplier comes with its conjugate), with the integer k and sign that put f
/// where the structure is most flexible (largest receptance), since chatter
/// grows near a mode.
double chatter_frequency_hz(std::complex<double> multiplier, double delay_s,
                            const dynamics::ModalModel& modes);

/// "flip" (period doubling) for a real negative critical multiplier, "hopf"
/// otherwise (a complex pair: secondary Hopf / Neimark–Sacker).
const char* bifurcation_name(std::complex<double> multiplier) noexcept;

}  // namespace robomill::stability
