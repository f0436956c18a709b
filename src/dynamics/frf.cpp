#include "robomill/dynamics/frf.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "robomill/core/error.hpp"

namespace robomill::dynamics {
namespace {

// Receptance, mobility and accelerance are successive time derivatives of the
// response, so the distance between two kinds is a power of iω.
int derivative_order(FrfKind kind) noexcept {
  switch (kind) {
    case FrfKind::receptance:
      return 0;
    case FrfKind::mobility:
      return 1;
    case FrfKind::accelerance:
      return 2;
  }
  return 0;
}

void check_axis(int axis, const char* what) {
  if (axis < 0 || axis > 2)
    throw std::invalid_argument(std::string("FRF ") + what + " must be 0, 1 or 2, got " +
                                std::to_string(axis));
}

void check_grid(const std::vector<double>& frequency_hz) {
  if (frequency_hz.empty())
    throw std::invalid_argument("FRF frequency grid is empty");
  for (std::size_t i = 0; i < frequency_hz.size(); ++i) {
    const double f = frequency_hz[i];
    if (!std::isfinite(f) || f < 0.0)
      throw std::invalid_argument("FRF frequency " + std::to_string(i + 1) +
                                  " must be finite and >= 0 Hz, got " + std::to_string(f));
    if (i > 0 && !(f > frequency_hz[i - 1]))
      throw std::invalid_argument("FRF frequencies must be strictly increasing (point " +
                                  std::to_string(i + 1) + ")");
  }
}

// Refuses to hand out an overflowed result (a huge value divided by a tiny ω).
void check_values_finite(const Frf& frf) {
  for (std::size_t i = 0; i < frf.value.size(); ++i) {
    if (!std::isfinite(frf.value[i].real()) || !std::isfinite(frf.value[i].imag()))
      throw NumericalError("FRF value at " + std::to_string(frf.frequency_hz[i]) +
                           " Hz is not finite after conversion");
  }
}

}  // namespace

void validate(const Frf& frf) {
  check_grid(frf.frequency_hz);
  if (frf.value.size() != frf.frequency_hz.size())
    throw std::invalid_argument("FRF has " + std::to_string(frf.value.size()) + " values for " +
                                std::to_string(frf.frequency_hz.size()) + " frequencies");
  for (std::size_t i = 0; i < frf.value.size(); ++i) {
    if (!std::isfinite(frf.value[i].real()) || !std::isfinite(frf.value[i].imag()))
      throw std::invalid_argument("FRF value " + std::to_string(i + 1) + " is not finite");
  }
  check_axis(frf.response_axis, "response axis");
  check_axis(frf.reference_axis, "reference axis");
}

Frf convert(const Frf& frf, FrfKind to) {
  validate(frf);
  const int order = derivative_order(to) - derivative_order(frf.kind);
  Frf result = frf;
  result.kind = to;
  if (order == 0)
    return result;
  result.frequency_hz.clear();
  result.value.clear();
  for (std::size_t i = 0; i < frf.frequency_hz.size(); ++i) {
    const double f_hz = frf.frequency_hz[i];
    const std::complex<double> i_omega(0.0, 2.0 * std::numbers::pi * f_hz);
    std::complex<double> factor = 1.0;
    for (int k = 0; k < std::abs(order); ++k)
      factor *= i_omega;
    if (order < 0) {
      // Integrating has no value at ω = 0 (the static response is unbounded).
      if (f_hz == 0.0)
        continue;
      result.value.push_back(frf.value[i] / factor);
    } else {
      result.value.push_back(frf.value[i] * factor);
    }
    result.frequency_hz.push_back(f_hz);
  }
  if (result.frequency_hz.empty())
    throw std::invalid_argument("FRF has only a 0 Hz point, which cannot be integrated");
  check_values_finite(result);
  return result;
}

Frf synthesize(const ModalModel& modes, int response_axis, int reference_axis,
               const std::vector<double>& frequency_hz, FrfKind kind) {
  check_axis(response_axis, "response axis");
  check_axis(reference_axis, "reference axis");
  check_grid(frequency_hz);
  Frf frf;
  frf.frequency_hz = frequency_hz;
  frf.kind = kind;
  frf.response_axis = response_axis;
  frf.reference_axis = reference_axis;
  frf.label = "synthesized";
  frf.value.reserve(frequency_hz.size());
  const int order = derivative_order(kind);
  for (const double f_hz : frequency_hz) {
    const double omega = 2.0 * std::numbers::pi * f_hz;
    std::complex<double> receptance = 0.0;
    for (const Mode& mode : modes.modes()) {
      const double omega_n = 2.0 * std::numbers::pi * mode.natural_frequency_hz;
      const std::complex<double> denominator(omega_n * omega_n - omega * omega,
                                             2.0 * mode.damping_ratio * omega_n * omega);
      receptance += mode.shape[response_axis] * mode.shape[reference_axis] / denominator;
    }
    std::complex<double> value = receptance;
    for (int k = 0; k < order; ++k)
      value *= std::complex<double>(0.0, omega);
    frf.value.push_back(value);
  }
  check_values_finite(frf);
  return frf;
}

std::complex<double> interpolate(const Frf& frf, double frequency_hz) {
  if (frf.frequency_hz.empty() || frf.value.size() != frf.frequency_hz.size())
    throw std::invalid_argument("cannot interpolate an empty or inconsistent FRF");
  const double first_hz = frf.frequency_hz.front();
  const double last_hz = frf.frequency_hz.back();
  if (!(frequency_hz >= first_hz && frequency_hz <= last_hz))
    throw std::invalid_argument("frequency " + std::to_string(frequency_hz) +
                                " Hz is outside the FRF's range [" + std::to_string(first_hz) +
                                ", " + std::to_string(last_hz) + "] Hz");
  // First grid point strictly above f; f == last falls on the final point.
  const auto above =
      std::upper_bound(frf.frequency_hz.begin(), frf.frequency_hz.end(), frequency_hz);
  if (above == frf.frequency_hz.end())
    return frf.value.back();
  const auto upper = static_cast<std::size_t>(above - frf.frequency_hz.begin());
  const std::size_t lower = upper - 1;
  const double weight = (frequency_hz - frf.frequency_hz[lower]) /
                        (frf.frequency_hz[upper] - frf.frequency_hz[lower]);
  return frf.value[lower] + weight * (frf.value[upper] - frf.value[lower]);
}

const char* kind_name(FrfKind kind) noexcept {
  switch (kind) {
    case FrfKind::receptance:
      return "receptance";
    case FrfKind::mobility:
      return "mobility";
    case FrfKind::accelerance:
      return "accelerance";
  }
  return "unknown";
}

}  // namespace robomill::dynamics
