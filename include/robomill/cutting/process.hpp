#pragma once
// The cutting conditions of one milling operation, in SI units.

#include <string_view>

namespace robomill::cutting {

/// Down (climb) milling: the tooth enters thick and leaves at zero chip
/// thickness; up (conventional) milling: the reverse.
enum class MillingDirection { down, up };

std::string_view to_string(MillingDirection direction) noexcept;

struct MillingProcess {
  double spindle_rad_s = 0.0;
  double feed_per_tooth_m = 0.0;
  double axial_depth_m = 0.0;   ///< ap
  double radial_depth_m = 0.0;  ///< ae
  MillingDirection direction = MillingDirection::down;
};

}  // namespace robomill::cutting
