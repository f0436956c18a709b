#include "robomill/uncertainty/distribution.hpp"

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/policies/policy.hpp>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "robomill/core/constants.hpp"

namespace robomill::uncertainty {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Boost.Math's normal in plain double precision: without promote_double<false>
// Boost evaluates double arguments in long double, whose width differs
// between platforms (80-bit on x86-64, 128-bit on AArch64), so the same draw
// would differ in its last bits from machine to machine.
using DoublePolicy = boost::math::policies::policy<boost::math::policies::promote_double<false>>;
using BoostStandardNormal = boost::math::normal_distribution<double, DoublePolicy>;

/// Φ(z), with Φ(±∞) = 1 or 0.
double normal_cdf(double z) {
  if (std::isinf(z))
    return z > 0.0 ? 1.0 : 0.0;
  return boost::math::cdf(BoostStandardNormal(), z);
}

/// Q(z) = 1 − Φ(z), accurate in the upper tail (Boost's complement).
double normal_upper_tail(double z) {
  if (std::isinf(z))
    return z > 0.0 ? 0.0 : 1.0;
  return boost::math::cdf(boost::math::complement(BoostStandardNormal(), z));
}

/// Φ⁻¹(p) for p in (0, 1).
double normal_inverse_cdf(double p) {
  return boost::math::quantile(BoostStandardNormal(), p);
}

/// Q⁻¹(q) = −Φ⁻¹(q) for q in (0, 1), accurate for small q.
double normal_inverse_upper_tail(double q) {
  return boost::math::quantile(boost::math::complement(BoostStandardNormal(), q));
}

/// φ(z), with φ(±∞) = 0.
double normal_density(double z) {
  if (std::isinf(z))
    return 0.0;
  return std::exp(-0.5 * z * z) / std::sqrt(kTwoPi);
}

/// z·φ(z), with the limit 0 at z = ±∞.
double z_times_density(double z) {
  return std::isinf(z) ? 0.0 : z * normal_density(z);
}

/// ln φ(z).
double log_normal_density(double z) {
  return -0.5 * z * z - 0.5 * std::log(kTwoPi);
}

std::string number_text(double value) {
  std::ostringstream text;
  text.precision(6);
  text << value;
  return text.str();
}

[[noreturn]] void refuse(const std::string& family, const std::string& problem) {
  throw std::invalid_argument(family + " distribution: " + problem);
}

void require_finite(const std::string& family, const char* name, double value) {
  if (!std::isfinite(value))
    refuse(family, std::string(name) + " must be a finite number (got " + number_text(value) + ")");
}

void require_positive(const std::string& family, const char* name, double value) {
  require_finite(family, name, value);
  if (value <= 0.0)
    refuse(family, std::string(name) + " must be positive (got " + number_text(value) + ")");
}

void require_ordered(const std::string& family, double min, double max) {
  if (!(min < max))
    refuse(family, "min must be below max (got min " + number_text(min) + ", max " +
                       number_text(max) + ")");
}

/// Φ and Q at the standardized bounds and the mass between them, each from
/// the tail where it is accurate: Z = Q(α) − Q(β) when the interval lies in
/// the upper half (α > 0), Φ(β) − Φ(α) otherwise.
Distribution::TruncationTails truncation_tails(const TruncatedNormal& p) {
  Distribution::TruncationTails tails;
  tails.alpha = (p.min - p.mean) / p.sd;
  tails.beta = (p.max - p.mean) / p.sd;
  tails.cdf_alpha = normal_cdf(tails.alpha);
  tails.cdf_beta = normal_cdf(tails.beta);
  tails.upper_tail_alpha = normal_upper_tail(tails.alpha);
  tails.upper_tail_beta = normal_upper_tail(tails.beta);
  tails.mass = tails.alpha > 0.0 ? tails.upper_tail_alpha - tails.upper_tail_beta
                                 : tails.cdf_beta - tails.cdf_alpha;
  return tails;
}

double truncated_quantile(const TruncatedNormal& p, const Distribution::TruncationTails& t,
                          double u) {
  // Lower half of the untruncated normal: Φ(α) + uZ stays accurate; upper
  // half: the same point as Q(β) + (1 − u)Z, accurate however small.
  const double lower_probability = t.cdf_alpha + u * t.mass;
  const double z = lower_probability <= 0.5
                       ? normal_inverse_cdf(lower_probability)
                       : normal_inverse_upper_tail(t.upper_tail_beta + (1.0 - u) * t.mass);
  return std::clamp(p.mean + p.sd * z, p.min, p.max);
}

double truncated_cdf(const TruncatedNormal& p, const Distribution::TruncationTails& t, double x) {
  if (x <= p.min)
    return 0.0;
  if (x >= p.max)
    return 1.0;
  const double z = (x - p.mean) / p.sd;
  const double below =
      z <= 0.0 ? normal_cdf(z) - t.cdf_alpha : t.upper_tail_alpha - normal_upper_tail(z);
  return std::clamp(below / t.mass, 0.0, 1.0);
}

double truncated_mean(const TruncatedNormal& p, const Distribution::TruncationTails& t) {
  return p.mean + p.sd * (normal_density(t.alpha) - normal_density(t.beta)) / t.mass;
}

double truncated_standard_deviation(const TruncatedNormal& p,
                                    const Distribution::TruncationTails& t) {
  const double shift = (normal_density(t.alpha) - normal_density(t.beta)) / t.mass;
  const double spread = (z_times_density(t.alpha) - z_times_density(t.beta)) / t.mass;
  return p.sd * std::sqrt(std::max(0.0, 1.0 + spread - shift * shift));
}

}  // namespace

