#pragma once
// The static compliance of the robot milling system between points on the
// tool (000 §2, Eq 1-4): the tool as a cantilever clamped in the holder and
// the robot's end deflection through its joint springs.
//
// The engaged flute is split into m axial elements and m + 1 nodes (000 §2,
// §4); node k sits at height z_k above the tool tip (000 writes z_k as the
// distance from the free end). A force F_n at node n deflects node k by
//
//   ΔT(k, n) = F_n (l − z_k)² (2l − 3z_n + z_k) / (6EI)   z_n < z_k < l
//            = F_n (l − z_n)² (2l − 3z_k + z_n) / (6EI)   0 < z_k < z_n   (000 Eq 1)
//
// (l the overhang, EI the flexural rigidity), summed over n (Eq 2), plus the
// robot's end deflection ΔE_k = Jc,k Kq⁻¹ Σ_n Je,nᵀ F_n (Eq 3) with Jc,k the
// Jacobian of node k and Je,n that of node n; the total is ΔR_k = ΔT_k + ΔE_k
// (Eq 4). Everything here is in the tool frame's x (feed) and y (normal).

#include <Eigen/Core>
#include <vector>

#include "robomill/robot/robot_model.hpp"

namespace robomill::deflection {

/// 000 Eq 1: deflection (m) at height z_k above the tip per newton at height
/// z_n, for a cantilever of length l (tip to clamp) and flexural rigidity EI
/// (N·m²). Symmetric in (z_k, z_n) (Maxwell-Betti); zero at the clamp.
/// Throws std::invalid_argument unless 0 ≤ z ≤ l, l > 0 and EI > 0.
double cantilever_influence_m_per_n(double length_m, double flexural_rigidity_n_m2,
                                    double height_k_m, double height_n_m);

/// EI of a tool of solid circular section with diameter d_eq: E π d_eq⁴ / 64.
/// A fluted cutter is softer than its shank; the usual equivalent diameter is
/// about 0.8 D (docs/assumptions.md).
double flexural_rigidity_n_m2(double youngs_modulus_pa, double equivalent_diameter_m);

/// Node heights z_k = (k − 1) ap / m, k = 1 … m + 1 (000: dz = ap / m).
std::vector<double> node_heights_m(double axial_depth_m, int elements);

/// The tool part (000 Eq 1-2): G(2k + a, 2n + a) = influence(z_k, z_n) for
/// a = x, y (the section is round: x and y decouple).
Eigen::MatrixXd tool_node_compliance(const std::vector<double>& node_heights_m, double length_m,
                                     double flexural_rigidity_n_m2);

/// The robot part (000 Eq 3): G(2k + a, 2n + b) = e_aᵀ Rᵀ Jc,k Kq⁻¹ Je,nᵀ R e_b
/// with R the tool orientation, J the linear rows of the point Jacobians of
/// nodes k and n (points on the tool axis, z_k above the tip) — the full
/// Jc ≠ Je form, so the robot's rotation under a load low on the cutter moves
/// a node higher up differently.
Eigen::MatrixXd robot_node_compliance(const robot::RobotModel& robot, const Eigen::VectorXd& q,
                                      const std::vector<double>& node_heights_m);

/// The same with x and y taken from `frame` (columns x, y, z in the robot's
/// base frame) instead of the tool frame: a cut whose feed is not the tool
/// frame's x (a program's sample, robot_path/robot_along_path.hpp). The nodes
/// stay on the tool axis, z_k above the tip.
Eigen::MatrixXd robot_node_compliance(const robot::RobotModel& robot, const Eigen::VectorXd& q,
                                      const std::vector<double>& node_heights_m,
                                      const Eigen::Matrix3d& frame);

}  // namespace robomill::deflection
