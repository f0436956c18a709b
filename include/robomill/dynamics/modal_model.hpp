#pragma once
// Modal description of the structure at the tool tip: any number of modes,
// each with a natural frequency, a damping ratio and a mass-normalized mode
// shape (a 3-vector in the tool frame). A mode measured along one direction
// with modal mass m has the shape e_d / √m; coupled modes have general shapes.

#include <Eigen/Core>
#include <complex>
#include <vector>

namespace robomill::dynamics {

struct Mode {
  double natural_frequency_hz = 0.0;
  double damping_ratio = 0.0;
  /// Mass-normalized shape φ at the tool tip, 1/√kg, tool frame:
  /// receptance H(ω) = Σ φ φᵀ / (ωn² − ω² + 2i ζ ωn ω).
  Eigen::Vector3d shape = Eigen::Vector3d::Zero();
};

/// A mode along one axis of the tool frame (0 = x, 1 = y, 2 = z) from its
/// natural frequency, damping ratio and modal stiffness k (shape e_d √(ωn²/k)).
Mode directional_mode(int axis, double natural_frequency_hz, double damping_ratio,
                      double stiffness_n_per_m);

/// An immutable, validated set of modes.
class ModalModel {
 public:
  /// Throws std::invalid_argument naming the mode (1-based) if a frequency is
  /// not positive, a damping ratio is outside (0, 1), a shape is zero or not
  /// finite, or there are no modes.
  explicit ModalModel(std::vector<Mode> modes);

  const std::vector<Mode>& modes() const noexcept { return modes_; }
  int size() const noexcept { return static_cast<int>(modes_.size()); }
  double highest_frequency_hz() const noexcept;

  /// 3x3 receptance (m/N) at angular frequency ω.
  Eigen::Matrix3cd receptance(double omega_rad_s) const noexcept;

  /// The modes' shapes as columns (3 x n) and their ωn (rad/s), ζ.
  Eigen::Matrix<double, 3, Eigen::Dynamic> shape_matrix() const;
  Eigen::VectorXd natural_rad_s() const;
  Eigen::VectorXd damping_ratios() const;

  /// The model restricted to some modes (for single-mode diagrams, 003 §3.2).
  ModalModel subset(const std::vector<int>& indices) const;

 private:
  std::vector<Mode> modes_;
};

}  // namespace robomill::dynamics
