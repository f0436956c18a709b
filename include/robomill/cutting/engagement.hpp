#pragma once
// Where an edge is in the material: the radial engagement (entry and exit
// angles) and the undeformed chip thickness.

#include "robomill/cutting/process.hpp"

namespace robomill::cutting {

/// Entry and exit angles φst ≤ φ ≤ φex of the cut, measured like every edge
/// angle (clockwise from +y, tool frame).
struct Engagement {
  double entry_rad = 0.0;
  double exit_rad = 0.0;
  bool empty() const noexcept { return !(exit_rad > entry_rad); }
};

/// Engagement of an edge point at radius `edge_radius_m` when the cutter of
/// radius `tool_radius_m` removes a radial depth ae. The material is the band
/// y ≥ R − ae (up milling) or y ≤ ae − R (down milling) ahead of the tool, so
/// for a full-radius edge this is Altintas' φst = 0, φex = acos(1 − ae/R) (up)
/// and φst = acos(ae/R − 1), φex = π (down); edge points of smaller radius (on a
/// ball nose) see a narrower arc or none. ae ≥ 2R is a slot, [0, π].
Engagement radial_engagement(double tool_radius_m, double edge_radius_m, double radial_depth_m,
                             MillingDirection direction) noexcept;

/// Mean undeformed chip thickness over the engagement,
/// t_c = fz (cos φst − cos φex) / (φex − φst); for up milling this is
/// 004 Eq A3, t_c = fz (ae/R) / acos(1 − ae/R).
double mean_chip_thickness_m(double feed_per_tooth_m, const Engagement& engagement) noexcept;

/// Wraps an angle to [0, 2π).
double wrap_angle_rad(double angle_rad) noexcept;

}  // namespace robomill::cutting
