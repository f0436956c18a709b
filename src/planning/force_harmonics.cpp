#include "robomill/planning/force_harmonics.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace robomill::planning {

ForceHarmonics force_harmonics(const cutting::MillingForceModel& model, int samples,
                               int harmonics) {
  if (harmonics < 1 || samples < 2 * harmonics + 1)
    throw std::invalid_argument("force_harmonics: need harmonics >= 1 and samples >= 2 K + 1");
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  const auto& runout = model.tool().runout();
  // With runout the teeth cut unequal chips: the force repeats per revolution.
  const int teeth_per_period = runout.offset_m > 0.0 ? model.tool().teeth() : 1;
  const double period_s = model.tooth_period_s() * teeth_per_period;
  const double period_angle = kTwoPi / model.tool().teeth() * teeth_per_period;

  std::vector<Eigen::Vector3d> force(static_cast<std::size_t>(samples));
  for (int m = 0; m < samples; ++m)
    force[static_cast<std::size_t>(m)] = model.at(period_angle * m / samples).force_n;

  ForceHarmonics result;
  result.period_s = period_s;
  result.fundamental_rad_s = kTwoPi / period_s;
  result.samples = samples;
  result.coefficients.assign(static_cast<std::size_t>(harmonics) + 1, Eigen::Vector3cd::Zero());
  for (int k = 0; k <= harmonics; ++k) {
    Eigen::Vector3cd sum = Eigen::Vector3cd::Zero();
    for (int m = 0; m < samples; ++m) {
      // The index product is reduced modulo M so the phase stays exact.
      const long j = (static_cast<long>(k) * m) % samples;
      sum += force[static_cast<std::size_t>(m)].cast<std::complex<double>>() *
             std::polar(1.0, -kTwoPi * static_cast<double>(j) / samples);
    }
    result.coefficients[static_cast<std::size_t>(k)] = sum / static_cast<double>(samples);
  }
  return result;
}

Eigen::Vector3d force_at(const ForceHarmonics& harmonics, double time_s) {
  Eigen::Vector3d f = harmonics.coefficients[0].real();
  for (int k = 1; k <= harmonics.harmonics(); ++k) {
    const std::complex<double> e = std::polar(1.0, k * harmonics.fundamental_rad_s * time_s);
    f += 2.0 * (harmonics.coefficients[static_cast<std::size_t>(k)] * e).real();
  }
  return f;
}

}  // namespace robomill::planning
