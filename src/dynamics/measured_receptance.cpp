#include "robomill/dynamics/measured_receptance.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace robomill::dynamics {

MeasuredReceptance::MeasuredReceptance(std::vector<Frf> frfs) {
  if (frfs.empty())
    throw std::invalid_argument("measured receptance: no FRF given");
  entry_.setConstant(-1);
  min_hz_ = 0.0;
  max_hz_ = INFINITY;
  for (Frf& frf : frfs) {
    validate(frf);
    Frf receptance = convert(frf, FrfKind::receptance);
    // A 0 Hz receptance point is a static compliance that interpolation
    // toward the first resonance would distort little, but a mobility or
    // accelerance has none: drop 0 Hz everywhere for one rule.
    if (!receptance.frequency_hz.empty() && receptance.frequency_hz.front() == 0.0) {
      receptance.frequency_hz.erase(receptance.frequency_hz.begin());
      receptance.value.erase(receptance.value.begin());
    }
    if (receptance.frequency_hz.size() < 2)
      throw std::invalid_argument("measured receptance: FRF '" + frf.label +
                                  "' has fewer than two frequencies above 0 Hz");
    const int r = receptance.response_axis, s = receptance.reference_axis;
    const int index = static_cast<int>(frfs_.size());
    const Frf* present =
        entry_(r, s) >= 0 ? &frfs_[static_cast<std::size_t>(entry_(r, s))] : nullptr;
    // An entry filled only by reciprocity (from H_sr) gives way to H_rs itself.
    if (present && present->response_axis == r && present->reference_axis == s) {
      throw std::invalid_argument("measured receptance: the FRF " + std::string(1, "xyz"[r]) +
                                  std::string(1, "xyz"[s]) + " is given twice");
    }
    entry_(r, s) = index;
    if (entry_(s, r) < 0)
      entry_(s, r) = index;  // reciprocity, until H_sr itself is measured
    min_hz_ = std::max(min_hz_, receptance.frequency_hz.front());
    max_hz_ = std::min(max_hz_, receptance.frequency_hz.back());
    frfs_.push_back(std::move(receptance));
  }
  if (!(max_hz_ > min_hz_))
    throw std::invalid_argument("measured receptance: the FRFs' frequency ranges do not overlap");
}

Eigen::Matrix3cd MeasuredReceptance::operator()(double omega_rad_s) const {
  const double frequency_hz = std::clamp(omega_rad_s / (2.0 * std::numbers::pi), min_hz_, max_hz_);
  Eigen::Matrix3cd h = Eigen::Matrix3cd::Zero();
  for (int r = 0; r < 3; ++r) {
    for (int s = 0; s < 3; ++s) {
      if (entry_(r, s) >= 0)
        h(r, s) = interpolate(frfs_[static_cast<std::size_t>(entry_(r, s))], frequency_hz);
    }
  }
  return h;
}

std::vector<double> MeasuredReceptance::frequencies_hz() const {
  std::vector<double> grid;
  for (const Frf& frf : frfs_) {
    for (const double f : frf.frequency_hz) {
      if (f >= min_hz_ && f <= max_hz_)
        grid.push_back(f);
    }
  }
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());
  return grid;
}

}  // namespace robomill::dynamics
