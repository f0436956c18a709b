#pragma once
// One uncertain input: an immutable, validated description of a
// one-dimensional probability distribution, and the free functions the
// propagation (draws.hpp) and, later, Bayesian updating need from it.
//
// Four families, with the parameters an engineer states (docs/uncertainty.md):
//
//   normal            N(μ, σ²)                      mean μ, sd σ
//   lognormal         ln X ~ N(ln m, s²)            median m > 0, sigma s (sd of ln X)
//   uniform           U[a, b]                       min a, max b
//   truncated_normal  N(μ, σ²) restricted to [a, b] mean μ, sd σ of the untruncated
//                                                   normal, min a, max b
//
// The normal CDF Φ and its inverse are Boost.Math's (boost::math::normal,
// evaluated in double precision: no promotion to long double, so the numbers
// do not depend on the platform's long double). The truncated normal's
// quantile and CDF are evaluated in whichever tail keeps them accurate (upper
// tail probabilities Q = 1 − Φ from Boost's complement), so a variable
// truncated far out in a tail keeps its precision; its mean and standard
// deviation are the closed forms of Barr & Sherrill, "Mean and variance of
// truncated normal distributions", The American Statistician 53(4), 1999.
//
// Numbers only: SI in, SI out; this module knows no job, file or unit.

#include <limits>
#include <string>
#include <variant>

namespace robomill::uncertainty {

/// Normal distribution N(mean, sd²).
struct Normal {
  double mean = 0.0;  ///< μ, in the variable's SI unit; finite
  double sd = 1.0;    ///< σ > 0, same unit; finite
};

/// Lognormal distribution: ln X ~ N(ln median, sigma²). The natural choice
/// for a positive quantity known to a factor (a joint stiffness ± 25 % is
/// roughly sigma 0.22), and for a dimensionless scale factor of median 1.
struct Lognormal {
  double median = 1.0;  ///< m = exp(E[ln X]) > 0, the variable's SI unit; finite
  double sigma = 0.1;   ///< s > 0: the standard deviation of ln X (dimensionless); finite
};

/// Continuous uniform distribution on [min, max].
struct Uniform {
  double min = 0.0;  ///< a, finite, < max
  double max = 1.0;  ///< b, finite
};

/// A normal N(mean, sd²) restricted to [min, max] and renormalized. mean and
/// sd are those of the untruncated normal (the distribution's own mean and
/// sd are mean() and standard_deviation() below). min may be −∞ and max +∞
/// (one-sided truncation, e.g. a stiffness kept positive with min 0).
struct TruncatedNormal {
  double mean = 0.0;  ///< μ of the untruncated normal; finite
  double sd = 1.0;    ///< σ > 0 of the untruncated normal; finite
  double min = -std::numeric_limits<double>::infinity();  ///< a (may be −∞), < max
  double max = std::numeric_limits<double>::infinity();   ///< b (may be +∞)
};

/// The interval a distribution's draws can take: [lower, upper], with
/// ±infinity where it is unbounded (lognormal: lower 0, never reached).
struct Support {
  double lower = -std::numeric_limits<double>::infinity();  ///< lowest value (or −∞)
  double upper = std::numeric_limits<double>::infinity();   ///< highest value (or +∞)
};

/// The truncated normal's interval is refused when it holds less than this
/// fraction of the untruncated normal's probability (bounds more than about
/// six sd beyond the mean): every draw would then sit at a bound, which is
/// a mistyped mean or bound rather than a belief.
inline constexpr double kMinimumTruncatedMass = 1e-9;

/// One validated distribution: an immutable value built from one of the
/// parameter structs above; the constructors throw std::invalid_argument,
/// naming the family and the parameter, when the parameters do not describe
/// a distribution (sd or sigma ≤ 0, min ≥ max, a non-finite value, a
/// median ≤ 0, a truncation interval with less than kMinimumTruncatedMass).
class Distribution {
 public:
  /// The parameters, one alternative per family.
  using Parameters = std::variant<Normal, Lognormal, Uniform, TruncatedNormal>;

