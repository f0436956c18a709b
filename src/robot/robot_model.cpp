#include "robomill/robot/robot_model.hpp"

#include <urdf_model/model.h>
#include <urdf_parser/urdf_parser.h>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <kdl/frames.hpp>
#include <kdl/joint.hpp>
#include <kdl/rigidbodyinertia.hpp>
#include <kdl/rotationalinertia.hpp>
#include <kdl/segment.hpp>
#include <kdl/tree.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <stdexcept>
#include <string>
#include <utility>

namespace robomill::robot {
namespace {

// The "derive" marker of JointProperties::damping_nms_per_rad: the default
// value, -1. Any other negative value is a mistake and is rejected.
constexpr double kDeriveDampingMarker = -1.0;

std::string joint_label(std::size_t i) {
  return "robot joint " + std::to_string(i + 1);
}
std::string link_label(std::size_t i) {
  return "robot link " + std::to_string(i + 1);
}

[[noreturn]] void fail(const std::string& message) {
  throw std::invalid_argument(message);
}

bool is_rigid_transform(const Eigen::Isometry3d& t) {
  if (!t.matrix().allFinite())
    return false;
  const Eigen::Matrix3d r = t.linear();
  return (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() < 1e-9 && r.determinant() > 0.0;
}

KDL::Frame to_kdl(const Eigen::Isometry3d& t) {
  const Eigen::Matrix3d r = t.linear();
  return KDL::Frame(KDL::Rotation(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0),
                                  r(2, 1), r(2, 2)),
                    KDL::Vector(t.translation().x(), t.translation().y(), t.translation().z()));
}

void validate_joint(const JointProperties& j, const std::string& label) {
  if (!std::isfinite(j.stiffness_nm_per_rad) || !(j.stiffness_nm_per_rad > 0.0)) {
    fail(label + ": stiffness must be positive and finite, got " +
         std::to_string(j.stiffness_nm_per_rad) + " N·m/rad");
  }
  if (!std::isfinite(j.lower_rad) || !std::isfinite(j.upper_rad) || !(j.lower_rad < j.upper_rad)) {
    fail(label + ": lower limit must be below the upper limit (got " + std::to_string(j.lower_rad) +
         " ≥ " + std::to_string(j.upper_rad) + " rad)");
  }
  const double c = j.damping_nms_per_rad;
  if (!std::isfinite(c) || (c < 0.0 && c != kDeriveDampingMarker)) {
    fail(label + ": damping must be ≥ 0 N·m·s/rad or -1 (derive from modal_damping_ratio), got " +
         std::to_string(c));
  }
}

// Mass properties as the header states them: mass ≥ 0, finite centre of mass,
// inertia about the centre of mass symmetric positive semi-definite.
void validate_inertia(const LinkInertia& link, const std::string& label) {
  if (!std::isfinite(link.mass_kg) || link.mass_kg < 0.0)
    fail(label + ": mass must be ≥ 0 kg, got " + std::to_string(link.mass_kg));
  if (!link.center_of_mass_m.allFinite())
    fail(label + ": centre of mass must be finite");
  const Eigen::Matrix3d& i = link.inertia_kg_m2;
  if (!i.allFinite())
    fail(label + ": inertia must be finite");
  const double scale = std::max(i.cwiseAbs().maxCoeff(), 1e-300);
  if ((i - i.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale)
    fail(label + ": inertia tensor must be symmetric");
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(i, Eigen::EigenvaluesOnly);
  if (eig.eigenvalues().minCoeff() < -1e-12 * scale)
    fail(label + ": inertia tensor must be positive semi-definite (smallest principal moment " +
         std::to_string(eig.eigenvalues().minCoeff()) + " kg·m²)");
}

KDL::RigidBodyInertia to_kdl(const LinkInertia& link) {
  const Eigen::Matrix3d& i = link.inertia_kg_m2;
  // KDL's RigidBodyInertia takes (m, centre of mass in the segment's tip
  // frame, rotational inertia about the centre of mass) and shifts it to the
  // tip frame origin itself.
  return KDL::RigidBodyInertia(
      link.mass_kg,
      KDL::Vector(link.center_of_mass_m.x(), link.center_of_mass_m.y(), link.center_of_mass_m.z()),
      KDL::RotationalInertia(i(0, 0), i(1, 1), i(2, 2), i(0, 1), i(0, 2), i(1, 2)));
}

// Builds the chain of a DH table. Each revolute joint becomes one KDL segment
// whose tip frame is the DH link frame i and whose joint rotates about z_i
// (modified) or z_{i-1} (standard), so the link inertia given "in the link's
// own frame" is exactly the segment's inertia (KDL expresses a segment's
// inertia in its tip frame).
KDL::Chain chain_from_dh(const DhTable& dh) {
  KDL::Chain chain;
  for (std::size_t i = 0; i < dh.rows.size(); ++i) {
    const DhRow& r = dh.rows[i];
    const KDL::RigidBodyInertia inertia =
        dh.links.empty() ? KDL::RigidBodyInertia::Zero() : to_kdl(dh.links[i]);
    const std::string name = "link_" + std::to_string(i + 1);
    const std::string joint = "joint_" + std::to_string(i + 1);
    if (dh.convention == DhConvention::standard) {
      // T = Rz(q + θ₀) Tz(d) Tx(a) Rx(α): the joint turns about the root z
      // (z_{i-1}); Frame::DH is Rz(θ₀) Tz(d) Tx(a) Rx(α).
      chain.addSegment(KDL::Segment(name, KDL::Joint(joint, KDL::Joint::RotZ),
                                    KDL::Frame::DH(r.a_m, r.alpha_rad, r.d_m, r.theta_offset_rad),
                                    inertia));
    } else {
      // T = Rx(α) Tx(a) Rz(q + θ₀) Tz(d): the joint axis is z_i, which in the
      // root frame passes through (a, 0, 0) along Rx(α) ẑ = (0, −sin α, cos α).
      const KDL::Joint rot(joint, KDL::Vector(r.a_m, 0.0, 0.0),
                           KDL::Vector(0.0, -std::sin(r.alpha_rad), std::cos(r.alpha_rad)),
                           KDL::Joint::RotAxis);
      chain.addSegment(KDL::Segment(
          name, rot, KDL::Frame::DH_Craig1989(r.a_m, r.alpha_rad, r.d_m, r.theta_offset_rad),
          inertia));
    }
  }
  return chain;
}

bool is_revolute(KDL::Joint::JointType t) {
  return t == KDL::Joint::RotAxis || t == KDL::Joint::RotX || t == KDL::Joint::RotY ||
         t == KDL::Joint::RotZ;
}

// Builds the chain of a URDF (kdl_parser), checks its joints and link
// inertias, and copies the <limit> of each revolute joint when asked.
KDL::Chain chain_from_urdf(RobotDescription& d) {
  const UrdfSource& src = *d.urdf;
  urdf::ModelInterfaceSharedPtr urdf_model;
  try {
    urdf_model = urdf::parseURDF(src.xml);
  } catch (const std::exception& e) {
    fail(std::string("robot urdf: does not parse: ") + e.what());
  }
  if (!urdf_model)
    fail("robot urdf: does not parse as a URDF document");
  KDL::Tree tree;
  if (!kdl_parser::treeFromUrdfModel(*urdf_model, tree))
    fail("robot urdf: cannot be converted to a kinematic tree");
  KDL::Chain chain;
  if (!tree.getChain(src.base_link, src.tip_link, chain)) {
    fail("robot urdf: no chain from base_link '" + src.base_link + "' to tip_link '" +
         src.tip_link + "'");
  }
  // kdl_parser's segments carry the URDF link names and, for moving ones, the
  // URDF joint names: check the joints and mass properties one by one.
  std::size_t moving = 0;
  for (unsigned s = 0; s < chain.getNrOfSegments(); ++s) {
    const KDL::Segment& seg = chain.getSegment(s);
    const KDL::Joint& jnt = seg.getJoint();
    if (jnt.getType() != KDL::Joint::Fixed) {
      if (!is_revolute(jnt.getType())) {
        fail("robot urdf: joint '" + jnt.getName() + "' (joint " + std::to_string(moving + 1) +
             ") is not revolute; only revolute joints are supported");
      }
      ++moving;
    }
    const auto link = urdf_model->getLink(seg.getName());
    if (link && link->inertial) {
      const urdf::Inertial& in = *link->inertial;
      LinkInertia li;
      li.mass_kg = in.mass;
      li.inertia_kg_m2 << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
      validate_inertia(li, "robot urdf link '" + seg.getName() + "'");
    }
  }
  if (moving != d.joints.size()) {
    fail("robot urdf: the chain from '" + src.base_link + "' to '" + src.tip_link + "' has " +
         std::to_string(moving) + " revolute joints but " + std::to_string(d.joints.size()) +
         " joint entries were given");
  }
  if (d.use_urdf_limits) {
    std::size_t k = 0;
    for (unsigned s = 0; s < chain.getNrOfSegments(); ++s) {
      const KDL::Joint& jnt = chain.getSegment(s).getJoint();
      if (jnt.getType() == KDL::Joint::Fixed)
        continue;
      const auto uj = urdf_model->getJoint(jnt.getName());
      // Continuous joints have no limits: keep the description's.
      if (uj && uj->type == urdf::Joint::REVOLUTE && uj->limits) {
        d.joints[k].lower_rad = uj->limits->lower;
        d.joints[k].upper_rad = uj->limits->upper;
      }
      ++k;
    }
  }
  return chain;
}

}  // namespace

RobotModel::RobotModel(RobotDescription description) : description_(std::move(description)) {
  RobotDescription& d = description_;
  if (d.dh.has_value() == d.urdf.has_value())
    fail("robot: exactly one of a DH table and a URDF must be given");
  if (d.joints.empty())
    fail("robot: no joints");
  if (!is_rigid_transform(d.base))
    fail("robot base: must be a finite rigid transform (orthonormal rotation)");
  if (!is_rigid_transform(d.flange_to_tool))
    fail("robot flange_to_tool: must be a finite rigid transform (orthonormal rotation)");
  if (!std::isfinite(d.modal_damping_ratio) || d.modal_damping_ratio < 0.0 ||
      d.modal_damping_ratio >= 1.0) {
    fail("robot modal_damping_ratio: must lie in [0, 1), got " +
         std::to_string(d.modal_damping_ratio));
  }

  if (d.dh) {
    const DhTable& dh = *d.dh;
    if (dh.rows.size() != d.joints.size()) {
      fail("robot: the DH table has " + std::to_string(dh.rows.size()) + " rows but " +
           std::to_string(d.joints.size()) + " joint entries were given");
    }
    if (!dh.links.empty() && dh.links.size() != dh.rows.size()) {
      fail("robot: the DH table has " + std::to_string(dh.rows.size()) + " rows but " +
           std::to_string(dh.links.size()) + " links were given");
    }
    for (std::size_t i = 0; i < dh.rows.size(); ++i) {
      const DhRow& r = dh.rows[i];
      if (!std::isfinite(r.a_m) || !std::isfinite(r.alpha_rad) || !std::isfinite(r.d_m) ||
          !std::isfinite(r.theta_offset_rad)) {
        fail(joint_label(i) + ": DH parameters must be finite");
      }
    }
    for (std::size_t i = 0; i < dh.links.size(); ++i)
      validate_inertia(dh.links[i], link_label(i));
    chain_ = chain_from_dh(dh);
  } else {
    chain_ = chain_from_urdf(d);
  }
  for (std::size_t i = 0; i < d.joints.size(); ++i)
    validate_joint(d.joints[i], joint_label(i));

  chain_.addSegment(
      KDL::Segment("tool", KDL::Joint("tool_mount", KDL::Joint::Fixed), to_kdl(d.flange_to_tool)));
}

Eigen::VectorXd RobotModel::joint_stiffness() const {
  Eigen::VectorXd k(dof());
  for (int i = 0; i < dof(); ++i)
    k[i] = description_.joints[static_cast<std::size_t>(i)].stiffness_nm_per_rad;
  return k;
}

bool RobotModel::within_limits(const Eigen::VectorXd& q, double margin_rad) const {
  if (q.size() != dof() || !q.allFinite())
    return false;
  for (int i = 0; i < dof(); ++i) {
    const JointProperties& j = description_.joints[static_cast<std::size_t>(i)];
    if (q[i] < j.lower_rad + margin_rad || q[i] > j.upper_rad - margin_rad)
      return false;
  }
  return true;
}

}  // namespace robomill::robot
