#pragma once
// Circular and helical moves from what programs state: a centre and a turning
// sense (G2/G3 with I J K or R, APT CIRCLE), or three points (KRL CIRC). The
// readers share these so every dialect's arcs are checked the same way.

#include <Eigen/Core>
#include <optional>

#include "robomill/toolpath/program.hpp"

namespace robomill::toolpath {

/// Why an arc could not be built (the reader turns it into an error naming
/// the line and word).
enum class ArcProblem { none, zero_radius, radius_mismatch, collinear, start_is_end };

struct ArcResult {
  Move move;  ///< kind = arc; feed, spindle, tool and line left for the caller
  ArcProblem problem = ArcProblem::none;
  double start_radius_m = 0.0, end_radius_m = 0.0;  ///< in-plane distances from the centre
};

/// Arc from `start_m` to `end_m` about `centre_m` in the plane of unit
/// `normal`, turning clockwise (G2) or counter-clockwise (G3) seen from the
/// normal's tip, plus `extra_turns` full turns (G-code P). Start = end in the
/// plane is a full circle. The displacement along the normal makes it a helix.
/// The in-plane radii at start and end must agree to
/// max(`tolerance_m`, 1e-3 × radius) (LinuxCNC's check is 0.002 mm absolute
/// or 0.1 % relative, the same spirit); otherwise problem = radius_mismatch.
ArcResult arc_from_centre(const Eigen::Vector3d& start_m, const Eigen::Vector3d& end_m,
                          const Eigen::Vector3d& centre_m, const Eigen::Vector3d& normal,
                          bool clockwise, int extra_turns = 0, double tolerance_m = 2e-6);

/// Arc of signed radius `radius_m` (G-code R: positive takes the short way,
/// ≤ 180°; negative the long way) in the plane of `normal`. Start = end in the
/// plane cannot define a circle (start_is_end); |R| below half the chord is
/// widened to half the chord when within `tolerance_m`, else radius_mismatch.
ArcResult arc_from_radius(const Eigen::Vector3d& start_m, const Eigen::Vector3d& end_m,
                          double radius_m, const Eigen::Vector3d& normal, bool clockwise,
                          double tolerance_m = 2e-6);

/// Arc from `start_m` through `via_m` to `end_m` (KRL CIRC): the circle
/// through the three points, swept the way that passes `via_m`.
ArcResult arc_through(const Eigen::Vector3d& start_m, const Eigen::Vector3d& via_m,
                      const Eigen::Vector3d& end_m);

}  // namespace robomill::toolpath
