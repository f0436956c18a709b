#pragma once
// Zero-order (frequency-domain) chatter stability, Altintas & Budak (1995),
// multi-DOF form (Altintas & Budak 1999; 003 §3.2 uses it per mode).
//
// Model (regenerative_model.hpp, forces on the tool):
//   M q'' + C q' + K q = F_d = W(t) (q(t) − q(t − τ)),   τ = 2π / (N Ω_s).
// The zero-order approximation keeps only the period average of W, which for
// a flat end mill (straight or helical flutes) is proportional to the depth:
//   (1/τ) ∫ W dt = ap A0,   A0 in N/m per m of depth (3x3, tool frame).
// With q = Q e^{iωt} and G(ω) = (K − ω² M + iω C)^{-1} the receptance, a
// periodic solution exists when
//   det[I − ap (1 − e^{−iωτ}) A0 G(ω)] = 0.                              (1)
// Let λ be an eigenvalue of A0 G(ω_c). (1) holds when ap (1 − e^{−iω_c τ}) = 1/λ.
// Writing 1 − e^{−ix} = 2 sin(x/2) · i e^{−ix/2} and taking real and
// imaginary parts:
//   ap (1 − cos ω_c τ) = Re λ / |λ|²,   ap sin ω_c τ = −Im λ / |λ|².
// Since 1 − cos ≥ 0, a positive depth needs Re λ > 0. Squaring and adding,
// ap² · 2 (1 − cos ω_c τ) = 1/|λ|², and dividing by the first equation gives
//   ap = 1 / (2 Re λ)                                                      (2)
// (Altintas' a_lim = −2π Λ_R (1 + κ²) / (N K_t) in this sign convention).
// The phase follows from cos ω_c τ = 1 − 2 cos² ψ = −cos 2ψ and
// sin ω_c τ = −sin 2ψ with ψ = arg λ ∈ (−π/2, π/2):
//   ω_c τ = ε + 2π k,   ε = π + 2ψ ∈ (0, 2π),   k = 0, 1, 2, …              (3)
// so each eigenvalue branch b and lobe k gives the curve
//   Ω_s(ω_c) = 2π / (N τ) = N^{-1} 2π ω_c / (ε_b(ω_c) + 2π k),  ap_b(ω_c) = 1/(2 Re λ_b).
// The limit at one speed is the smallest ap over all curves passing that speed.
//
// Implementation: λ_b(ω) is computed once on a chatter-frequency grid (dense
// around every FRF peak, log-spaced elsewhere, extended by octaves at either
// end while some curve there still lies below depth_max) and the branches are
// tracked by nearest-neighbour matching. For a speed (τ fixed) the phase residual
// f_b(ω) = ω τ − ε_b(ω) is continuous on every run of grid points with
// Re λ_b > 0, and every integer k ≥ 0 with 2πk between f_b at two neighbouring
// points is a crossing of lobe k; the crossing with the smallest interpolated
// depth (and any within a few percent of it) is then refined on the exact
// eigenvalues (Illinois regula falsi on f_b(ω) − 2πk), so the returned
// (speed, depth, chatter frequency) satisfy (1) to round-off.
//
// When A0 has a zero third column (every flat end mill: the chip normal has
// no z component), the non-zero eigenvalues of A0 G are those of the 2x2
// G[0:2, :] A0[:, 0:2] and are found in closed form; otherwise a 3x3 complex
// eigensolver is used. Neither allocates per frequency. With a modal model
// (G = Σ_r φ_r φ_rᵀ h_r(ω), h_r = 1/(ω_r² − ω² + 2iζ_r ω_r ω), real shapes)
// that 2x2 is Σ_r h_r(ω) P_r with P_r = φ_r[0:2] (A0[:, 0:2]ᵀ φ_r)ᵀ real and
// fixed: per frequency one scalar h_r and two 2x2 real sums per mode, not
// the 3x3 receptance and its product with A0 (the draws of a program's
// uncertain robot solve this a few hundred thousand times).

