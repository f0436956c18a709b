#pragma once
// The robots the robot tests share: a KUKA KR 600 R2830-class arm (000) and
// the three-joint flexible robot of 004 §4.1.

#include <Eigen/Geometry>
#include <numbers>
#include <vector>

#include "robomill/robot/robot_description.hpp"

namespace robomill::test {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kDeg = kPi / 180.0;

inline robot::LinkInertia link(double m, Eigen::Vector3d c, Eigen::Vector3d principal) {
  robot::LinkInertia l;
  l.mass_kg = m;
  l.center_of_mass_m = c;
  l.inertia_kg_m2 = principal.asDiagonal();
  return l;
}

// KR 600 R2830-class geometry (standard DH), nominal public dimensions of
// the KUKA KR 600 R2830 datasheet (paper 000 gives none): A1 height 1.045 m,
// A1–A2 offset 0.5 m, upper arm 1.3 m, A3 offset 0.055 m, forearm 1.025 m,
// A5 to flange 0.29 m; check: 0.5 + 1.3 + √(1.025² + 0.055²) = 2.8265 m,
// the datasheet reach (2826 mm, to the wrist point). Joint directions and
// zeros are this table's, not KUKA's controller conventions, so 000 §6.3's
// posture is used as a generic non-singular posture. Kq: 000 §6.1. No link
// masses (statics only). A spindle: tip 0.35 m out along the flange z and
// 0.08 m off-axis, tool z tilted 90°, and a moved base (nontrivial frames).
inline robot::RobotDescription kr600() {
  robot::RobotDescription d;
  d.name = "KR600-class";
  robot::DhTable dh;
  dh.convention = robot::DhConvention::standard;
  dh.rows = {{0.5, -kPi / 2, 1.045, 0.0}, {1.3, 0.0, 0.0, -kPi / 2}, {0.055, -kPi / 2, 0.0, 0.0},
             {0.0, kPi / 2, 1.025, 0.0},  {0.0, -kPi / 2, 0.0, 0.0}, {0.0, 0.0, 0.29, 0.0}};
  d.dh = dh;
  const double k[] = {6.082e6, 6.816e6, 3.842e6, 2.926e6, 1.635e6, 2.479e6};
  const double lim[] = {185, 180, 180, 350, 125, 350};  // deg, generous
  for (int i = 0; i < 6; ++i)
    d.joints.push_back({-lim[i] * kDeg, lim[i] * kDeg, k[i], robot::kDeriveDamping});
  d.flange_to_tool =
      Eigen::Translation3d(0.08, 0.0, 0.35) * Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitY());
  d.base = Eigen::Translation3d(0.2, -0.4, 0.3) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ());
  return d;
}

/// 000 §6.3's posture (rad).
inline Eigen::VectorXd posture_000() {
  Eigen::VectorXd q(6);
  q << -71.73, -68.62, 110.51, 35.54, -47.68, -204.68;
  return q * kDeg;
}

/// 004 §4.1: k1 = 2.4e5, k2 = k3 = 1e5 N·m/rad; θ1 ∈ [−π, π],
/// θ2 ∈ [−π/2, π/2], θ3 ∈ [−π/3, π/3].
inline std::vector<robot::JointProperties> joints_004() {
  return {{-kPi, kPi, 2.4e5, robot::kDeriveDamping},
          {-kPi / 2, kPi / 2, 1e5, robot::kDeriveDamping},
          {-kPi / 3, kPi / 3, 1e5, robot::kDeriveDamping}};
}

// 004 §4.1 in modified (Craig) DH: frame i at joint i, z_i its axis, x2 and
// x3 along links 2 and 3, so Table 1's link 2 and 3 rows apply verbatim. The
// Craig frame 1 sits on joint 2's height (d1 = l1 = 0.2 m), 0.2 m above the
// paper's o1, so link 1's centre of mass (0, 0, 0.1) becomes (0, 0, −0.1).
// ζ = 0.06.
inline robot::RobotDescription robot_004() {
  robot::RobotDescription d;
  d.name = "004";
  robot::DhTable dh;
  dh.convention = robot::DhConvention::modified;
  dh.rows = {{0.0, 0.0, 0.2, 0.0}, {0.0, kPi / 2, 0.0, 0.0}, {0.8, 0.0, 0.0, 0.0}};
  dh.links = {link(80, {0, 0, -0.1}, {0.9, 1.0, 1.0}), link(40, {0.4, 0, 0}, {0.6, 6.5, 6.5}),
              link(55, {0.4, 0, 0}, {0.8, 9.5, 9.5})};
  d.dh = dh;
  d.joints = joints_004();
  d.flange_to_tool.translation() = Eigen::Vector3d(0.8, 0.0, 0.0);  // o3→ot = [l3, 0, 0]
  d.modal_damping_ratio = 0.06;
  return d;
}

/// Axis × angle of a rotation matrix.
inline Eigen::Vector3d rotation_vector(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

}  // namespace robomill::test
