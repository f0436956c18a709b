#pragma once
// Reproducible normal deviates for synthetic measurements (FRF noise, loading
// tests). std::normal_distribution is implementation-defined, so the same
// seed would give different data with another standard library; std::mt19937
// is fully specified by the C++ standard, and the Box-Muller transform is
// written here.

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

namespace robomill::core {

/// Standard normal deviates N(0, 1): Box-Muller pairs (r cos a, r sin a) from
/// two uniform draws of an std::mt19937, handed out in that order.
class StandardNormal {
 public:
  explicit StandardNormal(std::uint32_t seed) : engine_(seed) {}

  double operator()() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double radius = std::sqrt(-2.0 * std::log(uniform()));
    const double angle = 2.0 * std::numbers::pi * uniform();
    spare_ = radius * std::sin(angle);
    has_spare_ = true;
    return radius * std::cos(angle);
  }

 private:
  /// Uniform in (0, 1]: 32 random bits, never 0, so the logarithm is finite.
  double uniform() { return (static_cast<double>(engine_()) + 1.0) / 4294967296.0; }

  std::mt19937 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace robomill::core
