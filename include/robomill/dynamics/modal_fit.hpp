#pragma once
// Modal parameters from measured FRFs (experimental modal analysis): natural
// frequencies, damping ratios and modal constants of the modes in one or more
// FRFs that share one frequency grid and one reference (force) direction —
// typically a hammer test at the tool tip, one FRF per direction.
//
// The fit runs in three stages, band by band, and a final refinement:
//  1. poles by the least-squares complex frequency-domain estimator (LSCF,
//     Guillaume et al. 2003; "PolyMAX", Peeters et al. 2004): a common-
//     denominator rational model in the discrete-time basis z = exp(iωΔt),
//     Δt = 1/(2 f_high), fitted linearly for every model order 1..max_order;
//  2. a stabilization diagram: poles that repeat over consecutive orders are
//     kept, one per cluster;
//  3. least-squares frequency-domain residues (LSFD) with those poles fixed,
//     plus lower and upper residual terms per band for the modes outside it;
//  4. (optional, on by default) poles and residues refined together by
//     nonlinear least squares on the output error (the modal-model maximum-
//     likelihood formulation of El-Kafafy et al. 2013).
// A band is a frequency range fitted with its own poles; bands are chosen
// automatically from the peaks of the FRFs (a single model over 10 Hz–6 kHz
// with modes at 17 Hz and 4.8 kHz is ill-conditioned) or given by the caller.
//
// Example:
//
//   dynamics::ModalFit fit = dynamics::fit_modes({hxx});
//   for (const auto& mode : fit.modes)
//     print(mode.natural_frequency_hz, mode.damping_ratio, mode.stiffness_n_per_m);

#include <complex>
#include <vector>

#include "robomill/dynamics/frf.hpp"

namespace robomill::dynamics {

/// A frequency range fitted with its own poles and residual terms.
struct FitBand {
  double low_hz = 0.0;
  double high_hz = 0.0;
  /// Highest LSCF model order (number of poles, conjugates counted) tried in
  /// this band; 0 uses ModalFitOptions::max_order.
  int max_order = 0;
};

struct ModalFitOptions {
  /// Bands to fit, in increasing frequency, not overlapping, inside the data.
  /// Empty: chosen from the peaks of the summed magnitude.
  std::vector<FitBand> bands;
  /// Highest model order for bands that do not set their own (≥ 2).
  int max_order = 40;
  /// A pole is stable when the nearest pole of the previous order lies within
  /// this relative distance in natural frequency ...
  double frequency_stability = 0.01;
  /// ... and, for damping, also within this relative distance in damping ratio.
  double damping_stability = 0.05;
  /// A mode needs a pole stable in frequency and damping at this many orders.
  int min_stable_orders = 3;
  /// Refine poles, residues and residual terms together by nonlinear least
  /// squares on the output error weighted by 1 / |H| (Levenberg–Marquardt from
  /// the LSCF/LSFD estimate). Off: poles as read from the stabilization diagram.
  bool refine = true;
};

/// One mode, in the real-mode form H_pq(ω) = A_pq / (ωn² − ω² + 2iζωnω).
struct FittedMode {
  double natural_frequency_hz = 0.0;
  double damping_ratio = 0.0;
  /// A = φ_p φ_q per input FRF (1/kg for receptance): real for a real
  /// (proportionally damped) mode, complex in general.
  std::vector<std::complex<double>> modal_constant;
  /// From the driving-point FRF (response axis = reference axis, the first one
  /// if several): k = ωn² / Re A and m = 1 / Re A. Zero without a driving point.
  double stiffness_n_per_m = 0.0;
  double mass_kg = 0.0;
  double band_low_hz = 0.0;  ///< the band the pole came from
  double band_high_hz = 0.0;
  /// ‖H − Ĥ‖ / ‖H‖ over the half-power band fn(1 ± ζ) (at least 3 grid points), all FRFs.
  double fit_error = 0.0;
  /// Frequency response assurance criterion |Σ H̄ Ĥ|² / (Σ|H|² Σ|Ĥ|²) over the
  /// same points: 1 when measured and fitted FRFs have the same shape there.
  double assurance = 0.0;
  /// RMS of this mode's own term over the RMS of the fitted FRF, same points,
  /// in the driving-point FRF (else the first): near 1 for a mode that
  /// dominates its resonance, small for a computational one.
  double contribution = 0.0;
  /// Orders at which its pole was stable in frequency and damping.
  int stable_orders = 0;
};

/// One physical pole (0 < ζ < 0.5, fn inside the band) of one model order:
/// the data of a stabilization diagram.
struct StabilizationPoint {
  int band = 0;  ///< index into ModalFit::bands_used
  int order = 0;
  double frequency_hz = 0.0;
  double damping_ratio = 0.0;
  bool stable_frequency = false;  ///< the previous order has a pole within the frequency tolerance
  bool stable_damping = false;    ///< ... whose damping is also within the damping tolerance
};

struct ModalFit {
  std::vector<FittedMode> modes;  ///< physical modes, increasing frequency
  /// Stable poles rejected after the residue fit as computational modes (they
  /// fit noise, or bend the model around residual effects near a band edge):
  /// a contribution below 1 % or below 3 times the fit error in their own
  /// half-power band, or a driving-point modal constant φ_p² that is not positive.
  std::vector<FittedMode> rejected;
  /// The fitted FRF per input FRF, same kind and grid as the input less any 0 Hz
  /// point; outside every band only the modes contribute.
  std::vector<Frf> fitted;
  std::vector<StabilizationPoint> stabilization;
  double overall_error = 0.0;       ///< ‖H − Ĥ‖ / ‖H‖ over all band points of all FRFs
  std::vector<FitBand> bands_used;  ///< with the max_order used in each
};

/// Fits the modes of FRFs that share one frequency grid (any kind; mobility and
/// accelerance are integrated to receptance and 0 Hz points dropped).
/// Throws std::invalid_argument when there are no FRFs, an FRF is malformed,
/// the grids differ, the options are out of range, a band lies outside the data,
/// overlaps another or holds fewer points than its model order needs; throws
/// NumericalError naming the band when no pole is stable in it or every stable
/// pole in it is computational.
ModalFit fit_modes(const std::vector<Frf>& frfs, const ModalFitOptions& options = {});

}  // namespace robomill::dynamics
