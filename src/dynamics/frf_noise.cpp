#include "robomill/dynamics/frf_noise.hpp"

#include <cmath>
#include <stdexcept>

#include "robomill/core/random.hpp"

namespace robomill::dynamics {

void add_relative_noise(Frf& frf, double relative, std::uint32_t seed) {
  if (!(relative >= 0.0) || !std::isfinite(relative))
    throw std::invalid_argument("noise level must be finite and ≥ 0");
  core::StandardNormal normal(seed);
  for (std::complex<double>& value : frf.value) {
    const double real = normal();
    const double imaginary = normal();
    value += relative * std::abs(value) * std::complex<double>(real, imaginary) / std::sqrt(2.0);
  }
}

}  // namespace robomill::dynamics
