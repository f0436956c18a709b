#pragma once
// The plain description of a robot (see robot_model.hpp): what a job file or
// code says about it, before validation. Free of KDL so that the job parser
// can hold it.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

namespace robomill::robot {

enum class DhConvention {
  standard,  ///< Denavit-Hartenberg: Rz(θ) Tz(d) Tx(a) Rx(α), link frame at the distal joint
  modified,  ///< Craig: Rx(α) Tx(a) Rz(θ) Tz(d), link frame at the proximal joint
};

/// One row of a DH table; the joint angle θ = q + theta_offset.
struct DhRow {
  double a_m = 0.0;
  double alpha_rad = 0.0;
  double d_m = 0.0;
  double theta_offset_rad = 0.0;
};

/// JointProperties::damping_nms_per_rad value meaning "derive it from the
/// modal damping ratio"; any other negative value is invalid.
inline constexpr double kDeriveDamping = -1.0;

/// The properties of one revolute joint beyond its geometry.
struct JointProperties {
  double lower_rad = -3.141592653589793;
  double upper_rad = 3.141592653589793;
  double stiffness_nm_per_rad = 0.0;  ///< torsional stiffness Kq, > 0
  /// Viscous damping in N·m·s/rad, or kDeriveDamping: from the
  /// description's modal_damping_ratio (joint_dynamics.hpp says how).
  double damping_nms_per_rad = -1.0;
};

/// Mass properties of one link, in the link's own frame (the DH or URDF
/// frame that moves with the joint).
struct LinkInertia {
  double mass_kg = 0.0;
  Eigen::Vector3d center_of_mass_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero();  ///< about the centre of mass
};

struct DhTable {
  DhConvention convention = DhConvention::standard;
  std::vector<DhRow> rows;
  std::vector<LinkInertia> links;  ///< one per row (empty: massless, statics only)
};

struct UrdfSource {
  std::string xml;        ///< the URDF document
  std::string base_link;  ///< chain root
  std::string tip_link;   ///< chain end (the flange)
};

/// Plain description of a robot; exactly one of `dh` and `urdf` is set.
struct RobotDescription {
  std::string name;
  std::optional<DhTable> dh;
  std::optional<UrdfSource> urdf;
  /// One per revolute joint, in chain order.
  std::vector<JointProperties> joints;
  /// URDF only: take each joint's lower/upper limit from the file (its
  /// <limit> element) instead of `joints`.
  bool use_urdf_limits = true;
  Eigen::Isometry3d base = Eigen::Isometry3d::Identity();            ///< cell → robot base
  Eigen::Isometry3d flange_to_tool = Eigen::Isometry3d::Identity();  ///< flange → tool tip
  /// Damping ratio applied to every mode of the joint-space model (004 §4.1
  /// uses 0.06) for joints whose damping is not given.
  double modal_damping_ratio = 0.0;
};

}  // namespace robomill::robot
