#pragma once
// The solid a milling cutter sweeps: what material removal and engagement see
// of a tool/tool.hpp cutter (flat end: a cylinder; ball end: a cylinder on a
// hemisphere). Tool frame as in tool.hpp: origin at the tip, z along the axis
// towards the spindle.

#include "robomill/tool/tool.hpp"

namespace robomill::toolpath {

struct CutterShape {
  double radius_m = 0.0;         ///< R
  double corner_radius_m = 0.0;  ///< 0: flat end; R: ball end
  double length_m = 0.0;         ///< solid length from the tip (the tool's overhang)

  bool is_ball() const noexcept { return corner_radius_m > 0.0; }
  /// Radius of the cutter's surface at height z above the tip (0 ≤ z ≤ length).
  double radius_at(double height_m) const noexcept;
};

/// The shape of a validated tool: its radius, R for a ball end, its overhang.
CutterShape cutter_shape(const tool::Tool& tool) noexcept;

}  // namespace robomill::toolpath
