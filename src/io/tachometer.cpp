// The spindle speed from a pulse channel (io/tachometer.hpp).

#include "robomill/io/tachometer.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include "recording_detail.hpp"

namespace robomill::io {
namespace {

using recording_detail::fail;
using recording_detail::file_name;

/// Hysteresis of the edge detector, as fractions of the channel's range: a
/// pulse must fall below the low level before its rise through the high one
/// counts, so noise on a level does not count twice.
constexpr double kLowLevel = 0.3, kHighLevel = 0.7, kMidLevel = 0.5;
/// Pulse periods may vary this much (coefficient of variation) before the
/// channel is refused: a spindle's speed wanders by a few %, a missed or a
/// doubled pulse changes one period by half or by double.
constexpr double kMaxPeriodSpread = 0.25;
constexpr std::size_t kMinPulses = 3;
constexpr std::size_t kBlock = 65536;

/// The tachometer's own spec: the signal's file and stretch, its channel
/// (sound, uff) or column (mat, csv) in place of the signal's.
RecordingSpec tachometer_spec(const RecordingSpec& spec) {
  RecordingSpec tach = spec;
  tach.scale = 1.0;
  tach.ignore.clear();
  tach.path = (spec.path.empty() ? std::string("recording") : spec.path) + ".tachometer";
  if (spec.format == RecordingFormat::sound_file || spec.format == RecordingFormat::uff) {
    int channel = 0;
    const std::string& text = spec.tachometer;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), channel);
    if (error != std::errc() || end != text.data() + text.size() || channel < 1)
      fail(spec, "tachometer",
           fmt::format("expected the channel number (from 1) of the pulse train in {}, got '{}'",
                       file_name(spec), text));
    tach.channel = channel;
  } else {
    tach.column = spec.tachometer;
  }
  return tach;
}

/// Calls `visit(sample_index, value)` for every sample of a fresh reader;
/// returns the channel's sample rate (Hz).
template <class Visit>
double stream(const RecordingSpec& tach, Visit visit) {
  const auto source = open_recording(tach);
  std::vector<double> block(kBlock);
  std::size_t index = 0;
  for (std::size_t n; (n = source->read(block)) > 0;)
    for (std::size_t i = 0; i < n; ++i)
      visit(index++, block[i]);
  return source->info().sample_rate_hz;
}

}  // namespace

TachometerReading read_tachometer(const RecordingSpec& spec) {
  const RecordingSpec tach = tachometer_spec(spec);
  // Pass 1: the range (and the sample rate).
  double low = std::numeric_limits<double>::infinity(), high = -low;
  const double rate_hz = stream(tach, [&](std::size_t, double v) {
    if (std::isfinite(v)) {
      low = std::min(low, v);
      high = std::max(high, v);
    }
  });
  const double range = high - low;
  if (!(range > 0.0) || !std::isfinite(range))
    fail(spec, "tachometer",
         fmt::format("the pulse channel '{}' of {} is flat: no pulses to count", spec.tachometer,
                     file_name(spec)));
  // Pass 2: the rising edges, each at the time the signal crosses the middle
  // level (linear between the two samples around it); the periods' mean and
  // spread by Welford's update.
  const double low_level = low + kLowLevel * range, high_level = low + kHighLevel * range;
  const double mid_level = low + kMidLevel * range;
  bool armed = false;
  double previous = mid_level, crossing = 0.0, first_edge = 0.0, last_edge = 0.0;
  double mean_period = 0.0, period_m2 = 0.0;
  std::size_t pulses = 0;
  stream(tach, [&](std::size_t i, double v) {
    if (!std::isfinite(v)) {
      previous = v;
      return;
    }
    if (std::isfinite(previous) && previous < mid_level && v >= mid_level)
      crossing = (static_cast<double>(i) - 1.0 + (mid_level - previous) / (v - previous)) / rate_hz;
    if (v < low_level) {
      armed = true;
    } else if (armed && v >= high_level) {
      armed = false;
      if (pulses > 0) {
        const double period = crossing - last_edge;
        const auto k = static_cast<double>(pulses);
        const double delta = period - mean_period;
        mean_period += delta / k;
        period_m2 += delta * (period - mean_period);
      } else {
        first_edge = crossing;
      }
      last_edge = crossing;
      ++pulses;
    }
    previous = v;
  });
  if (pulses < kMinPulses)
    fail(spec, "tachometer",
         fmt::format("the pulse channel '{}' of {} holds {} pulse(s) in the stretch read: at least "
                     "{} are needed for a speed",
                     spec.tachometer, file_name(spec), pulses, kMinPulses));
  TachometerReading reading;
  reading.pulses = pulses;
  reading.spindle_hz = static_cast<double>(pulses - 1) / (last_edge - first_edge) /
                       static_cast<double>(spec.tachometer_pulses);
  reading.period_spread =
      std::sqrt(period_m2 / static_cast<double>(pulses - 1)) / std::max(mean_period, 1e-300);
  if (reading.period_spread > kMaxPeriodSpread)
    fail(spec, "tachometer",
         fmt::format("the pulse periods of channel '{}' of {} vary by {:.0f} % (at most {:.0f} %): "
                     "pulses are missed or doubled; check the channel and its level",
                     spec.tachometer, file_name(spec), 100.0 * reading.period_spread,
                     100.0 * kMaxPeriodSpread));
  return reading;
}

}  // namespace robomill::io
