#pragma once
// Measured FRFs as the 3x3 receptance matrix of the tool tip, for methods that
// work in the frequency domain on measured data directly (the zero-order
// stability method, "directly from an FRF").

#include <Eigen/Core>
#include <vector>

#include "robomill/dynamics/frf.hpp"

namespace robomill::dynamics {

class MeasuredReceptance {
 public:
  /// Each FRF (any kind; converted to receptance) fills its (response,
  /// reference) entry and, by Maxwell's reciprocity, the transposed entry
  /// when that one was not measured; entries never measured stay 0 (no
  /// coupling). Throws std::invalid_argument for an empty list, an entry
  /// measured twice, or FRFs whose frequency ranges do not overlap.
  explicit MeasuredReceptance(std::vector<Frf> frfs);

  /// H(ω), each entry interpolated linearly in its real and imaginary parts;
  /// outside the common range the nearest end value is held.
  Eigen::Matrix3cd operator()(double omega_rad_s) const;

  /// The range every FRF covers (Hz); frequencies with a 0 Hz point removed.
  double min_frequency_hz() const noexcept { return min_hz_; }
  double max_frequency_hz() const noexcept { return max_hz_; }
  /// The measured frequencies inside the common range, sorted and unique.
  std::vector<double> frequencies_hz() const;

  const std::vector<Frf>& frfs() const noexcept { return frfs_; }

 private:
  std::vector<Frf> frfs_;
  // entry_(r, s): index into frfs_ or −1.
  Eigen::Matrix3i entry_;
  double min_hz_ = 0.0, max_hz_ = 0.0;
};

}  // namespace robomill::dynamics
