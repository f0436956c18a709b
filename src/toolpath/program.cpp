#include "robomill/toolpath/program.hpp"

#include <algorithm>
#include <cmath>

namespace robomill::toolpath {
namespace {

// The arc's in-plane radius vector at the start, and the lift along the normal
// that a helical arc adds over its whole sweep.
struct ArcFrame {
  Eigen::Vector3d radial;  // start − centre, in the plane
  double lift_m;           // (end − start) · normal
};

ArcFrame arc_frame(const Move& move) noexcept {
  const Eigen::Vector3d from_centre = move.start_m - move.centre_m;
  const double out_of_plane = from_centre.dot(move.normal);
  return {from_centre - out_of_plane * move.normal, (move.end_m - move.start_m).dot(move.normal)};
}

}  // namespace

double path_length_m(const Move& move) noexcept {
  switch (move.kind) {
    case MotionKind::dwell:
      return 0.0;
    case MotionKind::arc: {
      const ArcFrame frame = arc_frame(move);
      const double arc_m = frame.radial.norm() * std::abs(move.sweep_rad);
      return std::hypot(arc_m, frame.lift_m);
    }
    default:
      return (move.end_m - move.start_m).norm();
  }
}

Eigen::Vector3d position_at(const Move& move, double u) noexcept {
  u = std::clamp(u, 0.0, 1.0);
  if (move.kind == MotionKind::dwell)
    return move.start_m;
  if (move.kind != MotionKind::arc)
    return move.start_m + u * (move.end_m - move.start_m);
  if (u >= 1.0)
    return move.end_m;  // exactly the programmed end, free of round-off
  const ArcFrame frame = arc_frame(move);
  const Eigen::AngleAxisd turn(u * move.sweep_rad, move.normal);
  const Eigen::Vector3d in_plane_centre =
      move.centre_m + (move.start_m - move.centre_m).dot(move.normal) * move.normal;
  return in_plane_centre + turn * frame.radial + u * frame.lift_m * move.normal;
}

Eigen::Vector3d tangent_at(const Move& move, double u) noexcept {
  u = std::clamp(u, 0.0, 1.0);
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  if (move.kind == MotionKind::arc) {
    const ArcFrame frame = arc_frame(move);
    const Eigen::AngleAxisd turn(u * move.sweep_rad, move.normal);
    // d/du of the position: the sweep times the normal × radius, plus the lift.
    direction =
        move.sweep_rad * move.normal.cross(turn * frame.radial) + frame.lift_m * move.normal;
  } else if (move.kind != MotionKind::dwell) {
    direction = move.end_m - move.start_m;
  }
  const double norm = direction.norm();
  return norm > 0.0 ? Eigen::Vector3d(direction / norm) : axis_at(move, u);
}

Eigen::Vector3d axis_at(const Move& move, double u) noexcept {
  if (move.kind != MotionKind::linear && move.kind != MotionKind::rapid)
    return move.axis_start;
  const Eigen::Quaterniond identity = Eigen::Quaterniond::Identity();
  const Eigen::Quaterniond rotation =
      Eigen::Quaterniond::FromTwoVectors(move.axis_start, move.axis_end);
  return (identity.slerp(std::clamp(u, 0.0, 1.0), rotation) * move.axis_start).normalized();
}

Eigen::Vector3d tool_x_at(const Move& move, double u) noexcept {
  const Eigen::Vector3d axis = axis_at(move, u);
  auto normal_part = [&](const Eigen::Vector3d& x) -> Eigen::Vector3d {
    const Eigen::Vector3d n = x - x.dot(axis) * axis;
    return n.norm() > 1e-9 ? Eigen::Vector3d(n.normalized()) : axis.unitOrthogonal();
  };
  const Eigen::Vector3d from = normal_part(move.tool_x_start), to = normal_part(move.tool_x_end);
  const double angle = std::atan2(from.cross(to).dot(axis), from.dot(to));
  return Eigen::AngleAxisd(std::clamp(u, 0.0, 1.0) * angle, axis) * from;
}

double duration_s(const Move& move, double rapid_m_s) noexcept {
  switch (move.kind) {
    case MotionKind::dwell:
      return move.dwell_s;
    case MotionKind::rapid:
      return rapid_m_s > 0.0 ? path_length_m(move) / rapid_m_s : 0.0;
    default:
      return move.feed_m_s > 0.0 ? path_length_m(move) / move.feed_m_s : 0.0;
  }
}

void apply_transform(Program& program, const Eigen::Isometry3d& program_to_workpiece) {
  const Eigen::Matrix3d rotation = program_to_workpiece.linear();
  for (Move& move : program.moves) {
    move.start_m = program_to_workpiece * move.start_m;
    move.end_m = program_to_workpiece * move.end_m;
    move.centre_m = program_to_workpiece * move.centre_m;
    move.axis_start = rotation * move.axis_start;
    move.axis_end = rotation * move.axis_end;
    move.tool_x_start = rotation * move.tool_x_start;
    move.tool_x_end = rotation * move.tool_x_end;
    move.normal = rotation * move.normal;
  }
}

}  // namespace robomill::toolpath