Distribution::Distribution(const Normal& normal) : parameters_(normal) {
  require_finite("normal", "mean", normal.mean);
  require_positive("normal", "sd", normal.sd);
}

Distribution::Distribution(const Lognormal& lognormal) : parameters_(lognormal) {
  require_positive("lognormal", "median", lognormal.median);
  require_positive("lognormal", "sigma", lognormal.sigma);
}

Distribution::Distribution(const Uniform& uniform) : parameters_(uniform) {
  require_finite("uniform", "min", uniform.min);
  require_finite("uniform", "max", uniform.max);
  require_ordered("uniform", uniform.min, uniform.max);
  if (!std::isfinite(uniform.max - uniform.min))
    refuse("uniform", "max - min overflows a double");
}

Distribution::Distribution(const TruncatedNormal& truncated) : parameters_(truncated) {
  const std::string family = "truncated_normal";
  require_finite(family, "mean", truncated.mean);
  require_positive(family, "sd", truncated.sd);
  if (std::isnan(truncated.min) || truncated.min == kInfinity)
    refuse(family, "min must be a number or -infinity (got " + number_text(truncated.min) + ")");
  if (std::isnan(truncated.max) || truncated.max == -kInfinity)
    refuse(family, "max must be a number or +infinity (got " + number_text(truncated.max) + ")");
  require_ordered(family, truncated.min, truncated.max);
  truncation_ = truncation_tails(truncated);
  if (!(truncation_.mass >= kMinimumTruncatedMass))
    refuse(family, "[min, max] = [" + number_text(truncated.min) + ", " +
                       number_text(truncated.max) + "] holds only " +
                       number_text(truncation_.mass) + " of the probability of normal(mean " +
                       number_text(truncated.mean) + ", sd " + number_text(truncated.sd) +
                       ") (bounds " + number_text(truncation_.alpha) + " and " +
                       number_text(truncation_.beta) +
                       " sd from the mean): every draw would sit at a bound; move the mean "
                       "or widen the bounds");
}

std::string family_name(const Distribution& distribution) {
  static constexpr const char* kNames[] = {"normal", "lognormal", "uniform", "truncated_normal"};
  return kNames[distribution.parameters().index()];
}

std::string describe(const Distribution& distribution) {
  return std::visit(
      [](const auto& p) -> std::string {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, Normal>)
          return "normal(mean " + number_text(p.mean) + ", sd " + number_text(p.sd) + ")";
        else if constexpr (std::is_same_v<P, Lognormal>)
          return "lognormal(median " + number_text(p.median) + ", sigma " + number_text(p.sigma) +
                 ")";
        else if constexpr (std::is_same_v<P, Uniform>)
          return "uniform(min " + number_text(p.min) + ", max " + number_text(p.max) + ")";
        else
          return "truncated_normal(mean " + number_text(p.mean) + ", sd " + number_text(p.sd) +
                 ", min " + number_text(p.min) + ", max " + number_text(p.max) + ")";
      },
      distribution.parameters());
}

