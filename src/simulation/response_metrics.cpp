// Static deviation, overshoot, settling, first frequency and the chatter
// verdict of a simulated response (response_metrics.hpp).

#include "robomill/simulation/response_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "robomill/core/constants.hpp"
#include "robomill/monitoring/harmonic_comb.hpp"
#include "robomill/monitoring/spectrum.hpp"

namespace robomill::simulation {
namespace {

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

/// Samples spanning `periods` forced periods of `per_period` samples each
/// (not necessarily a whole number: a recorded signal, or a simulation kept
/// every k-th step): rounded once, so that windows of whole periods put the
/// forced harmonics on the spectrum's bins to within half a sample.
std::size_t samples_of(double periods, double per_period) {
  return static_cast<std::size_t>(std::llround(periods * per_period));
}

/// Samples [from, to) of one direction less a straight line through the
/// means of its forced periods (least squares): a drift of the static
/// deviation is not vibration. Fitted to the period means, the line of a
/// periodic response is flat, so the forced vibration is left untouched (a
/// line fitted to the samples themselves would tilt with it and leak a
/// low-frequency sawtooth into the non-harmonic part).
std::vector<double> detrended(const std::vector<Eigen::Vector3d>& series, int axis,
                              std::size_t from, std::size_t to, double per_period) {
  std::vector<double> out = component(series, axis, from, to);
  const auto periods =
      static_cast<std::size_t>(std::floor(static_cast<double>(out.size()) / per_period + 1e-9));
  if (periods < 2)
    return out;
  // Period means at the periods' centres, in samples from `from`.
  double sum_t = 0.0, sum_m = 0.0, sum_tt = 0.0, sum_tm = 0.0;
  for (std::size_t p = 0; p < periods; ++p) {
    const std::size_t begin = samples_of(static_cast<double>(p), per_period);
    const std::size_t end =
        std::min(out.size(), samples_of(static_cast<double>(p + 1), per_period));
    double m = 0.0;
    for (std::size_t i = begin; i < end; ++i)
      m += out[i];
    m /= static_cast<double>(end - begin);
    const double t = 0.5 * static_cast<double>(begin + end - 1);
    sum_t += t;
    sum_m += m;
    sum_tt += t * t;
    sum_tm += t * m;
  }
  const double n = static_cast<double>(periods);
  const double slope = (n * sum_tm - sum_t * sum_m) / (n * sum_tt - sum_t * sum_t);
  const double intercept = (sum_m - slope * sum_t) / n;
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] -= intercept + slope * static_cast<double>(i);
  return out;
}

/// The Hann spectrum of one direction split into the harmonics of the forced
/// frequency (within 2.5 bins: the window's main lobe) and the rest, above
/// three resolution bins (what is left of a drift below that): the monitoring
/// module's attribution (monitoring/harmonic_comb.hpp), the same rule the
/// recorded-signal detector applies. Energies are sums of squared
/// amplitudes: a sinusoid of amplitude A at a bin fills it with A and its two
/// neighbours with A/2, 1.5 A² in all, for a mean square of A²/2, so RMS² =
/// energy / 3 (Parseval, for any stationary signal).
monitoring::HarmonicSplit split_spectrum(const std::vector<double>& samples, double interval_s,
                                         double forced_hz) {
  bool moves = false;
  for (double v : samples)
    moves = moves || v != 0.0;
  if (!moves)
    return {};
  return monitoring::split_harmonics(monitoring::amplitude_spectrum(samples, interval_s, 1),
                                     forced_hz, 2.5, 3.0);
}

}  // namespace

const char* chatter_floor_name(ChatterFloor floor) noexcept {
  return floor == ChatterFloor::feed_per_tooth ? "feed_per_tooth" : "numerical";
}

