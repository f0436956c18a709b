#include "robomill/deflection/node_compliance.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "robomill/robot/kinematics.hpp"

namespace robomill::deflection {

double cantilever_influence_m_per_n(double length_m, double flexural_rigidity_n_m2,
                                    double height_k_m, double height_n_m) {
  if (!(length_m > 0.0) || !(flexural_rigidity_n_m2 > 0.0) || !std::isfinite(length_m) ||
      !std::isfinite(flexural_rigidity_n_m2)) {
    throw std::invalid_argument("cantilever: length and flexural rigidity must be positive");
  }
  const double tolerance = 1e-12 * length_m;
  for (const double z : {height_k_m, height_n_m}) {
    if (!(z >= -tolerance && z <= length_m + tolerance)) {
      throw std::invalid_argument("cantilever: node height " + std::to_string(z) +
                                  " m lies outside the tool (0 … " + std::to_string(length_m) +
                                  " m)");
    }
  }
  const double l = length_m, zk = height_k_m, zn = height_n_m;
  // 000 Eq 1, both branches; they agree at z_k = z_n.
  if (zn < zk)
    return (l - zk) * (l - zk) * (2.0 * l - 3.0 * zn + zk) / (6.0 * flexural_rigidity_n_m2);
  return (l - zn) * (l - zn) * (2.0 * l - 3.0 * zk + zn) / (6.0 * flexural_rigidity_n_m2);
}

double flexural_rigidity_n_m2(double youngs_modulus_pa, double equivalent_diameter_m) {
  if (!(youngs_modulus_pa > 0.0) || !(equivalent_diameter_m > 0.0))
    throw std::invalid_argument("flexural rigidity: E and the diameter must be positive");
  const double d2 = equivalent_diameter_m * equivalent_diameter_m;
  return youngs_modulus_pa * std::numbers::pi * d2 * d2 / 64.0;
}

std::vector<double> node_heights_m(double axial_depth_m, int elements) {
  if (!(axial_depth_m > 0.0) || elements < 1)
    throw std::invalid_argument("nodes: the depth must be positive and elements ≥ 1");
  std::vector<double> heights(static_cast<std::size_t>(elements) + 1);
  for (int k = 0; k <= elements; ++k)
    heights[static_cast<std::size_t>(k)] = axial_depth_m * k / elements;
  return heights;
}

Eigen::MatrixXd tool_node_compliance(const std::vector<double>& node_heights_m, double length_m,
                                     double flexural_rigidity_n_m2) {
  const auto nodes = static_cast<Eigen::Index>(node_heights_m.size());
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(2 * nodes, 2 * nodes);
  for (Eigen::Index k = 0; k < nodes; ++k) {
    for (Eigen::Index n = 0; n < nodes; ++n) {
      const double c = cantilever_influence_m_per_n(length_m, flexural_rigidity_n_m2,
                                                    node_heights_m[static_cast<std::size_t>(k)],
                                                    node_heights_m[static_cast<std::size_t>(n)]);
      g(2 * k, 2 * n) = c;
      g(2 * k + 1, 2 * n + 1) = c;
    }
  }
  return g;
}

Eigen::MatrixXd robot_node_compliance(const robot::RobotModel& robot, const Eigen::VectorXd& q,
                                      const std::vector<double>& node_heights_m) {
  return robot_node_compliance(robot, q, node_heights_m, robot::tool_pose(robot, q).linear());
}

Eigen::MatrixXd robot_node_compliance(const robot::RobotModel& robot, const Eigen::VectorXd& q,
                                      const std::vector<double>& node_heights_m,
                                      const Eigen::Matrix3d& rotation) {
  const auto nodes = static_cast<Eigen::Index>(node_heights_m.size());
  const Eigen::VectorXd compliance = robot.joint_stiffness().cwiseInverse();
  // Linear rows of each node's point Jacobian, rotated into the tool frame
  // and keeping x and y: 2 × n per node.
  std::vector<Eigen::MatrixXd> jacobians;
  jacobians.reserve(node_heights_m.size());
  for (const double z : node_heights_m) {
    const Eigen::MatrixXd j = robot::point_jacobian(robot, q, Eigen::Vector3d(0.0, 0.0, z));
    jacobians.push_back((rotation.transpose() * j.topRows<3>()).topRows<2>());
  }
  Eigen::MatrixXd g(2 * nodes, 2 * nodes);
  for (Eigen::Index k = 0; k < nodes; ++k) {
    for (Eigen::Index n = 0; n < nodes; ++n) {
      g.block<2, 2>(2 * k, 2 * n) = jacobians[static_cast<std::size_t>(k)] *
                                    compliance.asDiagonal() *
                                    jacobians[static_cast<std::size_t>(n)].transpose();
    }
  }
  return g;
}

}  // namespace robomill::deflection
