#include "robomill/dynamics/modal_model.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace robomill::dynamics {

Mode directional_mode(int axis, double natural_frequency_hz, double damping_ratio,
                      double stiffness_n_per_m) {
  if (axis < 0 || axis > 2)
    throw std::invalid_argument("mode axis must be 0, 1 or 2");
  if (!(stiffness_n_per_m > 0.0) || !std::isfinite(stiffness_n_per_m)) {
    throw std::invalid_argument("modal stiffness must be positive");
  }
  const double omega = 2.0 * std::numbers::pi * natural_frequency_hz;
  Mode mode;
  mode.natural_frequency_hz = natural_frequency_hz;
  mode.damping_ratio = damping_ratio;
  // m = k / ωn², φ = e_d / √m.
  mode.shape[axis] = omega / std::sqrt(stiffness_n_per_m);
  return mode;
}

ModalModel::ModalModel(std::vector<Mode> modes) : modes_(std::move(modes)) {
  if (modes_.empty())
    throw std::invalid_argument("a modal model needs at least one mode");
  for (std::size_t i = 0; i < modes_.size(); ++i) {
    const Mode& m = modes_[i];
    const std::string which = "mode " + std::to_string(i + 1) + ": ";
    if (!(m.natural_frequency_hz > 0.0) || !std::isfinite(m.natural_frequency_hz)) {
      throw std::invalid_argument(which + "natural frequency must be positive");
    }
    if (!(m.damping_ratio > 0.0 && m.damping_ratio < 1.0)) {
      throw std::invalid_argument(which + "damping ratio must lie in (0, 1)");
    }
    if (!m.shape.allFinite() || m.shape.norm() == 0.0) {
      throw std::invalid_argument(which + "mode shape must be finite and non-zero");
    }
  }
}

double ModalModel::highest_frequency_hz() const noexcept {
  double highest = 0.0;
  for (const Mode& m : modes_)
    highest = std::max(highest, m.natural_frequency_hz);
  return highest;
}

Eigen::Matrix3cd ModalModel::receptance(double omega_rad_s) const noexcept {
  Eigen::Matrix3cd h = Eigen::Matrix3cd::Zero();
  for (const Mode& m : modes_) {
    const double wn = 2.0 * std::numbers::pi * m.natural_frequency_hz;
    // 1 / (ωn² − ω² + 2iζωnω) as conj/|·|²: one real division per mode
    // instead of a complex one per matrix entry (libgcc's __divdc3, which
    // took a quarter of a path's uncertainty run). The denominator's squared
    // magnitude stays far inside double's range for any physical mode.
    const double re = wn * wn - omega_rad_s * omega_rad_s;
    const double im = 2.0 * m.damping_ratio * wn * omega_rad_s;
    const double scale = 1.0 / (re * re + im * im);
    const Eigen::Matrix3d outer = m.shape * m.shape.transpose();
    h.real() += outer * (re * scale);
    h.imag() -= outer * (im * scale);
  }
  return h;
}

Eigen::Matrix<double, 3, Eigen::Dynamic> ModalModel::shape_matrix() const {
  Eigen::Matrix<double, 3, Eigen::Dynamic> shapes(3, size());
  for (int i = 0; i < size(); ++i)
    shapes.col(i) = modes_[static_cast<std::size_t>(i)].shape;
  return shapes;
}

Eigen::VectorXd ModalModel::natural_rad_s() const {
  Eigen::VectorXd omega(size());
  for (int i = 0; i < size(); ++i) {
    omega[i] = 2.0 * std::numbers::pi * modes_[static_cast<std::size_t>(i)].natural_frequency_hz;
  }
  return omega;
}

Eigen::VectorXd ModalModel::damping_ratios() const {
  Eigen::VectorXd zeta(size());
  for (int i = 0; i < size(); ++i)
    zeta[i] = modes_[static_cast<std::size_t>(i)].damping_ratio;
  return zeta;
}

ModalModel ModalModel::subset(const std::vector<int>& indices) const {
  std::vector<Mode> chosen;
  for (int index : indices) {
    if (index < 0 || index >= size())
      throw std::invalid_argument("mode index out of range");
    chosen.push_back(modes_[static_cast<std::size_t>(index)]);
  }
  return ModalModel(std::move(chosen));
}

}  // namespace robomill::dynamics
