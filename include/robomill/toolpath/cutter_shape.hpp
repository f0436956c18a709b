#pragma once
// The solid a milling cutter sweeps: what material removal and engagement see
// of a tool/tool.hpp cutter (flat end: a cylinder; ball end: a cylinder on a
// hemisphere; bull nose: a cylinder whose end is rounded by a torus corner). Tool frame as in
// tool.hpp: origin at the tip, z along the axis towards the spindle.

#include "robomill/tool/tool.hpp"

namespace robomill::toolpath {

struct CutterShape {
  double radius_m = 0.0;         ///< R
  double corner_radius_m = 0.0;  ///< 0: flat end; R: ball end; between: bull nose
  double length_m = 0.0;         ///< solid length from the tip (the tool's overhang)

  /// A rounded end (ball or bull nose): the end is not a flat disc.
  bool has_corner() const noexcept { return corner_radius_m > 0.0; }
  bool is_ball() const noexcept { return corner_radius_m >= radius_m; }
  /// A bull nose: a torus corner with a flat end inside it, 0 < r_c < R.
  bool is_bull() const noexcept { return has_corner() && !is_ball(); }
  /// Radius of the cutter's surface at height z above the tip (0 ≤ z ≤ length).
  double radius_at(double height_m) const noexcept;
};

/// The shape of a validated tool: its radius, its corner radius (R for a ball
/// end), its overhang.
CutterShape cutter_shape(const tool::Tool& tool) noexcept;

}  // namespace robomill::toolpath
