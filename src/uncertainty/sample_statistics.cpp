#include "robomill/uncertainty/sample_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

namespace robomill::uncertainty {
namespace {

void check_sample(std::span<const double> values, const char* what) {
  if (values.empty())
    throw std::invalid_argument(std::string(what) + ": no values");
  for (std::size_t i = 0; i < values.size(); ++i)
    if (std::isnan(values[i]))
      throw std::invalid_argument(std::string(what) + ": value " + std::to_string(i) +
                                  " (0-based) is not a number");
}

void check_probability(double p) {
  if (!(p >= 0.0 && p <= 1.0)) {
    std::ostringstream text;
    text << "empirical quantile: probability " << p << " is not inside [0, 1]";
    throw std::invalid_argument(text.str());
  }
}

/// The sorted values at a fractional 0-based rank, linearly interpolated
/// (Hyndman & Fan definition 7 at rank (n − 1)p), the rank clamped to
/// [0, n − 1].
double value_at_rank(const std::vector<double>& sorted, double rank) {
  const double last = static_cast<double>(sorted.size() - 1);
  const double clamped = std::clamp(rank, 0.0, last);
  const double below = std::floor(clamped);
  const auto index = static_cast<std::size_t>(below);
  if (index + 1 >= sorted.size() || clamped == below || sorted[index] == sorted[index + 1])
    return sorted[index];  // also keeps two equal infinite values from giving ∞ − ∞
  return sorted[index] + (clamped - below) * (sorted[index + 1] - sorted[index]);
}

/// Type-7 quantile and its order-statistic standard error from sorted values.
Estimate quantile_of_sorted(const std::vector<double>& sorted, double p) {
  check_probability(p);
  const double n = static_cast<double>(sorted.size());
  const double rank = (n - 1.0) * p;
  const double rank_spread = std::sqrt(n * p * (1.0 - p));
  Estimate estimate;
  estimate.value = value_at_rank(sorted, rank);
  const double upper = value_at_rank(sorted, rank + rank_spread);
  const double lower = value_at_rank(sorted, rank - rank_spread);
  estimate.standard_error = upper == lower ? 0.0 : 0.5 * (upper - lower);
  return estimate;
}

/// The average, summed as offsets from the first value: exact for equal
/// values (a draw set without spread gives its one value back), and no
/// precision lost to a large common offset.
double average_of(std::span<const double> values) {
  const double origin = values.front();
  double offsets = 0.0;
  for (double value : values)
    offsets += value - origin;
  return origin + offsets / static_cast<double>(values.size());
}

std::vector<double> sorted_copy(std::span<const double> values) {
  std::vector<double> sorted(values.begin(), values.end());
  std::sort(sorted.begin(), sorted.end());
  return sorted;
}

}  // namespace

Estimate sample_mean(std::span<const double> values) {
  check_sample(values, "sample mean");
  const double n = static_cast<double>(values.size());
  return {average_of(values), sample_standard_deviation(values) / std::sqrt(n)};
}

double sample_standard_deviation(std::span<const double> values) {
  check_sample(values, "sample standard deviation");
  if (values.size() == 1)
    return 0.0;
  const double average = average_of(values);
  double squares = 0.0;
  for (double value : values)
    squares += (value - average) * (value - average);
  return std::sqrt(squares / static_cast<double>(values.size() - 1));
}

Estimate empirical_quantile(std::span<const double> values, double p) {
  check_sample(values, "empirical quantile");
  check_probability(p);
  return quantile_of_sorted(sorted_copy(values), p);
}

std::vector<Estimate> empirical_quantiles(std::span<const double> values,
                                          std::span<const double> probabilities) {
  check_sample(values, "empirical quantile");
  for (double p : probabilities)
    check_probability(p);
  const std::vector<double> sorted = sorted_copy(values);
  std::vector<Estimate> estimates;
  estimates.reserve(probabilities.size());
  for (double p : probabilities)
    estimates.push_back(quantile_of_sorted(sorted, p));
  return estimates;
}

Estimate fraction_below(std::span<const double> values, double threshold) {
  check_sample(values, "fraction below");
  if (std::isnan(threshold))
    throw std::invalid_argument("fraction below: the threshold is not a number");
  const auto below = std::count_if(values.begin(), values.end(),
                                   [threshold](double value) { return value < threshold; });
  const double n = static_cast<double>(values.size());
  const double fraction = static_cast<double>(below) / n;
  return {fraction, std::sqrt(fraction * (1.0 - fraction) / n)};
}

std::optional<double> value_at_fraction_bound(std::span<const double> values, double p) {
  check_sample(values, "value at a fraction bound");
  if (!(p >= 0.0 && p <= 1.0))
    throw std::invalid_argument("value at a fraction bound: p must lie in [0, 1]");
  const std::size_t n = values.size();
  // 1e-9 keeps p n = 50.000000000000007 at 50.
  const auto allowed = static_cast<std::size_t>(std::floor(p * static_cast<double>(n) + 1e-9));
  if (allowed >= n)
    return std::nullopt;
  std::vector<double> copy(values.begin(), values.end());
  const auto at = copy.begin() + static_cast<std::ptrdiff_t>(allowed);
  std::nth_element(copy.begin(), at, copy.end());
  return *at;
}

}  // namespace robomill::uncertainty
