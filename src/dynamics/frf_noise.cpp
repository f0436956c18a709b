#include "robomill/dynamics/frf_noise.hpp"

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

namespace robomill::dynamics {

void add_relative_noise(Frf& frf, double relative, std::uint32_t seed) {
  if (!(relative >= 0.0) || !std::isfinite(relative))
    throw std::invalid_argument("noise level must be finite and ≥ 0");
  std::mt19937 engine(seed);
  // Uniform in (0, 1]: 32 random bits, never 0, so the logarithm is finite.
  auto uniform = [&engine] { return (static_cast<double>(engine()) + 1.0) / 4294967296.0; };
  for (std::complex<double>& value : frf.value) {
    // Box-Muller: two independent standard normal deviates.
    const double radius = std::sqrt(-2.0 * std::log(uniform()));
    const double angle = 2.0 * std::numbers::pi * uniform();
    const std::complex<double> deviate(radius * std::cos(angle), radius * std::sin(angle));
    value += relative * std::abs(value) * deviate / std::sqrt(2.0);
  }
}

}  // namespace robomill::dynamics
