// Spectra of simulated responses (monitoring/spectrum.hpp): the resonance
// search that gives summary.json's first frequency must find a mode inside
// its band and report none when the band holds only the tail of something
// else (a slow drift, a mode above the band).

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "robomill/monitoring/spectrum.hpp"

namespace test_spectrum_cpp {

namespace {

using namespace robomill;
constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kInterval = 1e-3;  // s
constexpr int kSamples = 4000;      // 4 s

std::vector<double> signal(double frequency_hz, double decay_per_s, double drift_per_s) {
  std::vector<double> samples(kSamples);
  for (int i = 0; i < kSamples; ++i) {
    const double t = i * kInterval;
    samples[i] = std::exp(-decay_per_s * t) * std::cos(kTwoPi * frequency_hz * t) +
                 2.0 * std::exp(-drift_per_s * t);
  }
  return samples;
}

TEST(Spectrum, ResonanceOfADecayingOscillationOnADrift) {
  // 5 Hz at ζ ≈ 0.05 on a drift twice its amplitude (a robot's slow sway
  // settling onto its static deviation).
  const auto spectrum = monitoring::amplitude_spectrum(signal(5.0, 1.57, 3.0), kInterval, 8);
  EXPECT_NEAR(monitoring::resonance_frequency_hz(spectrum, 0.4, 50.0), 5.0, 0.05);
}

TEST(Spectrum, NoResonanceInABandHoldingOnlyATail) {
  // A drift alone: its spectrum falls from the band's low edge.
  auto drift = signal(0.0, 0.0, 3.0);
  const auto drift_spectrum = monitoring::amplitude_spectrum(drift, kInterval, 8);
  EXPECT_EQ(monitoring::resonance_frequency_hz(drift_spectrum, 0.4, 50.0), 0.0);
  // A mode at 200 Hz seen from a band ending at 50 Hz: it rises to the edge.
  const auto high = monitoring::amplitude_spectrum(signal(200.0, 60.0, 1e9), kInterval, 8);
  EXPECT_EQ(monitoring::resonance_frequency_hz(high, 0.4, 50.0), 0.0);
  // ... while the plain peak search returns a frequency for both.
  EXPECT_GT(monitoring::peak_frequency_hz(drift_spectrum, 0.4, 50.0), 0.0);
  EXPECT_GT(monitoring::peak_frequency_hz(high, 0.4, 50.0), 0.0);
}

}  // namespace

}  // namespace test_spectrum_cpp
