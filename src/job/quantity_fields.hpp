#pragma once
// Private to the job parser: the documented units of job fields (DESIGN.md
// §3: a bare number is read in them) and the QuantityField builders every
// section parser uses, so each section says only its schema.

#include <optional>
#include <string_view>

#include "robomill/core/constants.hpp"
#include "robomill/job/units.hpp"
#include "yaml_reader.hpp"

namespace robomill::job::detail {

inline constexpr double kMm = 1e-3;
inline constexpr double kDeg = kPi / 180.0;
inline constexpr double kRpm = 2.0 * kPi / 60.0;

inline constexpr Bound kPositive{0.0, false};
inline constexpr Bound kNonNegative{0.0, true};

/// A field of `dimension` whose bare numbers are in `unit` (SI value `unit_si`).
inline QuantityField field(Dimension dimension, double unit_si, std::string_view unit,
                           std::optional<Bound> min = {}, std::optional<Bound> max = {}) {
  QuantityField result;
  result.dimension = dimension;
  result.unit_si = unit_si;
  result.unit = unit;
  result.min = min;
  result.max = max;
  return result;
}

/// A length in mm, positive unless said otherwise.
inline QuantityField length_mm(std::optional<Bound> min = kPositive,
                               std::optional<Bound> max = {}) {
  return field(dimensions::length, kMm, "mm", min, max);
}

/// An angle in degrees.
inline QuantityField angle_deg(std::optional<Bound> min = {}, std::optional<Bound> max = {}) {
  return field(dimensions::angle, kDeg, "deg", min, max);
}

inline QuantityField dimensionless(std::optional<Bound> min = {}, std::optional<Bound> max = {}) {
  return field(dimensions::none, 1.0, "", min, max);
}

}  // namespace robomill::job::detail
