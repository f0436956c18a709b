#include "robomill/dynamics/axial_shape.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace robomill::dynamics {

AxialShape::AxialShape(std::vector<double> distance_from_tip_m, std::vector<double> value)
    : distance_m_(std::move(distance_from_tip_m)), value_(std::move(value)) {
  if (distance_m_.size() != value_.size())
    throw std::invalid_argument("mode shape: as many values as distances needed");
  for (std::size_t i = 0; i < distance_m_.size(); ++i) {
    if (!std::isfinite(distance_m_[i]) || distance_m_[i] < 0.0 || !std::isfinite(value_[i]))
      throw std::invalid_argument("mode shape: distances must be finite and ≥ 0, values finite");
    if (i > 0 && !(distance_m_[i] > distance_m_[i - 1]))
      throw std::invalid_argument("mode shape: distances must increase strictly");
  }
}

double AxialShape::at(double distance_from_tip_m) const {
  if (distance_m_.empty())
    throw std::invalid_argument("mode shape: no points");
  if (distance_m_.size() == 1)
    return value_[0];
  // The segment holding the distance, or the end segment nearest to it.
  const auto upper = std::upper_bound(distance_m_.begin(), distance_m_.end(), distance_from_tip_m);
  const std::size_t i = std::clamp<std::size_t>(
      static_cast<std::size_t>(upper - distance_m_.begin()), 1, distance_m_.size() - 1);
  const double t =
      (distance_from_tip_m - distance_m_[i - 1]) / (distance_m_[i] - distance_m_[i - 1]);
  return value_[i - 1] + t * (value_[i] - value_[i - 1]);
}

}  // namespace robomill::dynamics