ChatterVerdict detect_chatter(const std::vector<Eigen::Vector3d>& displacement_m, double interval_s,
                              double forced_period_s, double feed_per_tooth_m,
                              const ChatterOptions& options) {
  if (!(interval_s > 0.0) || !(forced_period_s > 0.0))
    throw std::invalid_argument("detect_chatter: the interval and the forced period must be > 0");
  const double per_period = forced_period_s / interval_s;
  // The last whole forced periods of the series (all of it when it holds
  // whole periods, as analyze_response's steady window does).
  const auto periods = static_cast<std::size_t>(
      std::floor(static_cast<double>(displacement_m.size()) / per_period + 1e-9));
  const std::size_t count =
      std::min(displacement_m.size(), samples_of(static_cast<double>(periods), per_period));
  if (periods < 1 || count < 8)
    throw std::invalid_argument("detect_chatter: needs 8 samples and one forced period");
  const std::size_t from = displacement_m.size() - count, to = displacement_m.size();
  const double forced_hz = 1.0 / forced_period_s;
  // The halves for the persistence: whole forced periods each, when the
  // window holds at least four.
  const std::size_t half = samples_of(static_cast<double>(periods / 2), per_period);
  const bool judge_persistence = periods >= 4 && half >= 8;

  ChatterVerdict c;
  double harmonic = 0.0, nonharmonic = 0.0, first = 0.0, second = 0.0, best = 0.0;
  double spread_samples = 0.0, variance_all = 0.0, static_sq = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    const std::vector<double> raw = component(displacement_m, axis, from, to);
    const double mean = mean_of(raw);
    static_sq += mean * mean;
    for (double v : raw)
      variance_all += (v - mean) * (v - mean) / static_cast<double>(count);

    // The non-harmonic part: the spectrum away from the forced harmonics.
    const monitoring::HarmonicSplit all = split_spectrum(
        detrended(displacement_m, axis, from, to, per_period), interval_s, forced_hz);
    harmonic += all.harmonic;
    nonharmonic += all.nonharmonic;
    if (all.peak_amplitude > best) {
      best = all.peak_amplitude;
      c.frequency_hz = all.peak_hz;
    }
    if (judge_persistence) {
      first += split_spectrum(detrended(displacement_m, axis, from, from + half, per_period),
                              interval_s, forced_hz)
                   .nonharmonic;
      second += split_spectrum(detrended(displacement_m, axis, to - half, to, per_period),
                               interval_s, forced_hz)
                    .nonharmonic;
    }

    // Evidence (reported, not a gate): the displacement sampled once per
    // forced period, a Poincaré section that a periodic response collapses
    // to a point.
    std::vector<double> sampled;
    for (std::size_t p = 0; p < periods; ++p)
      sampled.push_back(raw[std::min(count - 1, samples_of(static_cast<double>(p), per_period))]);
    const double sampled_mean = mean_of(sampled);
    double sampled_variance = 0.0;
    for (double v : sampled)
      sampled_variance += (v - sampled_mean) * (v - sampled_mean);
    spread_samples += sampled_variance / static_cast<double>(sampled.size());
  }
  c.nonharmonic_fraction =
      harmonic + nonharmonic > 0.0 ? nonharmonic / (harmonic + nonharmonic) : 0.0;
  c.sample_spread = variance_all > 0.0 ? std::sqrt(spread_samples / variance_all) : 0.0;
  c.nonharmonic_rms_m = std::sqrt(nonharmonic / 3.0);
  c.forced_rms_m = std::sqrt(harmonic / 3.0);
  c.persistence = judge_persistence ? (first > 0.0 ? std::sqrt(second / first) : 0.0) : 1.0;

  const double feed_floor = options.floor_feed_fraction * std::max(0.0, feed_per_tooth_m);
  const double numerical_floor =
      options.floor_numerical_fraction * std::max(std::sqrt(static_sq), std::sqrt(variance_all));
  c.floor = feed_floor >= numerical_floor ? ChatterFloor::feed_per_tooth : ChatterFloor::numerical;
  c.floor_m = std::max(feed_floor, numerical_floor);
  c.chatter = c.nonharmonic_rms_m > c.floor_m && c.persistence >= options.min_persistence;
  return c;
}

ResponseMetrics analyze_response(const SimulationResult& result, const ResponseOptions& options) {
  const std::size_t count = result.size();
  const double dt = result.record_interval_s;
  if (count < 8 || !(dt > 0.0) || !(options.spindle_rad_s > 0.0) || options.teeth < 1)
    throw std::invalid_argument("analyze_response: too few samples or no process");
  const double tooth_period_s = kTwoPi / (options.spindle_rad_s * options.teeth);
  const double forced_period_s = options.runout ? kTwoPi / options.spindle_rad_s : tooth_period_s;
  const auto tooth_samples = std::max<std::size_t>(1, std::llround(tooth_period_s / dt));
  const auto periods =
      static_cast<std::size_t>(std::floor(options.steady_window_s / forced_period_s + 1e-9));
  const auto window =
      static_cast<std::size_t>(std::llround(static_cast<double>(periods) * forced_period_s / dt));
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
      const monitoring::AmplitudeSpectrum spectrum = monitoring::amplitude_spectrum(after, dt, 8);
      d.first_frequency_hz = monitoring::resonance_frequency_hz(
          spectrum, 1.5 * spectrum.resolution_hz, 0.5 * spindle_hz);
    }
  }

  // The chatter verdict over the steady window (whole forced periods).
  const std::vector<Eigen::Vector3d> steady(
      result.displacement_m.begin() + static_cast<std::ptrdiff_t>(steady_from),
      result.displacement_m.begin() + static_cast<std::ptrdiff_t>(end));
  metrics.chatter =
      detect_chatter(steady, dt, forced_period_s, options.feed_per_tooth_m, options.chatter);
  return metrics;
}

}  // namespace robomill::simulation