double quantile(const Distribution& distribution, double u) {
  if (!(u > 0.0 && u < 1.0))
    throw std::invalid_argument("quantile of " + describe(distribution) + ": probability " +
                                number_text(u) + " is not inside (0, 1)");
  return std::visit(
      [&](const auto& p) -> double {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, Normal>)
          return p.mean + p.sd * normal_inverse_cdf(u);
        else if constexpr (std::is_same_v<P, Lognormal>)
          return p.median * std::exp(p.sigma * normal_inverse_cdf(u));
        else if constexpr (std::is_same_v<P, Uniform>)
          return std::min(p.min + u * (p.max - p.min), p.max);
        else
          return truncated_quantile(p, distribution.truncation(), u);
      },
      distribution.parameters());
}

double cdf(const Distribution& distribution, double x) {
  if (std::isnan(x))
    return x;
  return std::visit(
      [&](const auto& p) -> double {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, Normal>)
          return normal_cdf((x - p.mean) / p.sd);
        else if constexpr (std::is_same_v<P, Lognormal>)
          return x <= 0.0 ? 0.0 : normal_cdf((std::log(x) - std::log(p.median)) / p.sigma);
        else if constexpr (std::is_same_v<P, Uniform>)
          return std::clamp((x - p.min) / (p.max - p.min), 0.0, 1.0);
        else
          return truncated_cdf(p, distribution.truncation(), x);
      },
      distribution.parameters());
}

double log_density(const Distribution& distribution, double x) {
  if (std::isnan(x))
    return x;
  return std::visit(
      [&](const auto& p) -> double {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, Normal>) {
          if (std::isinf(x))
            return -kInfinity;
          return log_normal_density((x - p.mean) / p.sd) - std::log(p.sd);
        } else if constexpr (std::is_same_v<P, Lognormal>) {
          if (x <= 0.0 || std::isinf(x))
            return -kInfinity;
          const double log_x = std::log(x);
          return log_normal_density((log_x - std::log(p.median)) / p.sigma) - std::log(p.sigma) -
                 log_x;
        } else if constexpr (std::is_same_v<P, Uniform>) {
          return x < p.min || x > p.max ? -kInfinity : -std::log(p.max - p.min);
        } else {
          if (x < p.min || x > p.max || std::isinf(x))
            return -kInfinity;
          return log_normal_density((x - p.mean) / p.sd) - std::log(p.sd) -
                 std::log(distribution.truncation().mass);
        }
      },
      distribution.parameters());
}

double mean(const Distribution& distribution) {
  return std::visit(
      [&](const auto& p) -> double {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, Normal>)
          return p.mean;
        else if constexpr (std::is_same_v<P, Lognormal>)
          return p.median * std::exp(0.5 * p.sigma * p.sigma);
        else if constexpr (std::is_same_v<P, Uniform>)
          return 0.5 * (p.min + p.max);
        else
          return truncated_mean(p, distribution.truncation());
      },
      distribution.parameters());
}

double standard_deviation(const Distribution& distribution) {
  return std::visit(
      [&](const auto& p) -> double {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, Normal>)
          return p.sd;
        else if constexpr (std::is_same_v<P, Lognormal>)
          return p.median * std::exp(0.5 * p.sigma * p.sigma) *
                 std::sqrt(std::expm1(p.sigma * p.sigma));
        else if constexpr (std::is_same_v<P, Uniform>)
          return (p.max - p.min) / std::sqrt(12.0);
        else
          return truncated_standard_deviation(p, distribution.truncation());
      },
      distribution.parameters());
}

Support support(const Distribution& distribution) {
  return std::visit(
      [](const auto& p) -> Support {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, Normal>)
          return {-kInfinity, kInfinity};
        else if constexpr (std::is_same_v<P, Lognormal>)
          return {0.0, kInfinity};
        else
          return {p.min, p.max};
      },
      distribution.parameters());
}

}  // namespace robomill::uncertainty