#include <Eigen/Core>
#include <array>
#include <complex>
#include <cstddef>
#include <functional>
#include <utility>
#include <vector>

#include "robomill/dynamics/modal_model.hpp"
#include "robomill/stability/regenerative_model.hpp"

namespace robomill::stability {

/// A frequency response function: 3x3 receptance (m/N, tool frame) at ω (rad/s).
/// A ModalModel's receptance, a measured FRF interpolator, anything.
using Frf = std::function<Eigen::Matrix3cd(double omega_rad_s)>;

/// A resonance of the FRF, used only to place grid points densely around it.
struct FrfPeak {
  double frequency_hz = 0.0;
  double damping_ratio = 0.01;
};

struct ZeroOrderOptions {
  /// Chatter-frequency range of the global (log-spaced) grid; 0 picks
  /// 0.5 × the lowest and 1.5 × the highest peak.
  double min_frequency_hz = 0.0;
  double max_frequency_hz = 0.0;
  int global_points = 1500;
  /// Points around each peak: offsets ζ ω_n sinh(s), s uniform in
  /// [−asinh(B), asinh(B)] with B = `peak_half_bandwidths` (uniform near ω_n,
  /// log-spaced further out). 150 put 18 points in each half-bandwidth at
  /// the peak whatever ζ; the crossings are refined on the exact eigenvalues,
  /// so the grid only has to find them: against 400 points the limits of the
  /// stability examples and of the uncertain program agree to 1e-11, at 0.6
  /// of the cost per solve (docs/uncertainty.md, "Speed of a long program").
  int points_per_peak = 150;
  double peak_half_bandwidths = 30.0;
  /// Depths above this are reported as "not limited"; 0 takes the model's
  /// max_depth_m() (the tool overhang), or 1 m when no model is given.
  double depth_max_m = 0.0;
  /// Samples of W over a tooth period for A0 (midpoint rule).
  int averaging_samples = 4096;
  /// Depth at which A0 = (1/τ)∫W dt / depth is evaluated. Exact at any depth
  /// for flat end mills; a ball-end mill's A0 is not proportional to the depth
  /// and is linearized (secant) at this depth. 0 picks min(overhang,
  /// diameter) for flat tools and min(overhang, radius) for ball-end tools.
  double reference_depth_m = 0.0;
  /// Candidates within this relative margin of the best interpolated one are
  /// refined too (interpolation can misorder near-equal lobes).
  double refine_margin = 0.05;
};

/// The limit at one spindle speed.
struct ZeroOrderLimit {
  double spindle_rad_s = 0.0;
  /// Critical axial depth, or depth_max when no curve lies below depth_max at
  /// this speed (`limited` false): the cut is then stable over (0, depth_max].
  double depth_limit_m = 0.0;
  bool limited = false;
  double chatter_frequency_hz = 0.0;  ///< 0 when not limited
  int lobe = -1;                      ///< k of (3); −1 when not limited
  int branch = -1;                    ///< eigenvalue branch; −1 when not limited
  // Filled by the process-damped and multi-mode analyses (process_damping.hpp):
  int mode = -1;          ///< governing mode (envelope), −1 for the coupled diagram
  int iterations = 0;     ///< limit evaluations of the process-damping iteration
  bool converged = true;  ///< false when the process-damping iteration hit its cap
};

/// (1/τ) ∫ W dt / depth over one tooth period at `reference_depth_m` (0: the
/// default of ZeroOrderOptions), N/m per m of depth, tool frame. Midpoint rule
/// with `samples` spindle angles.
Eigen::Matrix3d mean_cutting_stiffness_per_depth(const RegenerativeModel& model, int samples = 4096,
                                                 double reference_depth_m = 0.0);

/// The same A0 for a cut alone, when the structure is known only by measured
/// FRFs: W(ϕ) depends on the tool, the law and the engagement, not on the modes.
Eigen::Matrix3d mean_cutting_stiffness_per_depth(const tool::Tool& tool,
                                                 const cutting::CuttingLaw& law,
                                                 const cutting::MillingProcess& process,
                                                 int samples = 4096,
                                                 double reference_depth_m = 0.0);

/// A0 split by shear coefficient, for many A0 of one cut: the tool, the
/// process and the reference depth fixed, the coefficients (K_tc, K_rc, K_ac)
/// varying (the stability band's draws, issue 33). A0 is linear in them
/// (000 Eq 14: W = Σ b (T K_c) nᵀ), so A0 = Σ_q K_qc ∂A0/∂K_qc exactly; this
/// sums the same terms as mean_cutting_stiffness_per_depth in another order,
/// so the two agree to round-off.
struct MeanCuttingStiffnessBasis {
  /// ∂A0/∂K_tc, ∂A0/∂K_rc, ∂A0/∂K_ac: (N/m per m of depth) per (N/m²).
  std::array<Eigen::Matrix3d, 3> per_shear_coefficient;
  /// A0 for `law`'s shear coefficients (N/m per m of depth).
  Eigen::Matrix3d operator()(const cutting::LinearLaw& law) const;
  /// The basis of the difference of two cuts (an arc as one band less
  /// another: A0 is additive over the engaged arc).
  MeanCuttingStiffnessBasis& operator-=(const MeanCuttingStiffnessBasis& other) {
    for (std::size_t c = 0; c < per_shear_coefficient.size(); ++c)
      per_shear_coefficient[c] -= other.per_shear_coefficient[c];
    return *this;
  }
};

/// The basis of `model`'s cut (its law's coefficients are not used), with
/// the samples and reference depth of mean_cutting_stiffness_per_depth.
MeanCuttingStiffnessBasis mean_cutting_stiffness_basis(const RegenerativeModel& model,
                                                       int samples = 4096,
                                                       double reference_depth_m = 0.0);

/// The same for a cut alone (W, and so A0, does not depend on the modes).
MeanCuttingStiffnessBasis mean_cutting_stiffness_basis(const tool::Tool& tool,
                                                       const cutting::CuttingLaw& law,
                                                       const cutting::MillingProcess& process,
                                                       int samples = 4096,
                                                       double reference_depth_m = 0.0);

/// The chatter-frequency grid (rad/s, sorted, unique) for the given peaks.
std::vector<double> chatter_frequency_grid_rad_s(const std::vector<FrfPeak>& peaks,
                                                 const ZeroOrderOptions& options);

/// The peaks of a modal model (its natural frequencies and damping ratios).
std::vector<FrfPeak> modal_peaks(const dynamics::ModalModel& modes);

/// det[I − ap (1 − e^{−iωτ}) A0 G(ω)], the characteristic function (1).
std::complex<double> characteristic_determinant(const Eigen::Matrix3d& mean_stiffness_per_depth,
                                                const Eigen::Matrix3cd& receptance, double depth_m,
                                                double omega_rad_s, double delay_s);

class ZeroOrderSolver {
 public:
  /// The model's A0 and its modal receptance.
  explicit ZeroOrderSolver(const RegenerativeModel& model, const ZeroOrderOptions& options = {});
  /// The model's A0 with any FRF; `peaks` place the dense grid (may be empty
  /// if the global grid is fine enough; then set min/max_frequency_hz).
  ZeroOrderSolver(const RegenerativeModel& model, Frf frf, const std::vector<FrfPeak>& peaks,
                  const ZeroOrderOptions& options = {});
  /// A given A0 (N/m per m of depth) and modal model; `teeth` sets τ = 2π/(NΩ).
  ZeroOrderSolver(const Eigen::Matrix3d& mean_stiffness_per_depth, int teeth,
                  const dynamics::ModalModel& modes, const ZeroOrderOptions& options = {});
  /// A0 and a modal model on an explicit grid (rad/s, sorted): the diagrams
  /// that share one grid over several mode sets (process_damping.hpp).
  ZeroOrderSolver(const Eigen::Matrix3d& mean_stiffness_per_depth, int teeth,
                  const dynamics::ModalModel& modes, std::vector<double> grid_rad_s,
                  double depth_max_m, double refine_margin = 0.05);
  /// The most general form: A0, FRF and an explicit grid (rad/s, sorted).
  ZeroOrderSolver(const Eigen::Matrix3d& mean_stiffness_per_depth, int teeth, Frf frf,
                  std::vector<double> grid_rad_s, double depth_max_m, double refine_margin = 0.05)
      : ZeroOrderSolver(mean_stiffness_per_depth, teeth, std::move(frf), std::move(grid_rad_s),
                        depth_max_m, refine_margin, nullptr) {}

