#pragma once
// What a set of per-draw results says, with its Monte-Carlo standard error:
// the quantity a lobe band, a chatter probability or a risk bound is read
// from.
//
// values[i] is one result per draw (e.g. the stability limit of draw i at one
// spindle speed). The standard errors assume independent draws (plain Monte
// Carlo). For randomly shifted Sobol draws they are conservative: the error
// of a quasi-random estimate of a smooth enough quantity shrinks faster than
// 1/√n, so the true error is at most about the one stated (for a fraction of
// draws below a threshold, an indicator, the gain is smaller but not
// negative in practice). docs/uncertainty.md says how many draws give a
// wanted precision.

#include <optional>
#include <span>
#include <vector>

namespace robomill::uncertainty {

/// A number estimated from draws, and its standard error (same unit).
struct Estimate {
  double value = 0.0;           ///< the estimate
  double standard_error = 0.0;  ///< its Monte-Carlo standard error (≥ 0)
};

/// The mean of the values, with standard error s/√n (s the sample standard
/// deviation, n the number of values; 0 for a single value). Equal values
/// give exactly that value back (no spread, no round-off). Throws
/// std::invalid_argument when values is empty or holds a NaN.
Estimate sample_mean(std::span<const double> values);

/// The sample standard deviation s = √(Σ(xᵢ − x̄)²/(n − 1)) (Bessel's
/// correction; two-pass, so a large common offset costs no precision); 0 for
/// a single value, which shows no spread. Throws std::invalid_argument when
/// values is empty or holds a NaN.
double sample_standard_deviation(std::span<const double> values);

/// The empirical p-quantile, Hyndman & Fan (The American Statistician 50(4),
/// 1996) definition 7, the default of NumPy (method "linear") and R: with the
/// values sorted x₀ ≤ … ≤ x_{n−1} and h = (n − 1)p, the value
/// x_⌊h⌋ + (h − ⌊h⌋)(x_⌊h⌋+1 − x_⌊h⌋); p = 0 gives the smallest, p = 1 the
/// largest value.
///
/// Standard error by the order-statistic (binomial) method: the number of
/// draws below the true quantile is Binomial(n, p), with standard deviation
/// d = √(np(1 − p)) ranks, so the order statistics d ranks either side of h
/// bracket the quantile with about 68 % confidence (the distribution-free
/// interval, Conover, Practical Nonparametric Statistics, 3rd ed., 1999,
/// §3.2); half that bracket is the standard error. It estimates the
/// asymptotic √(p(1 − p)/n)/f(q_p) (f the density at the quantile; Serfling,
/// Approximation Theorems of Mathematical Statistics, 1980, §2.3) without
/// estimating f. Ranks beyond the extreme values are clamped to them, so the
/// error is understated when n·min(p, 1 − p) is small: keep it above about
/// 10 (n ≥ 200 for a 5 % quantile).
///
/// Values may be ±∞ (a limit that does not exist): the quantile is then
/// infinite where the ranks reach them. Throws std::invalid_argument when
/// values is empty or holds a NaN, or p is outside [0, 1].
Estimate empirical_quantile(std::span<const double> values, double p);

/// empirical_quantile at several probabilities, sorting the values once.
std::vector<Estimate> empirical_quantiles(std::span<const double> values,
                                          std::span<const double> probabilities);

/// The fraction p̂ of values strictly below the threshold (e.g. the draws
/// whose stability limit lies below a depth: the probability that the depth
/// chatters), with the binomial standard error √(p̂(1 − p̂)/n). That error is 0
/// when no value or every value is below: then 3/n bounds the unseen fraction
/// at 95 % confidence (the "rule of three", docs/uncertainty.md). Throws
/// std::invalid_argument when values is empty or holds a NaN, or the threshold
/// is NaN.
Estimate fraction_below(std::span<const double> values, double threshold);

/// The (⌊p n⌋ + 1)-th smallest v of n values (p n within 1e-9 of an integer
/// counts as that integer): a risk bound read from the draws' limits. At
/// most a fraction p of the values lie at or below any threshold under v,
/// more than p at or below v; so with the draws' stability limits, a depth
/// under v has P(chatter) within p (and v is the deepest such depth when a
/// limit equal to the depth is not chatter). None when ⌊p n⌋ ≥ n (every
/// value may lie below). Throws std::invalid_argument when values is empty
/// or holds a NaN, or p is outside [0, 1].
std::optional<double> value_at_fraction_bound(std::span<const double> values, double p);

}  // namespace robomill::uncertainty
