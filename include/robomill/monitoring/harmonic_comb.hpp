#pragma once
// Which spectral bins belong to the harmonics of a fundamental (the forced
// response of a cut: the spindle's and the teeth's passing frequencies) and
// which do not (the evidence of chatter). The one attribution rule shared by
// the simulator's verdict (simulation::detect_chatter) and the
// recorded-signal detector (monitoring::analyze_recording): issue 22, "one
// detector".

#include "robomill/monitoring/spectrum.hpp"

namespace robomill::monitoring {

/// The harmonic number k ≥ 1 of `frequency_hz` when it lies within
/// `tolerance_hz` of k · fundamental_hz; 0 otherwise (also for f below half
/// the fundamental, the DC side, and for a non-positive fundamental).
int harmonic_number(double frequency_hz, double fundamental_hz, double tolerance_hz) noexcept;

/// An amplitude spectrum split into the harmonics of a fundamental and the
/// rest. Energies are sums of squared bin amplitudes (for a Hann spectrum
/// RMS² = energy / 3: a sinusoid of amplitude A fills three bins with 1.5 A²).
struct HarmonicSplit {
  double harmonic = 0.0, nonharmonic = 0.0;
  double peak_amplitude = 0.0, peak_hz = 0.0;  ///< largest non-harmonic bin (0: none)
};

/// Bins below `low_edge_bins` resolution bins are left out (what remains of
/// a drift); a bin within `tolerance_bins` resolution bins of a harmonic of
/// `fundamental_hz` is harmonic (2.5: the Hann window's main lobe), the rest
/// non-harmonic.
HarmonicSplit split_harmonics(const AmplitudeSpectrum& spectrum, double fundamental_hz,
                              double tolerance_bins = 2.5, double low_edge_bins = 3.0);

}  // namespace robomill::monitoring