  /// The limit at one spindle speed (rad/s > 0). Safe to call from several
  /// threads when the FRF callable is (a ModalModel's is).
  ZeroOrderLimit limit(double spindle_rad_s) const;
  /// Limits at many speeds, in order.
  std::vector<ZeroOrderLimit> limits(const std::vector<double>& spindle_rad_s) const;
  /// The absolute (speed-independent) limit: min over grid points and branches
  /// of 1/(2 Re λ), refined by golden-section search between neighbours;
  /// spindle_rad_s is that of lobe 0 (the curve's minimum is the same on every
  /// lobe, at speeds 2π ω_c / (N (ε + 2πk))).
  ZeroOrderLimit minimum_limit() const;

  const Eigen::Matrix3d& mean_stiffness_per_depth() const noexcept { return a0_; }
  const std::vector<double>& grid_rad_s() const noexcept { return grid_; }
  int teeth() const noexcept { return teeth_; }
  double depth_max_m() const noexcept { return depth_max_; }
  int branches() const noexcept { return branches_; }
  /// The receptance the solver uses.
  Eigen::Matrix3cd receptance(double omega_rad_s) const { return frf_(omega_rad_s); }

 private:
  /// The general form; `modes` (may be null) is the FRF's modal model, for
  /// the planar closed form's fixed per-mode matrices.
  ZeroOrderSolver(const Eigen::Matrix3d& mean_stiffness_per_depth, int teeth, Frf frf,
                  std::vector<double> grid_rad_s, double depth_max_m, double refine_margin,
                  const dynamics::ModalModel* modes);
  void build();  // track() and extend the grid while curves stay below depth_max
  /// Eigenvalues (where not `known` yet) and branch tracking on grid_.
  void track(std::vector<Eigen::Vector3cd>& raw, std::vector<char>& known);
  /// Eigenvalues of A0 G(ω) (first `branches_` entries meaningful).
  Eigen::Vector3cd eigenvalues(double omega_rad_s) const;
  /// Refines the crossing of branch b, lobe k in grid interval [i, i+1].
  bool refine(int branch, int interval, int lobe, double delay_s, double& omega,
              double& depth) const;

  Eigen::Matrix3d a0_;
  int teeth_ = 1;
  Frf frf_;
  std::vector<double> grid_;
  double depth_max_ = 1.0;
  double refine_margin_ = 0.05;
  bool planar_ = false;  // A0 has a zero third column: 2x2 eigenproblem
  int branches_ = 3;
  /// Planar with a modal model: per mode ω_r², 2ζ_r ω_r and P_r (see above).
  struct PlanarMode {
    double natural_squared = 0.0, damping_term = 0.0;
    Eigen::Matrix2d product = Eigen::Matrix2d::Zero();
  };
  std::vector<PlanarMode> planar_modes_;
  // Per branch b, per grid point i (index b * n + i): eigenvalue, phase ε, validity.
  std::vector<std::complex<double>> lambda_;
  std::vector<double> epsilon_;
  std::vector<char> valid_;
};

}  // namespace robomill::stability
