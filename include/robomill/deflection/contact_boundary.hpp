#pragma once
// Force-induced deformation of the robot milling system and the actual
// tool–workpiece contact boundary (000 §4, Eq 20-31).
//
// The static cutting force deflects the tool and the robot (node_compliance);
// in down milling the deflection away from the uncut stock lowers the radial
// depth at each node, ae,k = ae − ΔY,k (Eq 26), which raises the entry angle
// (Eq 27) and shortens the contact line — which lowers the force, which lowers
// the deflection: 000 iterates this to a fixed point (Eq 29, |Δae| ≤ 1e-6 mm),
// one contact-line position at a time (the tool turned by the nodes' lag Δφ =
// dz tan β / R between positions, Eq 11). At position K node K is on the
// surface-generation line (the exit, where the finished wall is cut) and the
// nodes above it trail by Δφ each (Eq 25); the nodes in contact are those
// still past their entry angle: m + 2 − K of them while the whole flute fits
// the engagement arc (Case 1, Eq 24), floor((φex − φen)/Δφ) + 1 when the
// depth exceeds the critical depth of Eq 22 (Case 2, Eq 30-31).
//
// Angles follow robomill's convention (clockwise from +y, docs/theory.md): a
// down-milling cut runs from φen = π − acos(1 − ae/R) to φex = π with chip
// fz sin φ. 000 measures φ from the feed direction with chip fz cos φ, entry
// π/2 − acos(1 − ae/R) and exit π/2: the same cut, rotated by π/2. Only down
// milling is treated (000's cuts; the surface is generated at the exit).
//
// Forces: 000 Eq 13 per unit length at each node in contact (shear and edge
// terms of the linear law, the chip from Eq 28), each element's force the mean
// of its two nodes' times dz, split equally between them (000 §4.2).

#include <Eigen/Core>
#include <vector>

#include "robomill/cutting/cutting_law.hpp"
#include "robomill/tool/tool.hpp"

namespace robomill::deflection {

/// 000 Eq 22: the axial depth above which the flute no longer fits the
/// engagement arc when its lowest node is at the exit,
/// ap_lim = R (π/2 − asin(1 − ae/R)) cot β; infinite for straight flutes.
double critical_depth_m(double tool_radius_m, double radial_depth_m, double helix_rad);

/// Nominal number of nodes in contact at contact-line position K (1-based):
/// Eq 24 (m + 2 − K) in Case 1, Eq 30 (floor((φex − φen)/Δφ) + 1, at most
/// m + 2 − K) in Case 2, for nominal entry angle φen.
int contact_node_count(int elements, int position, double entry_rad, double exit_rad,
                       double lag_step_rad);

/// Down-milling entry angle for a radial depth (000 Eq 23/27 in robomill's
/// angles): π − acos(1 − ae/R), ae clamped to [0, 2R].
double entry_angle_rad(double tool_radius_m, double radial_depth_m);

struct ContactProblem {
  double tool_radius_m = 0.0;
  double helix_rad = 0.0;
  double feed_per_tooth_m = 0.0;
  double radial_depth_m = 0.0;  ///< nominal ae
  double axial_depth_m = 0.0;   ///< ap
  int elements = 10;            ///< m
  cutting::LinearLaw law;       ///< Ktc, Krc, Kte, Kre (000 Eq 13, 39)
  /// Static compliance between the m + 1 nodes, 2(m+1) square, x and y of the
  /// tool frame at each node (node_compliance.hpp: tool + robot).
  Eigen::MatrixXd compliance;
};

struct ContactOptions {
  double tolerance_m = 1e-9;  ///< 000 Eq 29: ε = 1e-6 mm
  int max_iterations = 200;   ///< per contact-line position and relaxation
  /// 000 Eq 28's static-chip correction, h = [fz − R (sin φen,n − sin φen,a)] sin φ.
  /// false: h = fz sin φ (a steady deflection shifts consecutive tooth paths
  /// alike, so the chip itself keeps its nominal thickness; docs/theory.md).
  bool chip_correction = true;
};

/// One node at one contact-line position.
struct NodeState {
  double height_m = 0.0;
  Eigen::Vector2d deflection_m = Eigen::Vector2d::Zero();  ///< tool frame x, y
  Eigen::Vector2d force_n = Eigen::Vector2d::Zero();       ///< node force, x, y
  double radial_depth_m = 0.0;                             ///< actual ae at this node (Eq 26)
  double entry_rad = 0.0;                                  ///< actual entry angle (Eq 27)
  double edge_angle_rad = 0.0;                             ///< φ of the node's edge (Eq 25)
  bool in_contact = false;
};

/// The converged state with node K on the surface-generation line.
struct ContactPosition {
  int generating_node = 1;  ///< K (1-based)
  int contact_nodes = 0;    ///< N_dk (Eq 24, 30-31) after convergence
  int iterations = 0;       ///< fixed-point iterations l spent
  double relaxation = 1.0;  ///< 1: 000's plain iteration; < 1 when that oscillated
  std::vector<NodeState> nodes;
};

struct ContactBoundary {
  double critical_depth_m = 0.0;  ///< Eq 22
  int contact_case = 1;           ///< 1: ap ≤ ap_lim (Eq 24), 2: beyond (Eq 30-31)
  double lag_step_rad = 0.0;      ///< Δφ (Eq 11)
  double nominal_entry_rad = 0.0;
  std::vector<ContactPosition> positions;  ///< K = 1 … m + 1

  /// Node k (1-based) as it generates the surface (position K = k): the
  /// deformation and actual engagement of 000 Figure 11.
  const NodeState& generating(int node) const { return positions.at(node - 1).nodes.at(node - 1); }
};

/// 000 §4.3 steps 1-5. Throws std::invalid_argument for an inconsistent
/// problem (sizes, non-positive geometry, ae > 2R, compliance not
/// 2(m+1) square or not finite) and robomill::NumericalError when a position
/// does not converge even with relaxation down to 1/16 (naming it).
ContactBoundary solve_contact_boundary(const ContactProblem& problem,
                                       const ContactOptions& options = {});

}  // namespace robomill::deflection
