// Amplitude spectra with FFTW3 (spectrum.hpp).

#include "robomill/monitoring/spectrum.hpp"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numbers>
#include <stdexcept>

namespace robomill::monitoring {
std::mutex& fftw_planner_mutex() {
  static std::mutex mutex;
  return mutex;
}

AmplitudeSpectrum amplitude_spectrum(const std::vector<double>& samples, double interval_s,
                                     int padding) {
  const std::size_t count = samples.size();
  if (count < 4 || !(interval_s > 0.0) || padding < 1)
    throw std::invalid_argument("amplitude_spectrum: needs ≥ 4 samples, interval > 0, padding ≥ 1");
  double mean = 0.0;
  for (double s : samples)
    mean += s;
  mean /= static_cast<double>(count);
  const std::size_t length = count * static_cast<std::size_t>(padding);
  const std::size_t bins = length / 2 + 1;
  double* input = fftw_alloc_real(length);
  fftw_complex* output = fftw_alloc_complex(bins);
  fftw_plan plan;
  {
    const std::lock_guard lock(fftw_planner_mutex());
    plan = fftw_plan_dft_r2c_1d(static_cast<int>(length), input, output, FFTW_ESTIMATE);
  }
  // Hann window; its coherent gain is 1/2, so a sinusoid of amplitude A gives
  // |X| = A N / 4 at its bin.
  double window_sum = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    const double w =
        0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / double(count));
    window_sum += w;
    input[i] = (samples[i] - mean) * w;
  }
  std::fill(input + count, input + length, 0.0);
  fftw_execute(plan);
  AmplitudeSpectrum spectrum;
  spectrum.resolution_hz = 1.0 / (static_cast<double>(count) * interval_s);
  spectrum.frequency_hz.resize(bins);
  spectrum.amplitude.resize(bins);
  const double df = 1.0 / (static_cast<double>(length) * interval_s);
  for (std::size_t k = 0; k < bins; ++k) {
    spectrum.frequency_hz[k] = static_cast<double>(k) * df;
    const double magnitude = std::hypot(output[k][0], output[k][1]);
    spectrum.amplitude[k] = (k == 0 ? 1.0 : 2.0) * magnitude / window_sum;
  }
  {
    const std::lock_guard lock(fftw_planner_mutex());
    fftw_destroy_plan(plan);
  }
  fftw_free(input);
  fftw_free(output);
  return spectrum;
}

namespace {

/// Index of the largest amplitude among the bins in [low_hz, high_hz] that
/// have a neighbour on each side; size() when there is none.
std::size_t largest_bin(const AmplitudeSpectrum& spectrum, double low_hz, double high_hz) {
  const auto& f = spectrum.frequency_hz;
  const auto& a = spectrum.amplitude;
  std::size_t best = f.size();
  for (std::size_t k = 1; k + 1 < f.size(); ++k) {
    if (f[k] < low_hz || f[k] > high_hz)
      continue;
    if (best == f.size() || a[k] > a[best])
      best = k;
  }
  return best;
}

/// The peak at bin `best` refined by a parabola through log amplitudes.
double refined_peak_hz(const AmplitudeSpectrum& spectrum, std::size_t best) {
  const auto& f = spectrum.frequency_hz;
  const auto& a = spectrum.amplitude;
  const double left = std::log(std::max(a[best - 1], 1e-300));
  const double centre = std::log(a[best]);
  const double right = std::log(std::max(a[best + 1], 1e-300));
  const double curvature = left - 2.0 * centre + right;
  double offset = curvature < 0.0 ? 0.5 * (left - right) / curvature : 0.0;
  offset = std::clamp(offset, -0.5, 0.5);
  return f[best] + offset * (f[1] - f[0]);
}

}  // namespace

double peak_frequency_hz(const AmplitudeSpectrum& spectrum, double low_hz, double high_hz) {
  const std::size_t best = largest_bin(spectrum, low_hz, high_hz);
  if (best == spectrum.frequency_hz.size() || !(spectrum.amplitude[best] > 0.0))
    return 0.0;
  return refined_peak_hz(spectrum, best);
}

double resonance_frequency_hz(const AmplitudeSpectrum& spectrum, double low_hz, double high_hz,
                              double prominence) {
  const std::size_t best = largest_bin(spectrum, low_hz, high_hz);
  const auto& f = spectrum.frequency_hz;
  const auto& a = spectrum.amplitude;
  if (best == f.size() || !(a[best] > 0.0))
    return 0.0;
  const double floor = a[best] / prominence;
  bool dip_below = false, dip_above = false;
  for (std::size_t k = best; k-- > 0 && f[k] >= low_hz;)
    dip_below = dip_below || a[k] < floor;
  for (std::size_t k = best + 1; k < f.size() && f[k] <= high_hz; ++k)
    dip_above = dip_above || a[k] < floor;
  return dip_below && dip_above ? refined_peak_hz(spectrum, best) : 0.0;
}

}  // namespace robomill::monitoring
