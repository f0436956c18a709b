// Statistics of per-draw results: the type-7 empirical quantile (NumPy's
// default) and its order-statistic standard error, the fraction of draws
// below a threshold with its binomial standard error, the mean and sd, and
// the inputs they refuse. The standard errors are checked twice: against
// the asymptotic formula on a sample with no randomness in it, and against
// the actual scatter of the estimates over many seeds (calibration).

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "robomill/core/constants.hpp"
#include "robomill/uncertainty/distribution.hpp"
#include "robomill/uncertainty/draws.hpp"
#include "robomill/uncertainty/sample_statistics.hpp"
#include "uncertainty/refusal.hpp"

namespace test_sample_statistics_cpp {

namespace {

using robomill::uncertainty::Distribution;
using robomill::uncertainty::DrawSettings;
using robomill::uncertainty::Normal;
namespace uq = robomill::uncertainty;
using robomill::uncertainty::test_support::mentions;
using robomill::uncertainty::test_support::refusal;

// Sorted: −0.4, 2.2, 3.1, 5.9, 7.25. p = 0.37: h = 4 × 0.37 = 1.48, so
// 2.2 + 0.48 × 0.9 = 2.632 (numpy.quantile gives the same); p = 0.9: h = 3.6,
// 5.9 + 0.6 × 1.35 = 6.71. The SE at 0.37 by hand: d = √(5 × 0.37 × 0.63) =
// 1.0796 ranks, ranks 0.4004 and 2.5596 give 0.64104 and 4.66688, half the
// gap 2.01292.
TEST(SampleStatistics, EmpiricalQuantileIsHyndmanFanType7) {
  const std::vector<double> values = {3.1, -0.4, 7.25, 2.2, 5.9};
  const auto at_37 = uq::empirical_quantile(values, 0.37);
  EXPECT_NEAR(at_37.value, 2.632, 1e-14);
  EXPECT_NEAR(at_37.standard_error, 2.0128747829023466, 1e-12);
  EXPECT_NEAR(uq::empirical_quantile(values, 0.9).value, 6.71, 1e-14);
  EXPECT_EQ(uq::empirical_quantile(values, 0.5).value, 3.1);
  EXPECT_EQ(uq::empirical_quantile(values, 0.0).value, -0.4);
  EXPECT_EQ(uq::empirical_quantile(values, 1.0).value, 7.25);
  EXPECT_EQ(uq::empirical_quantile(values, 1.0).standard_error, 0.0);
  const std::vector<double> probabilities = {0.9, 0.37};
  const auto both = uq::empirical_quantiles(values, probabilities);
  ASSERT_EQ(both.size(), 2u);
  EXPECT_EQ(both[0].value, uq::empirical_quantile(values, 0.9).value);
  EXPECT_EQ(both[1].standard_error, at_37.standard_error);
}

// No spread, no error: one draw, or equal draws, give that value back exactly
// with standard error 0 (a zero-spread run must reproduce the nominal result).
TEST(SampleStatistics, EqualValuesGiveThemselvesWithoutError) {
  const std::vector<double> one = {0.00173};
  EXPECT_EQ(uq::empirical_quantile(one, 0.05).value, 0.00173);
  EXPECT_EQ(uq::empirical_quantile(one, 0.05).standard_error, 0.0);
  const std::vector<double> equal(7, 2.3e9 + 0.1);
  EXPECT_EQ(uq::sample_mean(equal).value, 2.3e9 + 0.1);
  EXPECT_EQ(uq::sample_mean(equal).standard_error, 0.0);
  EXPECT_EQ(uq::sample_standard_deviation(equal), 0.0);
  EXPECT_EQ(uq::empirical_quantile(equal, 0.95).value, 2.3e9 + 0.1);
  EXPECT_EQ(uq::empirical_quantile(equal, 0.95).standard_error, 0.0);
}

// A sample with no randomness: xᵢ = Φ⁻¹((i + ½)/n), n = 4096, a perfectly
// stratified normal sample. Its order-statistic half-bracket must equal the
// asymptotic SE √(p(1 − p)/n)/φ(Φ⁻¹(p)) of a sample quantile: the method's
// claim. 1 %: the bracket spans ±√(np(1 − p)) ranks, over which Φ⁻¹'s
// curvature changes the slope by under 0.3 % at these p.
TEST(SampleStatistics, QuantileErrorMatchesTheAsymptoticFormula) {
  const Distribution standard(Normal{0.0, 1.0});
  const int n = 4096;
  std::vector<double> values(n);
  for (int i = 0; i < n; ++i)
    values[static_cast<std::size_t>(i)] = uq::quantile(standard, (i + 0.5) / n);
  for (double p : {0.5, 0.05, 0.9, 0.0137}) {
    SCOPED_TRACE(p);
    const double q = uq::quantile(standard, p);
    const double density = std::exp(-0.5 * q * q) / std::sqrt(robomill::kTwoPi);
    const double asymptotic = std::sqrt(p * (1.0 - p) / n) / density;
    EXPECT_NEAR(uq::empirical_quantile(values, p).standard_error, asymptotic, 0.01 * asymptotic);
  }
}

// Calibration: over 400 seeds of 513 independent normal draws, the scatter
// (sd) of the estimated 10 % quantile equals the average SE the estimator
// reports. The sd of 400 values is known to ±1/√800 = 3.5 %, so ±15 % is
// more than 4 of its sds. Likewise the scatter of the fraction below a
// threshold (true p = Φ(−0.843) = 0.1995) against √(p(1 − p)/n).
TEST(SampleStatistics, StandardErrorsMatchTheScatterOverSeeds) {
  const std::vector<Distribution> variable = {Distribution(Normal{-2.4, 0.83})};
  const int seeds = 400, n = 513;
  std::vector<double> quantiles, fractions;
  double reported = 0.0;
  for (int seed = 0; seed < seeds; ++seed) {
    DrawSettings settings;
    settings.samples = n;
    settings.seed = 7000 + static_cast<std::uint64_t>(seed);
    settings.sampling = DrawSettings::Sampling::random;
    const Eigen::MatrixXd draws = uq::draw(variable, settings);
    const std::vector<double> values(draws.data(), draws.data() + draws.rows());
    const auto q10 = uq::empirical_quantile(values, 0.1);
    quantiles.push_back(q10.value);
    reported += q10.standard_error / seeds;
    fractions.push_back(uq::fraction_below(values, -3.1).value);
  }
  EXPECT_NEAR(uq::sample_standard_deviation(quantiles) / reported, 1.0, 0.15);
  const double p = uq::cdf(variable[0], -3.1);
  EXPECT_NEAR(uq::sample_standard_deviation(fractions) / std::sqrt(p * (1.0 - p) / n), 1.0, 0.15);
  EXPECT_NEAR(uq::sample_mean(fractions).value, p, 4.0 * std::sqrt(p * (1.0 - p) / n / seeds));
}

// 37 of 0.001, 0.002, ..., 1.000 lie below 0.0375: p̂ = 0.037, SE
// √(0.037 × 0.963/1000) = 0.005969. "Below" is strict: a value equal to the
// threshold does not count (a limit equal to the depth is not chatter).
TEST(SampleStatistics, FractionBelowWithBinomialError) {
  std::vector<double> values(1000);
  for (int i = 0; i < 1000; ++i)
    values[static_cast<std::size_t>(i)] = 0.001 * (i + 1);
  const auto below = uq::fraction_below(values, 0.0375);
  EXPECT_DOUBLE_EQ(below.value, 0.037);
  EXPECT_NEAR(below.standard_error, 0.005969170796685248, 1e-15);
  const std::vector<double> ties = {1.5, 2.5, 2.5, 4.0};
  EXPECT_EQ(uq::fraction_below(ties, 2.5).value, 0.25);
  EXPECT_EQ(uq::fraction_below(ties, 1.5).value, 0.0);
  EXPECT_EQ(uq::fraction_below(ties, 1.5).standard_error, 0.0);
  EXPECT_EQ(uq::fraction_below(ties, 4.01).value, 1.0);
}

// The risk bound's order statistic on 37 values nobody chose (frac(k φ)
// scaled), at fractions that are not round: v = the (⌊p n⌋ + 1)-th
// smallest, so at most p n values lie at or below anything under v and more
// than p n at or below v. p n = 3 exactly in floating point's eyes
// (0.15 × 20 = 3.0000000000000004) counts as 3. ⌊p n⌋ ≥ n: none.
TEST(SampleStatistics, ValueAtFractionBoundIsTheOrderStatistic) {
  std::vector<double> values;
  for (int k = 1; k <= 37; ++k)
    values.push_back(3.7 * std::fmod(k * 0.6180339887498949, 1.0) + 0.21);
  std::vector<double> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  for (const double p : {0.0, 0.0137, 0.05, 0.19, 0.5, 0.8648, 0.973}) {
    SCOPED_TRACE("p " + std::to_string(p));
    const std::optional<double> v = uq::value_at_fraction_bound(values, p);
    ASSERT_TRUE(v.has_value());
    EXPECT_EQ(*v, sorted[static_cast<std::size_t>(std::floor(p * 37.0))]);
    const auto at_or_below = [&](double t) {
      return static_cast<double>(
          std::count_if(values.begin(), values.end(), [t](double x) { return x <= t; }));
    };
    EXPECT_LE(at_or_below(std::nextafter(*v, -1.0)), p * 37.0);
    EXPECT_GT(at_or_below(*v), p * 37.0);
  }
  std::vector<double> twenty(sorted.begin(), sorted.begin() + 20);
  EXPECT_EQ(*uq::value_at_fraction_bound(twenty, 0.15), twenty[3]);
  EXPECT_FALSE(uq::value_at_fraction_bound(values, 1.0).has_value());
  EXPECT_TRUE(mentions(refusal([&] { (void)uq::value_at_fraction_bound(values, 1.5); }), "[0, 1]"));
}

// {2.5, 3.75, −1.125, 0.875}: mean 1.5, squared deviations 1 + 5.0625 +
// 6.890625 + 0.390625 = 13.34375, sd √(13.34375/3) = 2.109008..., SE of the
// mean sd/2.
TEST(SampleStatistics, MeanAndSampleStandardDeviation) {
  const std::vector<double> values = {2.5, 3.75, -1.125, 0.875};
  const auto mean = uq::sample_mean(values);
  EXPECT_DOUBLE_EQ(mean.value, 1.5);
  EXPECT_NEAR(uq::sample_standard_deviation(values), 2.109008455807294, 1e-14);
  EXPECT_NEAR(mean.standard_error, 1.054504227903647, 1e-14);
}

TEST(SampleStatistics, RefusesEmptySamplesNaNsAndBadProbabilities) {
  const std::vector<double> none;
  const std::vector<double> with_nan = {0.2, std::numeric_limits<double>::quiet_NaN(), 0.7};
  const std::vector<double> fine = {0.2, 0.5, 0.7};
  EXPECT_TRUE(mentions(refusal([&] { (void)uq::sample_mean(none); }), "no values"));
  EXPECT_TRUE(mentions(refusal([&] { (void)uq::empirical_quantile(with_nan, 0.5); }),
                       "value 1 (0-based) is not a number"));
  EXPECT_TRUE(
      mentions(refusal([&] { (void)uq::empirical_quantile(fine, 1.2); }), "not inside [0, 1]"));
  EXPECT_TRUE(
      mentions(refusal([&] { (void)uq::empirical_quantile(fine, -0.1); }), "not inside [0, 1]"));
  EXPECT_TRUE(mentions(
      refusal([&] { (void)uq::fraction_below(fine, std::numeric_limits<double>::quiet_NaN()); }),
      "threshold is not a number"));
  EXPECT_TRUE(
      mentions(refusal([&] { (void)uq::sample_standard_deviation(with_nan); }), "not a number"));
}

}  // namespace

}  // namespace test_sample_statistics_cpp
