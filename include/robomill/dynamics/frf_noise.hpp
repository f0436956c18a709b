#pragma once
// Measurement-like noise on a synthesized FRF, for test data and for checking
// how a fit or a stability prediction degrades with noisy measurements.

#include <cstdint>

#include "robomill/dynamics/frf.hpp"

namespace robomill::dynamics {

/// Adds complex noise proportional to the magnitude at each point:
///   H ← H + relative · |H| · (n₁ + i n₂)/√2,  n₁, n₂ ~ N(0, 1),
/// so the noise's RMS magnitude is `relative`·|H| ("2 % complex noise").
/// The normal deviates come from std::mt19937 (fully specified by the C++
/// standard) through the Box-Muller transform written here, so a seed gives
/// the same data with any standard library.
void add_relative_noise(Frf& frf, double relative, std::uint32_t seed);

}  // namespace robomill::dynamics
