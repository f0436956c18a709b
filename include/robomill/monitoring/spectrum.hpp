#pragma once
// One-sided amplitude spectra of sampled signals (FFTW3 real-to-complex):
// the simulator's response metrics and chatter verdict (simulation/) and the
// recorded-signal detector (recording_analysis.hpp) use the same transform.

#include <mutex>
#include <vector>

namespace robomill::monitoring {

/// FFTW's planner is not thread-safe (execution of distinct plans is): every
/// plan in robomill is created and destroyed under this mutex.
std::mutex& fftw_planner_mutex();

struct AmplitudeSpectrum {
  std::vector<double> frequency_hz;
  /// Amplitude of a sinusoid at that frequency (window-corrected), signal units.
  std::vector<double> amplitude;
  double resolution_hz = 0.0;  ///< 1 / (record length), the window's resolution
};

/// Mean-removed, Hann-windowed spectrum of `samples` taken every `interval_s`,
/// zero-padded to `padding` times the record length (for peak interpolation;
/// the resolution stays 1 / record length). A sinusoid of amplitude A at a
/// bin frequency shows amplitude A. Throws std::invalid_argument for fewer
/// than 4 samples, a non-positive interval or padding < 1.
AmplitudeSpectrum amplitude_spectrum(const std::vector<double>& samples, double interval_s,
                                     int padding = 1);

/// The frequency of the largest amplitude in [low_hz, high_hz], refined by a
/// parabola through the peak and its neighbours (log amplitude); 0 when the
/// band holds no bin or the spectrum is zero there.
double peak_frequency_hz(const AmplitudeSpectrum& spectrum, double low_hz, double high_hz);

/// The frequency of a resonance in [low_hz, high_hz]: the band's largest
/// amplitude, refined as in peak_frequency_hz, but only if it is a hump — the
/// spectrum falls below 1/prominence of it somewhere on each side within the
/// band. A maximum at the band's edge is the tail of something outside it (the
/// leakage of a slow drift, a mode above the band), not a mode: 0 then.
double resonance_frequency_hz(const AmplitudeSpectrum& spectrum, double low_hz, double high_hz,
                              double prominence = 2.0);

}  // namespace robomill::monitoring