  /// A normal distribution; throws std::invalid_argument on bad parameters.
  explicit Distribution(const Normal& normal);
  /// A lognormal distribution; throws std::invalid_argument on bad parameters.
  explicit Distribution(const Lognormal& lognormal);
  /// A uniform distribution; throws std::invalid_argument on bad parameters.
  explicit Distribution(const Uniform& uniform);
  /// A truncated normal distribution; throws std::invalid_argument on bad
  /// parameters or an interval holding (almost) none of the normal's mass.
  explicit Distribution(const TruncatedNormal& truncated);

  /// The parameters as given (std::get_if<Normal>(&d.parameters()) etc.).
  const Parameters& parameters() const noexcept { return parameters_; }

  /// Truncated normal only: the untruncated normal's CDF and upper-tail
  /// probability at the standardized bounds α = (min − μ)/σ, β = (max − μ)/σ,
  /// and the mass Z = Φ(β) − Φ(α) of the interval, each computed in the tail
  /// where it is accurate. Zero-initialized for the other families.
  struct TruncationTails {
    double alpha = 0.0;             ///< α = (min − μ)/σ (may be −∞)
    double beta = 0.0;              ///< β = (max − μ)/σ (may be +∞)
    double cdf_alpha = 0.0;         ///< Φ(α)
    double cdf_beta = 0.0;          ///< Φ(β)
    double upper_tail_alpha = 0.0;  ///< Q(α) = 1 − Φ(α)
    double upper_tail_beta = 0.0;   ///< Q(β) = 1 − Φ(β)
    double mass = 0.0;              ///< Z = Φ(β) − Φ(α) ≥ kMinimumTruncatedMass
  };

  /// The cached tail probabilities of a truncated normal (see TruncationTails).
  const TruncationTails& truncation() const noexcept { return truncation_; }

 private:
  Parameters parameters_;
  TruncationTails truncation_;
};

/// The family's name as the job file spells it: "normal", "lognormal",
/// "uniform" or "truncated_normal".
std::string family_name(const Distribution& distribution);

/// A one-line description for messages, e.g. "lognormal(median 1, sigma 0.25)".
std::string describe(const Distribution& distribution);

/// The inverse CDF F⁻¹(u): the value below which a fraction u of the
/// distribution lies, for u in the open interval (0, 1); throws
/// std::invalid_argument for u outside it (or NaN). Normal: μ + σΦ⁻¹(u);
/// lognormal: m·exp(sΦ⁻¹(u)); uniform: a + u(b − a); truncated normal:
/// μ + σΦ⁻¹(Φ(α) + uZ), evaluated through Q in the upper half.
double quantile(const Distribution& distribution, double u);

/// The CDF F(x) = P(X ≤ x) in [0, 1]; 0 below the support, 1 above it
/// (x = ±∞ allowed); NaN for a NaN x.
double cdf(const Distribution& distribution, double x);

/// The natural logarithm of the probability density at x (SI unit of x⁻¹
/// inside the logarithm); −∞ outside the support; NaN for a NaN x. For the
/// likelihood-times-prior products of Bayesian updating.
double log_density(const Distribution& distribution, double x);

/// The distribution's mean E[X] in closed form. Lognormal: m·exp(s²/2);
/// truncated normal: μ + σ(φ(α) − φ(β))/Z, φ the standard normal density
/// (Barr & Sherrill 1999).
double mean(const Distribution& distribution);

/// The distribution's standard deviation in closed form. Lognormal:
/// m·exp(s²/2)·√(exp(s²) − 1); uniform: (b − a)/√12; truncated normal:
/// σ·√(1 + (αφ(α) − βφ(β))/Z − ((φ(α) − φ(β))/Z)²), with αφ(α) = 0 at
/// α = ±∞ (Barr & Sherrill 1999).
double standard_deviation(const Distribution& distribution);

/// The support [lower, upper] (±∞ where unbounded; lognormal: [0, ∞)).
Support support(const Distribution& distribution);

}  // namespace robomill::uncertainty
