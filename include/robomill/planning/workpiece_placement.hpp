#pragma once
// Where the part sits and where its tool path goes (004 §3.3 Eq 7, §4.1).
//
// A workpiece is fixed on an inclinable fixture on a work table. Its pose on
// the table is p = (xp, yp, θp): the fixture's position on the table top and
// its inclination. A tool path is given in the workpiece frame {w} (xw, yw in
// the part's top plane, zw its normal) as points with their feed direction;
// placing it gives, for every point i, the tool-tip position and the tool
// frame in the cell (robot) frame:
//
//   p_mi = p_c + p_w + R_w(θp) p_ni,      p_w = [xp, yp, z_w]ᵀ        (004 Eq 7)
//   F_Ei = R_ni F'                                                     (004 Eq 7)
//
// with p_c the table origin, z_w the height of the workpiece origin above it,
// R_w the fixture's inclination and R_ni the tool frame of point i: x along
// the feed, z along the part's normal (from the tip into the spindle), y = z × x
// (robomill's tool frame, docs/theory.md).
//
// The paper names the inclination R_wz(θp) but draws no axis; its Figure 7c
// (the force's z component grows with θp) needs a tilt about a horizontal
// axis. `TiltAxis` makes the choice explicit (docs/planning.md).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace robomill::planning {

/// p = (xp, yp, θp) of 004 Eq 8.
struct WorkpiecePose {
  double x_m = 0.0;
  double y_m = 0.0;
  double theta_rad = 0.0;
};

/// The fixture's hinge: the workpiece axis about which θp inclines the part.
/// `y`: the part's +xw edge rises (xw → (cos θp, 0, sin θp)); `x`: its +yw
/// edge rises (yw → (0, cos θp, sin θp)).
enum class TiltAxis { x, y };

/// The work table (004 §4.1): fixed in the cell, axes parallel to the cell's.
struct Workcell {
  Eigen::Vector3d table_origin_m = Eigen::Vector3d::Zero();  ///< p_c, cell frame
  double workpiece_height_m = 0.0;                           ///< z_w above the table top
  TiltAxis tilt_axis = TiltAxis::y;
};

/// A point of the tool path in the workpiece frame.
struct PathPoint {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d feed_direction = Eigen::Vector3d::UnitX();  ///< unit, in the xw-yw plane
};

/// `points` points equally spaced (by arc length) along the closed rectangle
/// whose first corner is `start_m` and whose sides run `length_m` along xw and
/// `width_m` along yw, counterclockwise (seen from +zw: first along +xw) or
/// clockwise (first along +yw). A point on a corner takes the direction of
/// the side that leaves it. Throws std::invalid_argument for non-positive
/// sizes or fewer than one point.
std::vector<PathPoint> rectangular_path(const Eigen::Vector3d& start_m, double length_m,
                                        double width_m, int points, bool counterclockwise);

/// A path through given vertices (workpiece frame): the feed at vertex i
/// points towards vertex i+1; at the last vertex towards the first when
/// `closed`, else along the last segment. Throws std::invalid_argument for
/// fewer than two vertices or two consecutive coincident ones.
std::vector<PathPoint> polyline_path(const std::vector<Eigen::Vector3d>& vertices_m, bool closed);

/// R_w(θp): workpiece frame → table (cell-parallel) frame.
Eigen::Matrix3d fixture_rotation(TiltAxis axis, double theta_rad);

/// 004 Eq 7 as a frame: workpiece frame → cell frame, p_m = p_c + p_w + R_w(θp) p_n
/// with p_w = [xp, yp, z_w]ᵀ. Its linear part is R_w, its translation p_c + p_w.
Eigen::Isometry3d workpiece_to_cell(const Workcell& cell, const WorkpiecePose& pose);

/// One placed path point: tool-tip position and tool frame in the cell frame.
struct PlacedPoint {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();        ///< p_mi
  Eigen::Matrix3d tool_to_cell = Eigen::Matrix3d::Identity();  ///< R_ni, columns x_t, y_t, z_t
};

/// 004 Eq 7 for one point.
PlacedPoint place(const Workcell& cell, const WorkpiecePose& pose, const PathPoint& point);

}  // namespace robomill::planning
