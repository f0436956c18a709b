// Harmonic attribution of spectral bins (harmonic_comb.hpp).

#include "robomill/monitoring/harmonic_comb.hpp"

#include <cmath>

namespace robomill::monitoring {

int harmonic_number(double frequency_hz, double fundamental_hz, double tolerance_hz) noexcept {
  if (!(fundamental_hz > 0.0))
    return 0;
  const double k = std::round(frequency_hz / fundamental_hz);
  if (k < 1.0)
    return 0;
  return std::abs(frequency_hz - k * fundamental_hz) <= tolerance_hz ? static_cast<int>(k) : 0;
}

HarmonicSplit split_harmonics(const AmplitudeSpectrum& spectrum, double fundamental_hz,
                              double tolerance_bins, double low_edge_bins) {
  HarmonicSplit split;
  const double tolerance_hz = tolerance_bins * spectrum.resolution_hz;
  for (std::size_t k = 1; k < spectrum.frequency_hz.size(); ++k) {
    const double f = spectrum.frequency_hz[k];
    if (f < low_edge_bins * spectrum.resolution_hz)
      continue;
    const double energy = spectrum.amplitude[k] * spectrum.amplitude[k];
    if (harmonic_number(f, fundamental_hz, tolerance_hz) > 0) {
      split.harmonic += energy;
      continue;
    }
    split.nonharmonic += energy;
    if (spectrum.amplitude[k] > split.peak_amplitude) {
      split.peak_amplitude = spectrum.amplitude[k];
      split.peak_hz = f;
    }
  }
  return split;
}

}  // namespace robomill::monitoring
