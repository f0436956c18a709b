// Signals in memory and the names of signal kinds (signal_source.hpp).

#include "robomill/monitoring/signal_source.hpp"

#include <algorithm>
#include <stdexcept>

namespace robomill::monitoring {

const char* signal_kind_name(SignalKind kind) noexcept {
  switch (kind) {
    case SignalKind::sound:
      return "sound";
    case SignalKind::acceleration:
      return "acceleration";
    case SignalKind::velocity:
      return "velocity";
    case SignalKind::displacement:
      return "displacement";
    case SignalKind::force:
      return "force";
  }
  return "unknown";
}

const char* signal_kind_unit(SignalKind kind) noexcept {
  switch (kind) {
    case SignalKind::sound:
      return "Pa";
    case SignalKind::acceleration:
      return "m/s^2";
    case SignalKind::velocity:
      return "m/s";
    case SignalKind::displacement:
      return "m";
    case SignalKind::force:
      return "N";
  }
  return "";
}

VectorSource::VectorSource(std::vector<double> samples, double sample_rate_hz, SignalKind kind,
                           double full_scale)
    : samples_(std::move(samples)) {
  if (!(sample_rate_hz > 0.0))
    throw std::invalid_argument("VectorSource: the sample rate must be > 0");
  info_.sample_rate_hz = sample_rate_hz;
  info_.samples = static_cast<std::int64_t>(samples_.size());
  info_.kind = kind;
  info_.full_scale = full_scale;
  info_.description = "signal in memory, " + std::to_string(samples_.size()) + " samples";
}

std::size_t VectorSource::read(std::span<double> out) {
  const std::size_t count = std::min(out.size(), samples_.size() - next_);
  std::copy_n(samples_.begin() + static_cast<std::ptrdiff_t>(next_), count, out.begin());
  next_ += count;
  return count;
}

}  // namespace robomill::monitoring
