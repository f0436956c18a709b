#pragma once
// The periodic milling force as a Fourier series (004 §4.2, Figure 6).
//
// The force of a rigid cut repeats every tooth period τ = 2π/(N Ω) (every
// revolution when the cutter has runout). Sampled at M instants over one
// period, its discrete Fourier coefficients
//
//   c_k = (1/M) Σ_m F(t_m) e^{−2πi k m / M},   k = 0 … K,  K < M/2,
//
// give F(t) ≈ c_0 + Σ_{k≥1} 2 Re(c_k e^{i k ω_p t}) with ω_p = 2π/period, and
// a linear structure's steady state is the same sum with each c_k multiplied
// by the receptance at k ω_p (steady_state_offset.hpp). The coefficients are
// computed once per cut: the force in the tool frame is the same at every
// point of a path with constant engagement (004 §3.3: F_Ei = R_ni F').

#include <Eigen/Core>
#include <complex>
#include <vector>

#include "robomill/cutting/milling_forces.hpp"

namespace robomill::planning {

struct ForceHarmonics {
  double period_s = 0.0;           ///< τ (tooth period) or a revolution with runout
  double fundamental_rad_s = 0.0;  ///< ω_p = 2π / period
  /// c_0 … c_K, N, tool frame (c_0 is the mean force).
  std::vector<Eigen::Vector3cd> coefficients;
  /// Instants per period at which responses are reconstructed (≥ 2K + 1).
  int samples = 0;
  int harmonics() const noexcept { return static_cast<int>(coefficients.size()) - 1; }
};

/// Samples `model` at `samples` instants over one period (one tooth period,
/// or one revolution when the tool has runout) and keeps harmonics 0 …
/// `harmonics`. Throws std::invalid_argument unless 1 ≤ harmonics and
/// samples ≥ 2 harmonics + 1.
ForceHarmonics force_harmonics(const cutting::MillingForceModel& model, int samples, int harmonics);

/// F(t) (tool frame, N) from the series, for checks and plots.
Eigen::Vector3d force_at(const ForceHarmonics& harmonics, double time_s);

}  // namespace robomill::planning
