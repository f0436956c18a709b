// Static deviation, overshoot, settling, first frequency and the chatter
// verdict of a simulated response (response_metrics.hpp).

#include "robomill/simulation/response_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "robomill/simulation/spectrum.hpp"

namespace robomill::simulation {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kNoMotion = 1e-15;  // m: a direction that does not move

std::vector<double> component(const std::vector<Eigen::Vector3d>& series, int axis,
                              std::size_t from, std::size_t to) {
  std::vector<double> out;
  out.reserve(to - from);
  for (std::size_t i = from; i < to; ++i)
    out.push_back(series[i][axis]);
  return out;
}

double mean_of(const std::vector<double>& values) {
  double sum = 0.0;
  for (double v : values)
    sum += v;
  return values.empty() ? 0.0 : sum / static_cast<double>(values.size());
}

}  // namespace

ResponseMetrics analyze_response(const SimulationResult& result, const ResponseOptions& options) {
  const std::size_t count = result.size();
  const double dt = result.record_interval_s;
  if (count < 8 || !(dt > 0.0) || !(options.spindle_rad_s > 0.0) || options.teeth < 1)
    throw std::invalid_argument("analyze_response: too few samples or no process");
  const double tooth_period_s = kTwoPi / (options.spindle_rad_s * options.teeth);
  const double forced_period_s = options.runout ? kTwoPi / options.spindle_rad_s : tooth_period_s;
  const auto tooth_samples = std::max<std::size_t>(1, std::llround(tooth_period_s / dt));
  const auto period_samples = std::max<std::size_t>(1, std::llround(forced_period_s / dt));
  const auto periods =
      static_cast<std::size_t>(std::floor(options.steady_window_s / forced_period_s + 1e-9));
  const std::size_t window = periods * period_samples;
  if (periods < 1 || window + 1 > count)
    throw std::invalid_argument("analyze_response: the steady window does not fit the run");

  ResponseMetrics metrics;
  const std::size_t end = count - 1;  // the last sample closes the last period
  const std::size_t steady_from = end - window;
  metrics.steady_from_s = result.time_s[steady_from];
  const double contact_s = std::max(0.0, result.first_contact_s);

  // Forces over the steady window.
  for (std::size_t i = steady_from; i < end; ++i)
    metrics.mean_force_n += result.force_n[i];
  metrics.mean_force_n /= static_cast<double>(window);
  for (std::size_t i = 0; i < count; ++i)
    for (int a = 0; a < 3; ++a)
      if (std::abs(result.force_n[i][a]) > std::abs(metrics.peak_force_n[a]))
        metrics.peak_force_n[a] = result.force_n[i][a];

  // First-frequency window: after full engagement, whole tooth periods.
  std::size_t analysis_from = static_cast<std::size_t>(std::ceil(result.full_engagement_s / dt));
  analysis_from = std::min(analysis_from, steady_from);
  metrics.analysis_from_s = result.time_s[analysis_from];
  const double spindle_hz = options.spindle_rad_s / kTwoPi;

  double energy_all = 0.0, energy_off = 0.0, best_off = 0.0;
  double spread_samples = 0.0, spread_all = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    DirectionResponse& d = metrics.direction[axis];
    const std::vector<double> steady = component(result.displacement_m, axis, steady_from, end);
    d.static_deviation_m = mean_of(steady);
    const auto [lo, hi] = std::minmax_element(steady.begin(), steady.end());
    d.peak_to_peak_m = *hi - *lo;
    double variance = 0.0;
    for (double v : steady)
      variance += (v - d.static_deviation_m) * (v - d.static_deviation_m);
    variance /= static_cast<double>(steady.size());
    d.rms_vibration_m = std::sqrt(variance);
    const double level = std::abs(d.static_deviation_m);
    const bool moves = d.peak_to_peak_m > kNoMotion || level > kNoMotion;
    if (!moves)
      continue;

    // Tooth-period averages: overshoot and settling (002 Table 1's PO, τs).
    if (level > kNoMotion) {
      const double sign = d.static_deviation_m > 0.0 ? 1.0 : -1.0;
      double peak = 0.0, settled_at = contact_s;
      for (std::size_t first = 0; first + tooth_samples <= count; first += tooth_samples) {
        double average = 0.0;
        for (std::size_t i = first; i < first + tooth_samples; ++i)
          average += result.displacement_m[i][axis];
        average /= static_cast<double>(tooth_samples);
        peak = std::max(peak, sign * average);
        if (std::abs(average - d.static_deviation_m) > options.settling_band * level)
          settled_at = result.time_s[first] + static_cast<double>(tooth_samples) * dt;
      }
      d.overshoot_pct = 100.0 * std::max(0.0, peak - level) / level;
      d.settling_time_s = std::max(0.0, settled_at - contact_s);
    }

    // First frequency: a resonance below half the spindle frequency (none
    // when the direction's modes all lie above it).
    if (end - analysis_from >= 8) {
      const std::vector<double> after = component(result.displacement_m, axis, analysis_from, end);
      const AmplitudeSpectrum spectrum = amplitude_spectrum(after, dt, 8);
      d.first_frequency_hz =
          resonance_frequency_hz(spectrum, 1.5 * spectrum.resolution_hz, 0.5 * spindle_hz);
    }

    // Chatter evidence 1: energy away from the forced harmonics.
    const AmplitudeSpectrum spectrum = amplitude_spectrum(steady, dt, 1);
    const double forced_hz = 1.0 / forced_period_s;
    for (std::size_t k = 1; k < spectrum.frequency_hz.size(); ++k) {
      const double f = spectrum.frequency_hz[k];
      if (f < 0.5 * forced_hz)
        continue;
      const double energy = spectrum.amplitude[k] * spectrum.amplitude[k];
      energy_all += energy;
      const double harmonic = std::round(f / forced_hz) * forced_hz;
      if (std::abs(f - harmonic) > 2.5 * spectrum.resolution_hz) {
        energy_off += energy;
        if (spectrum.amplitude[k] > best_off) {
          best_off = spectrum.amplitude[k];
          metrics.chatter.frequency_hz = f;
        }
      }
    }
    // Chatter evidence 2: the displacement sampled once per forced period.
    std::vector<double> sampled;
    for (std::size_t i = 0; i < window; i += period_samples)
      sampled.push_back(steady[i]);
    const double sampled_mean = mean_of(sampled);
    double sampled_variance = 0.0;
    for (double v : sampled)
      sampled_variance += (v - sampled_mean) * (v - sampled_mean);
    spread_samples += sampled_variance / static_cast<double>(sampled.size());
    spread_all += variance;
  }
  ChatterVerdict& c = metrics.chatter;
  c.nonharmonic_fraction = energy_all > 0.0 ? energy_off / energy_all : 0.0;
  c.sample_spread = spread_all > 0.0 ? std::sqrt(spread_samples / spread_all) : 0.0;
  c.chatter = c.nonharmonic_fraction > options.chatter_energy_fraction &&
              c.sample_spread > options.chatter_sample_spread;
  return metrics;
}

}  // namespace robomill::simulation
