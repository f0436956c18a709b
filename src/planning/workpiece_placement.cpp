#include "robomill/planning/workpiece_placement.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace robomill::planning {

std::vector<PathPoint> rectangular_path(const Eigen::Vector3d& start_m, double length_m,
                                        double width_m, int points, bool counterclockwise) {
  if (!(length_m > 0.0) || !(width_m > 0.0) || !std::isfinite(length_m) || !std::isfinite(width_m))
    throw std::invalid_argument("rectangular_path: length and width must be positive");
  if (points < 1)
    throw std::invalid_argument("rectangular_path: at least one point");
  if (!start_m.allFinite())
    throw std::invalid_argument("rectangular_path: start must be finite");
  // The four sides in travel order: counterclockwise seen from +zw starts
  // along +xw, clockwise along +yw.
  const Eigen::Vector3d ex = Eigen::Vector3d::UnitX(), ey = Eigen::Vector3d::UnitY();
  const Eigen::Vector3d directions[4] = {
      counterclockwise ? ex : ey, counterclockwise ? ey : ex,
      counterclockwise ? Eigen::Vector3d(-ex) : Eigen::Vector3d(-ey),
      counterclockwise ? Eigen::Vector3d(-ey) : Eigen::Vector3d(-ex)};
  const double lengths[4] = {
      counterclockwise ? length_m : width_m, counterclockwise ? width_m : length_m,
      counterclockwise ? length_m : width_m, counterclockwise ? width_m : length_m};
  const double perimeter = 2.0 * (length_m + width_m);
  std::vector<PathPoint> path;
  path.reserve(static_cast<std::size_t>(points));
  for (int i = 0; i < points; ++i) {
    double s = perimeter * i / points;
    Eigen::Vector3d corner = start_m;
    int side = 0;
    // A point within round-off of a corner belongs to the side leaving it.
    while (side < 3 && s >= lengths[side] - 1e-12 * perimeter) {
      s -= lengths[side];
      corner += lengths[side] * directions[side];
      ++side;
    }
    s = std::max(s, 0.0);
    path.push_back({corner + s * directions[side], directions[side]});
  }
  return path;
}

std::vector<PathPoint> polyline_path(const std::vector<Eigen::Vector3d>& vertices_m, bool closed) {
  if (vertices_m.size() < 2)
    throw std::invalid_argument("polyline_path: at least two vertices");
  std::vector<PathPoint> path;
  path.reserve(vertices_m.size());
  const std::size_t n = vertices_m.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (!vertices_m[i].allFinite())
      throw std::invalid_argument("polyline_path: vertex " + std::to_string(i + 1) +
                                  " is not finite");
    Eigen::Vector3d step;
    if (i + 1 < n)
      step = vertices_m[i + 1] - vertices_m[i];
    else
      step = closed ? Eigen::Vector3d(vertices_m[0] - vertices_m[i])
                    : Eigen::Vector3d(vertices_m[i] - vertices_m[i - 1]);
    step.z() = 0.0;  // the feed lies in the part's plane (the tool axis is zw)
    if (!(step.norm() > 0.0))
      throw std::invalid_argument("polyline_path: vertex " + std::to_string(i + 1) +
                                  " has no feed direction (coincident with the next vertex in "
                                  "the xw-yw plane)");
    path.push_back({vertices_m[i], step.normalized()});
  }
  return path;
}

Eigen::Matrix3d fixture_rotation(TiltAxis axis, double theta_rad) {
  // Positive θp raises the part's +xw (or +yw) edge: a rotation about −yw
  // (or +xw).
  return axis == TiltAxis::y
             ? Eigen::AngleAxisd(-theta_rad, Eigen::Vector3d::UnitY()).toRotationMatrix()
             : Eigen::AngleAxisd(theta_rad, Eigen::Vector3d::UnitX()).toRotationMatrix();
}

Eigen::Isometry3d workpiece_to_cell(const Workcell& cell, const WorkpiecePose& pose) {
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  frame.linear() = fixture_rotation(cell.tilt_axis, pose.theta_rad);
  frame.translation() =
      cell.table_origin_m + Eigen::Vector3d(pose.x_m, pose.y_m, cell.workpiece_height_m);
  return frame;
}

PlacedPoint place(const Workcell& cell, const WorkpiecePose& pose, const PathPoint& point) {
  // 004 Eq 7: p_mi = p_c + p_w + R_w p_ni with p_w = [xp, yp, z_w].
  const Eigen::Isometry3d frame = workpiece_to_cell(cell, pose);
  const Eigen::Matrix3d r_w = frame.linear();
  PlacedPoint placed;
  placed.position_m = frame * point.position_m;
  // R_ni: tool x along the feed, z along the part normal, y = z × x.
  const Eigen::Vector3d z = r_w.col(2);
  Eigen::Vector3d x = r_w * point.feed_direction;
  x = (x - x.dot(z) * z).normalized();
  placed.tool_to_cell.col(0) = x;
  placed.tool_to_cell.col(1) = z.cross(x);
  placed.tool_to_cell.col(2) = z;
  return placed;
}

}  // namespace robomill::planning
