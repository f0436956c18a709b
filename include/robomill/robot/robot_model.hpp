#pragma once
// An industrial robot as a structure (000 §2, 002 §2, 004 §3.1): a serial
// chain of revolute joints whose geometry comes from a Denavit-Hartenberg
// table or a URDF file, with joint limits, a tool frame at the tool tip, the
// torsional stiffness and damping of each joint, and the links' masses.
//
// The description (RobotDescription) is plain data, filled by the job parser
// or by code; RobotModel validates it once and holds it, immutable, as an
// Orocos KDL chain that ends at the tool tip. Algorithms are free functions
// on it (kinematics.hpp, stiffness.hpp, joint_dynamics.hpp).
//
// Frames: the robot base frame is the chain's root (the cell frame moved by
// `base`); the tool frame sits at the tool tip with z along the tool axis,
// pointing from the tip into the spindle (robomill's tool-frame convention,
// docs/theory.md), reached from the flange by `flange_to_tool`.

#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <string>
#include <vector>

#include "robomill/robot/robot_description.hpp"

namespace robomill::robot {

/// A validated, immutable robot. Construction throws std::invalid_argument
/// with a message naming the joint or link (1-based) for: no joints, a
/// joint count different from the DH rows / URDF chain, non-positive or
/// non-finite stiffness, lower limit ≥ upper limit, negative damping other
/// than the "derive" marker, negative mass, an inertia that is not symmetric
/// positive semi-definite, a URDF that does not parse or has no chain from
/// base_link to tip_link, or a chain with non-revolute moving joints.
class RobotModel {
 public:
  explicit RobotModel(RobotDescription description);

  const std::string& name() const noexcept { return description_.name; }
  int dof() const noexcept { return static_cast<int>(description_.joints.size()); }
  /// The kinematic and inertial chain from the base to the tool tip: the
  /// robot's segments, then a fixed "tool" segment (flange_to_tool). The
  /// base transform is applied by the algorithms, not stored in the chain.
  const KDL::Chain& chain() const noexcept { return chain_; }
  const std::vector<JointProperties>& joints() const noexcept { return description_.joints; }
  const RobotDescription& description() const noexcept { return description_; }

  /// Kq, N·m/rad, one entry per joint.
  Eigen::VectorXd joint_stiffness() const;
  /// Whether every joint lies within [lower + margin, upper − margin].
  bool within_limits(const Eigen::VectorXd& q, double margin_rad = 0.0) const;

 private:
  RobotDescription description_;
  KDL::Chain chain_;
};

}  // namespace robomill::robot
