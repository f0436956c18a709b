#pragma once
// Private to src/io: KUKA's A, B, C angles as a rotation, shared by the KRL
// reader and the frame turns (io/krl_frame_turn.hpp).

#include <Eigen/Geometry>

#include "robomill/core/constants.hpp"

namespace robomill::io::krl_rotation {

/// KUKA's A, B, C (deg): R = Rz(A) Ry(B) Rx(C).
inline Eigen::Matrix3d rotation_abc(double a_deg, double b_deg, double c_deg) {
  return (Eigen::AngleAxisd(a_deg * kRadPerDeg, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(b_deg * kRadPerDeg, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(c_deg * kRadPerDeg, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

}  // namespace robomill::io::krl_rotation
