#pragma once
// `robomill robot` of a job: what the robot's structure is at a posture —
// tool pose, Jacobian, Cartesian compliance (000 Eq 3-4), principal
// stiffness, joint-space natural frequencies and tool-tip modes (004 Eq 1-2),
// the tool-tip FRF, 002 §2's reduced tip model (Eq 8-23) — and, with
// robot.map, the same figures over a grid of tool-tip positions. SI units,
// cell frame unless a field says otherwise.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "robomill/job/job.hpp"
#include "robomill/robot/joint_dynamics.hpp"
#include "robomill/robot/reduced_model.hpp"
#include "robomill/robot/stiffness.hpp"

namespace robomill::analysis {

/// One grid point of the workspace map (robot.map).
struct WorkspacePoint {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  ///< the tool tip asked for
  /// The inverse kinematics about robot.map's tool axis converged.
  bool reachable = false;
  /// The joint angles the inverse kinematics ended at (rad); meaningful only
  /// where reachable.
  Eigen::VectorXd q_rad;
  /// The robot's lowest natural frequency there; 0 without link masses or
  /// where unreachable.
  double lowest_frequency_hz = 0.0;
  /// Translational compliance dᵀ C d along the feed, the normal (tool axis ×
  /// feed) and the tool axis; 0 where unreachable.
  double compliance_feed_m_per_n = 0.0, compliance_normal_m_per_n = 0.0;
  double compliance_axial_m_per_n = 0.0;
  /// Of the translational compliance: largest / smallest eigenvalue (0 where
  /// the smallest is not positive or the point is unreachable).
  double condition_number = 0.0;
};

/// robot.map: the grid and its reachable points' range of lowest frequency.
struct WorkspaceMap {
  /// Every grid point, x fastest, then y, then z.
  std::vector<WorkspacePoint> points;
  int reachable = 0;  ///< points whose inverse kinematics converged
  /// Lowest and highest lowest_frequency_hz over the reachable points (+inf
  /// and 0 when none is reachable).
  double lowest_frequency_min_hz = std::numeric_limits<double>::infinity();
  double lowest_frequency_max_hz = 0.0;
};

/// 002 §2 (Eq 8-23): the reduced tip model and its frequencies against the
/// full joint-space eigenproblem.
struct ReducedTipModel {
  int dimension = 0;  ///< 6 (compliance invertible) or 3 (translational)
  robot::ReducedModel model;
  robot::FrequencyComparison frequencies;
};

struct RobotAtPosture {
  std::string robot_name;
  int dof = 0;                  ///< joints
  Eigen::VectorXd posture_rad;  ///< robot.posture, checked against the joint ranges
  Eigen::Isometry3d tool_pose = Eigen::Isometry3d::Identity();  ///< translation in m
  /// Roll, pitch, yaw of the tool's rotation (rad): Z-Y-X Euler angles, reversed.
  Eigen::Vector3d tool_rpy_rad = Eigen::Vector3d::Zero();
  /// Geometric Jacobian at the tool tip (6×dof): linear rows in m, angular
  /// rows in rad, per unit joint motion.
  Eigen::Matrix<double, 6, Eigen::Dynamic> jacobian;
  /// 000 Eq 3: C = J Kq⁻¹ Jᵀ, blocks [m/N, m/(N·m); rad/N, rad/(N·m)].
  robot::Matrix6d compliance = robot::Matrix6d::Zero();
  Eigen::Matrix3d translational_compliance_m_per_n = Eigen::Matrix3d::Zero();
  /// The translational stiffness's eigenvalues and directions; nullopt (and
  /// the reason in principal_stiffness_note) where it does not exist.
  std::optional<robot::PrincipalStiffness> principal_stiffness;
  std::string principal_stiffness_note;
  /// 004 Eq 1's modes; nullopt for a DH robot without link masses (statics
  /// only: then no modal table, FRF or reduced model either).
  std::optional<robot::RobotModes> modes;
  /// The modes along the tool's own axes (the tool frame of the pose), as a
  /// hammer test at the tip and the stability engine see them.
  std::vector<robot::DirectionalModalParameters> modal_table_tool_frame;
  /// The FRF's range: robot.frf, or 0.5 × the lowest to 2 × the highest
  /// natural frequency; 0 without modes.
  double frf_from_hz = 0.0, frf_to_hz = 0.0;
  /// Tool-tip receptance (m/N, 3×3, cell frame) at each frequency.
  std::vector<double> frf_frequencies_hz;
  std::vector<Eigen::Matrix3cd> frf_receptance_m_per_n;
  /// 6-D where the compliance is invertible, else 3-D; nullopt without modes
  /// or (the reason in reduced_model_note) when neither reduction exists.
  std::optional<ReducedTipModel> reduced_model;
  std::string reduced_model_note;
  std::optional<WorkspaceMap> map;  ///< with robot.map
  double elapsed_s = 0.0;           ///< the whole analysis
};

/// The robot at robot.posture, and the workspace map on up to `threads`
/// threads (0: all cores). Needs the robot section; throws InputError naming
/// robot.posture (missing, or an angle outside its joint's range) or
/// robot.frf.to (not above from).
RobotAtPosture robot_at_posture(const job::Job& job, int threads = 0);

}  // namespace robomill::analysis
