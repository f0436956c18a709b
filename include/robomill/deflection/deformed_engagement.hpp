#pragma once
// The deformation-corrected engagement as the stability engine needs it
// (000 §4-5): for any axial depth ap and height z on the flute, the actual
// entry angle φen^a of Eq 27, from the contact-boundary iteration solved on a
// grid of depths and interpolated linearly in ap and z.
//
// Node k's entry angle is taken at the contact-line position where node k
// generates the surface (K = k of 000 §4.2): that is where its deflection
// decides the wall and the contact, and 000 Figure 11 plots node 1 there.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <vector>

#include "robomill/deflection/contact_boundary.hpp"
#include "robomill/robot/robot_model.hpp"

namespace robomill::deflection {

/// Everything a contact-boundary problem needs except the axial depth.
struct DeflectionSetup {
  double tool_radius_m = 0.0;
  double helix_rad = 0.0;
  double overhang_m = 0.0;              ///< cantilever length l (000 Eq 1)
  double flexural_rigidity_n_m2 = 0.0;  ///< EI; infinite: a rigid tool
  double feed_per_tooth_m = 0.0;
  double radial_depth_m = 0.0;
  cutting::LinearLaw law;
  int elements = 10;  ///< m
  /// The robot and its posture (000 Eq 3); null: a rigid robot.
  std::shared_ptr<const robot::RobotModel> robot;
  Eigen::VectorXd posture_rad;
  /// The cut's frame (columns feed x, normal y, axis z) in the robot's base
  /// frame; none: the robot's tool frame at the posture (`robomill
  /// deflection`, whose feed is the tool x).
  std::optional<Eigen::Matrix3d> cut_frame;
  ContactOptions options;
};

/// The problem at depth ap: node heights, tool + robot compliance (Eq 1-4).
ContactProblem contact_problem(const DeflectionSetup& setup, double axial_depth_m);

class DeformedEngagement {
 public:
  /// Solves the contact boundary at `count` depths evenly spaced over
  /// (0, depth_max] on up to `threads` threads (0: all cores). Throws what
  /// solve_contact_boundary throws, naming the depth.
  DeformedEngagement(const DeflectionSetup& setup, double depth_max_m, int count, int threads = 0);

  /// φen^a at height z (m above the tip) for axial depth ap: linear in z
  /// between nodes and in ap between grid depths; ap → 0 is the nominal
  /// (undeformed) entry; beyond depth_max the last depth's values.
  double entry_angle_rad(double axial_depth_m, double height_m) const;

  double nominal_entry_rad() const noexcept { return nominal_entry_rad_; }
  const std::vector<double>& depths_m() const noexcept { return depths_m_; }
  const std::vector<ContactBoundary>& boundaries() const noexcept { return boundaries_; }

 private:
  double entry_at_grid(std::size_t index, double height_m) const;

  std::vector<double> depths_m_;
  std::vector<ContactBoundary> boundaries_;
  double nominal_entry_rad_ = 0.0;
};

}  // namespace robomill::deflection
