#pragma once
// The robot cell of examples/toolpath_robot_pocket.yaml for the tests of the
// robot along a program: a KR 270 R2900-class robot (003's DH table, twice
// 000 §6.1's joint stiffnesses, assumed link masses, 2 % modal damping), its
// modes from the model, a 10 mm three-flute cutter in aluminium, the part on
// a table in front of it, the zero-order method. Tests append sections.

#include <cmath>
#include <numbers>
#include <string>

#include "robomill/toolpath/program_analysis.hpp"

namespace robomill::support {

inline std::string kr270_cell_yaml() {
  return R"(
tool: {type: flat, diameter: 10 mm, teeth: 3, helix: 30 deg, overhang: 40 mm}
cutting: {law: linear, Ktc: 796 N/mm^2, Krc: 169 N/mm^2, Kac: 223 N/mm^2}
robot:
  name: KR 270
  convention: standard
  dh:
    - {a: 350 mm, alpha: -90 deg, d: 675 mm, theta: 0 deg}
    - {a: 1350 mm, alpha: 0 deg, d: 0 mm, theta: -90 deg}
    - {a: 41 mm, alpha: -90 deg, d: 0 mm, theta: 0 deg}
    - {a: 0 mm, alpha: 90 deg, d: 1200 mm, theta: 0 deg}
    - {a: 0 mm, alpha: -90 deg, d: 0 mm, theta: 0 deg}
    - {a: 0 mm, alpha: 0 deg, d: 215 mm, theta: 0 deg}
  joint_stiffness: [12.164e6, 13.632e6, 7.684e6, 5.852e6, 3.27e6, 4.958e6]
  joints:
    - {lower: -185 deg, upper: 185 deg}
    - {lower: -180 deg, upper: 180 deg}
    - {lower: -180 deg, upper: 180 deg}
    - {lower: -350 deg, upper: 350 deg}
    - {lower: -125 deg, upper: 125 deg}
    - {lower: -350 deg, upper: 350 deg}
  links:
    - {mass: 400 kg, cog: [-175, 0, 0], inertia: [40, 40, 30]}
    - {mass: 220 kg, cog: [-675, 0, 0], inertia: [3, 33, 33]}
    - {mass: 200 kg, cog: [0, 0, 400], inertia: [15, 15, 5]}
    - {mass: 90 kg, cog: [0, 0, 0], inertia: [5, 5, 2]}
    - {mass: 30 kg, cog: [0, 0, 0], inertia: [0.5, 0.5, 0.5]}
    - {mass: 60 kg, cog: [0, 0, 150], inertia: [1, 1, 0.3]}
  damping_ratio: 2 %
  tool: {xyz: [0, 0, 350], rpy: [180, 0, 0]}
  posture: [0, 22.55, 18.47, 0, 48.97, 0]
dynamics: {from_robot: true}
workpiece:
  table: [1770, -20, 560]
  height: 20 mm
  pose: {x: 0 mm, y: 0 mm, theta: 0 deg}
stability: {method: zoa, depth_max: 10 mm, speeds: {from: 6000 rpm, to: 10000 rpm, count: 41}}
)";
}

/// A sample of a straight side cut along +x on that part (workpiece frame,
/// 20 mm in y, 17 mm up) with the given engaged arc, depth and speed.
inline toolpath::PathSample side_cut_sample(double x_m, double entry_rad, double exit_rad,
                                            int line = 1, double ap_m = 3e-3,
                                            double spindle_rpm = 8000.0) {
  toolpath::PathSample s;
  s.line = line;
  s.tip_m = {x_m, 20e-3, 17e-3};
  s.axis = Eigen::Vector3d::UnitZ();
  s.feed_direction = Eigen::Vector3d::UnitX();
  s.feed_m_s = 0.01;
  s.spindle_rad_s = spindle_rpm * 2.0 * std::numbers::pi / 60.0;
  s.feed_per_tooth_m = 0.05e-3;
  s.analysed = true;
  s.axial_depth_m = ap_m;
  s.entry_rad = entry_rad;
  s.exit_rad = exit_rad;
  s.engaged_rad = exit_rad - entry_rad;
  s.arcs = 1;
  return s;
}

}  // namespace robomill::support
