#include "robomill/toolpath/arc.hpp"

#include <algorithm>
#include <cmath>

#include "robomill/core/constants.hpp"

namespace robomill::toolpath {
namespace {

// Signed angle from a to b about n (both in the plane normal to n), in (−π, π].
double signed_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& n) {
  return std::atan2(n.dot(a.cross(b)), a.dot(b));
}

Eigen::Vector3d in_plane(const Eigen::Vector3d& v, const Eigen::Vector3d& n) {
  return v - v.dot(n) * n;
}

}  // namespace

ArcResult arc_from_centre(const Eigen::Vector3d& start_m, const Eigen::Vector3d& end_m,
                          const Eigen::Vector3d& centre_m, const Eigen::Vector3d& normal,
                          bool clockwise, int extra_turns, double tolerance_m) {
  ArcResult result;
  Move& move = result.move;
  move.kind = MotionKind::arc;
  move.start_m = start_m;
  move.end_m = end_m;
  move.normal = normal.normalized();
  // The centre in the start's plane: a helix's centre is given at either end's
  // height by different programs; only its in-plane position matters.
  move.centre_m = centre_m + (start_m - centre_m).dot(move.normal) * move.normal;
  const Eigen::Vector3d from = in_plane(start_m - centre_m, move.normal);
  const Eigen::Vector3d to = in_plane(end_m - centre_m, move.normal);
  result.start_radius_m = from.norm();
  result.end_radius_m = to.norm();
  if (result.start_radius_m <= 0.0 || result.end_radius_m <= 0.0) {
    result.problem = ArcProblem::zero_radius;
    return result;
  }
  const double allowed = std::max(tolerance_m, 1e-3 * result.start_radius_m);
  if (std::abs(result.start_radius_m - result.end_radius_m) > allowed) {
    result.problem = ArcProblem::radius_mismatch;
    return result;
  }
  // Sweep in the programmed sense; equal in-plane ends are a full turn.
  double sweep = signed_angle(from, to, move.normal);  // counter-clockwise positive
  const bool full_circle = (from - to).norm() <= 1e-9 + 1e-9 * result.start_radius_m;
  if (clockwise) {
    if (full_circle || sweep >= 0.0)
      sweep -= kTwoPi;
    if (full_circle)
      sweep = -kTwoPi;
  } else {
    if (full_circle || sweep <= 0.0)
      sweep += kTwoPi;
    if (full_circle)
      sweep = kTwoPi;
  }
  sweep += (clockwise ? -1.0 : 1.0) * kTwoPi * std::max(0, extra_turns);
  move.sweep_rad = sweep;
  return result;
}

ArcResult arc_from_radius(const Eigen::Vector3d& start_m, const Eigen::Vector3d& end_m,
                          double radius_m, const Eigen::Vector3d& normal, bool clockwise,
                          double tolerance_m) {
  const Eigen::Vector3d n = normal.normalized();
  const Eigen::Vector3d chord = in_plane(end_m - start_m, n);
  const double half_chord = 0.5 * chord.norm();
  ArcResult result;
  result.move.kind = MotionKind::arc;
  if (half_chord <= 1e-12) {
    result.problem = ArcProblem::start_is_end;
    return result;
  }
  double radius = std::abs(radius_m);
  if (radius < half_chord) {
    if (half_chord - radius > tolerance_m) {
      result.problem = ArcProblem::radius_mismatch;
      result.start_radius_m = radius;
      result.end_radius_m = half_chord;
      return result;
    }
    radius = half_chord;
  }
  // Centre on the chord's perpendicular bisector: to the left of the chord
  // (about n) for a counter-clockwise short arc, to the right for clockwise;
  // a negative R (long way) takes the other side.
  const double offset = std::sqrt(std::max(0.0, radius * radius - half_chord * half_chord));
  const Eigen::Vector3d left = n.cross(chord).normalized();
  double side = clockwise ? -1.0 : 1.0;
  if (radius_m < 0.0)
    side = -side;
  const Eigen::Vector3d centre = start_m + 0.5 * chord + side * offset * left;
  return arc_from_centre(start_m, end_m, centre, n, clockwise, 0, tolerance_m + 1e-9 * radius);
}

ArcResult arc_through(const Eigen::Vector3d& start_m, const Eigen::Vector3d& via_m,
                      const Eigen::Vector3d& end_m) {
  ArcResult result;
  result.move.kind = MotionKind::arc;
  const Eigen::Vector3d a = via_m - start_m;
  const Eigen::Vector3d b = end_m - start_m;
  const Eigen::Vector3d n = a.cross(b);
  const double n2 = n.squaredNorm();
  if (n2 <= 1e-24 * a.squaredNorm() * b.squaredNorm() || n2 == 0.0) {
    result.problem = (b.norm() <= 1e-12) ? ArcProblem::start_is_end : ArcProblem::collinear;
    return result;
  }
  // Circumcentre of the triangle (start, via, end).
  const Eigen::Vector3d centre =
      start_m + (b.squaredNorm() * n.cross(a) + a.squaredNorm() * b.cross(n)) / (2.0 * n2);
  // With normal a × b the path start → via → end turns counter-clockwise.
  return arc_from_centre(start_m, end_m, centre, n / std::sqrt(n2), false, 0,
                         1e-9 * (start_m - centre).norm() + 1e-12);
}

}  // namespace robomill::toolpath
