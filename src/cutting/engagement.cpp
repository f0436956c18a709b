#include "robomill/cutting/engagement.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace robomill::cutting {

std::string_view to_string(MillingDirection direction) noexcept {
  return direction == MillingDirection::down ? "down" : "up";
}

Engagement radial_engagement(double tool_radius_m, double edge_radius_m, double radial_depth_m,
                             MillingDirection direction) noexcept {
  constexpr double pi = std::numbers::pi;
  if (!(edge_radius_m > 0.0) || !(radial_depth_m > 0.0))
    return {0.0, 0.0};
  // Distance of the material's boundary line from the tool axis, signed along
  // +y for up milling (material at y ≥ R − ae) and −y for down milling.
  const double boundary_m = tool_radius_m - radial_depth_m;
  const double cosine = boundary_m / edge_radius_m;
  if (cosine >= 1.0)
    return {0.0, 0.0};  // this edge point never reaches the part
  const double arc = std::acos(std::max(cosine, -1.0));
  if (direction == MillingDirection::up)
    return {0.0, arc};
  return {pi - arc, pi};
}

double mean_chip_thickness_m(double feed_per_tooth_m, const Engagement& engagement) noexcept {
  if (engagement.empty())
    return 0.0;
  return feed_per_tooth_m * (std::cos(engagement.entry_rad) - std::cos(engagement.exit_rad)) /
         (engagement.exit_rad - engagement.entry_rad);
}

double wrap_angle_rad(double angle_rad) noexcept {
  constexpr double two_pi = 2.0 * std::numbers::pi;
  double wrapped = std::fmod(angle_rad, two_pi);
  if (wrapped < 0.0)
    wrapped += two_pi;
  return wrapped;
}

}  // namespace robomill::cutting
