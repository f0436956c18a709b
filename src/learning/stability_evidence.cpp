#include "robomill/learning/stability_evidence.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace robomill::learning {
namespace {

/// log Φ(z), accurate for very negative z (erfc keeps the tail's digits
/// down to about z = −37; beyond, the asymptotic series' leading terms).
double log_normal_cdf(double z) {
  if (z > -30.0)
    return std::log(0.5 * std::erfc(-z / std::numbers::sqrt2));
  const double z2 = z * z;
  return -0.5 * z2 - std::log(-z) - 0.5 * std::log(2.0 * std::numbers::pi) +
         std::log1p(-1.0 / z2 + 3.0 / (z2 * z2));
}

}  // namespace

double verdict_sd_m(double limit_m, const VerdictModel& model) {
  const double relative = model.relative_sd * limit_m;
  return std::sqrt(model.sd_m * model.sd_m + relative * relative);
}

double chatter_probability(double depth_m, double limit_m, const VerdictModel& model) {
  if (std::isinf(limit_m))
    return 0.5 * model.mislabel;
  const double z = (depth_m - limit_m) / verdict_sd_m(limit_m, model);
  return 0.5 * model.mislabel + (1.0 - model.mislabel) * 0.5 * std::erfc(-z / std::numbers::sqrt2);
}

double log_verdict_likelihood(bool chatter, double depth_m, double limit_m,
                              const VerdictModel& model) {
  const double half_mislabel = 0.5 * model.mislabel;
  double log_phi = 0.0;  // log Φ(±z): the probability the probit gives the verdict
  if (std::isinf(limit_m)) {
    log_phi = chatter ? -std::numeric_limits<double>::infinity() : 0.0;
  } else {
    const double z = (depth_m - limit_m) / verdict_sd_m(limit_m, model);
    log_phi = log_normal_cdf(chatter ? z : -z);
  }
  if (half_mislabel <= 0.0)
    return log_phi;
  // log(ε/2 + (1 − ε) e^{log_phi}) without underflow.
  const double a = std::log(half_mislabel), b = std::log1p(-model.mislabel) + log_phi;
  const double high = std::max(a, b);
  return high + std::log1p(std::exp(std::min(a, b) - high));
}

double nearest_chatter_family_hz(double measured_hz, double predicted_hz, double tooth_hz) {
  if (!(tooth_hz > 0.0))
    return predicted_hz;
  double best = predicted_hz;
  for (const double sign : {1.0, -1.0}) {
    // ±f_c + k f_tooth nearest to +f_m and to −f_m (the folded line).
    for (const double target : {measured_hz, -measured_hz}) {
      const double k = std::round((target - sign * predicted_hz) / tooth_hz);
      const double member = std::abs(sign * predicted_hz + k * tooth_hz);
      if (std::abs(member - measured_hz) < std::abs(best - measured_hz))
        best = member;
    }
  }
  return best;
}

double log_chatter_frequency_likelihood(double measured_hz, double predicted_hz, double tooth_hz,
                                        double sd_hz) {
  const double r =
      (measured_hz - nearest_chatter_family_hz(measured_hz, predicted_hz, tooth_hz)) / sd_hz;
  return -0.5 * r * r - std::log(sd_hz * std::sqrt(2.0 * std::numbers::pi));
}

double binary_entropy_bits(double p) {
  if (p <= 0.0 || p >= 1.0)
    return 0.0;
  return -(p * std::log2(p) + (1.0 - p) * std::log2(1.0 - p));
}

double expected_information_bits(std::span<const double> p_chatter) {
  if (p_chatter.empty())
    return 0.0;
  double mean = 0.0, mean_entropy = 0.0;
  for (const double p : p_chatter) {
    mean += p;
    mean_entropy += binary_entropy_bits(p);
  }
  const double n = static_cast<double>(p_chatter.size());
  return std::max(0.0, binary_entropy_bits(mean / n) - mean_entropy / n);
}

}  // namespace robomill::learning
