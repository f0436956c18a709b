#pragma once
// Unit constants shared by the library: one definition each, so that no two
// source files define the same name (a unity build joins them into one
// translation unit).

#include <numbers>

namespace robomill {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;
/// Degrees per radian.
inline constexpr double kDegPerRad = 180.0 / std::numbers::pi;
/// Radians per degree.
inline constexpr double kRadPerDeg = std::numbers::pi / 180.0;
/// rpm per rad/s.
inline constexpr double kRpmPerRadS = 60.0 / (2.0 * std::numbers::pi);
/// Metres per millimetre.
inline constexpr double kMillimetre = 1e-3;

}  // namespace robomill
