#pragma once
// A mode shape along the tool axis. Paper 000 (Table 2, Eq 35) measures the
// mass-normalized shapes of the tool modes at a few points from the free end
// (3, 12, 24 and 36 mm) and needs them at every axial node of its multipoint
// model; this interpolates them.

#include <vector>

namespace robomill::dynamics {

class AxialShape {
 public:
  AxialShape() = default;
  /// Points (distance from the tool tip, m; value, 1/√kg). Throws
  /// std::invalid_argument unless the distances are finite, ≥ 0 and strictly
  /// increasing and the values finite.
  AxialShape(std::vector<double> distance_from_tip_m, std::vector<double> value);

  bool empty() const noexcept { return distance_m_.empty(); }
  /// The shape at a distance from the tip: linear between measured points and
  /// extrapolated linearly from the two nearest points outside them (a
  /// cantilever's shape is smooth and nearly straight near the tip); one
  /// point gives a constant.
  double at(double distance_from_tip_m) const;

  const std::vector<double>& distances_m() const noexcept { return distance_m_; }
  const std::vector<double>& values() const noexcept { return value_; }

 private:
  std::vector<double> distance_m_, value_;
};

}  // namespace robomill::dynamics
