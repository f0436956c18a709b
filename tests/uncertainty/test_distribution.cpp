// Distributions of uncertain inputs: quantiles, CDFs, densities and moments
// against 40-digit references (mpmath: quantiles from erfinv, moments by
// numerical integration of x·f(x), independent of the closed forms the code
// uses), and the parameters they must refuse.
//
// The probabilities and parameters are deliberately not round, so that a
// formula that happens to be right at u = 0.5 or σ = 1 cannot pass. Boost's
// normal quantile and CDF are accurate to a few ulp, so the tolerances are
// relative 1e-12 (a factor ~1000 above double round-off, far below any
// formula error) unless a test says otherwise.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "robomill/uncertainty/distribution.hpp"
#include "uncertainty/refusal.hpp"

namespace test_distribution_cpp {

namespace {

using robomill::uncertainty::Distribution;
using robomill::uncertainty::Lognormal;
using robomill::uncertainty::Normal;
using robomill::uncertainty::TruncatedNormal;
using robomill::uncertainty::Uniform;
namespace uq = robomill::uncertainty;
using robomill::uncertainty::test_support::mentions;
using robomill::uncertainty::test_support::refusal;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kRelative = 1e-12;

void expect_relative(double actual, double expected, double relative = kRelative) {
  EXPECT_NEAR(actual, expected, std::abs(expected) * relative);
}

// A stiffness-like normal: quantiles μ + σΦ⁻¹(u) at odd probabilities, and a
// far tail, where a poor inverse-CDF approximation shows first.
TEST(Distribution, NormalQuantileMatchesHighPrecisionReference) {
  const Distribution stiffness(Normal{2.87e7, 4.13e6});
  expect_relative(uq::quantile(stiffness, 0.0371), 21326388.231739509584);
  expect_relative(uq::quantile(stiffness, 0.4129), 27791022.664300340531);
  expect_relative(uq::quantile(stiffness, 0.9786), 37065961.236484506015);
  expect_relative(uq::quantile(Distribution(Normal{0.0, 1.0}), 3.7e-8), -5.3811779427107443559);
}

// m·exp(sΦ⁻¹(u)): the median and log-sd enter as stated, not as the mean and
// sd of X.
TEST(Distribution, LognormalQuantileMatchesHighPrecisionReference) {
  const Distribution factor(Lognormal{0.913, 0.287});
  expect_relative(uq::quantile(factor, 0.0271), 0.52541767372424033824);
  expect_relative(uq::quantile(factor, 0.6617), 1.0291059005360179559);
  expect_relative(uq::quantile(factor, 0.9903), 1.7858885387632991871);
  expect_relative(uq::quantile(factor, 0.5), 0.913);
}

TEST(Distribution, UniformQuantileIsLinear) {
  const Distribution uniform(Uniform{-0.0713, 0.3391});
  EXPECT_NEAR(uq::quantile(uniform, 0.2237), 0.02050648, 1e-15);
  EXPECT_NEAR(uq::cdf(uniform, 0.02050648), 0.2237, 1e-14);
}

// Doubly truncated normal: μ + σΦ⁻¹(Φ(α) + uZ).
TEST(Distribution, TruncatedNormalQuantileMatchesHighPrecisionReference) {
  const Distribution truncated(TruncatedNormal{1.06, 0.21, 0.83, 1.47});
  expect_relative(uq::quantile(truncated, 0.1313), 0.91617899425906811967);
  expect_relative(uq::quantile(truncated, 0.5077), 1.0928120974255263027);
  expect_relative(uq::quantile(truncated, 0.9461), 1.3689707222685778658);
}

// Truncated 4.3 sd above the mean, where Φ(α) = 1 − 8.5e-6 would keep only
// ~11 significant digits of the tail: evaluated through Q = 1 − Φ the
// quantile keeps ~13 (tolerance 1e-11 for the composition of two tail
// functions).
TEST(Distribution, TruncatedNormalKeepsPrecisionFarInTheUpperTail) {
  const Distribution one_sided(TruncatedNormal{0.0, 1.0, 4.3, kInf});
  expect_relative(uq::quantile(one_sided, 0.7213), 4.5750904310975643564, 1e-11);
  const Distribution bounded(TruncatedNormal{0.0, 1.0, 4.3, 5.1});
  expect_relative(uq::quantile(bounded, 0.2719), 4.3681880148125245142, 1e-11);
  EXPECT_GE(uq::quantile(one_sided, 1e-15), 4.3);
  EXPECT_NEAR(uq::cdf(one_sided, 4.5750904310975643564), 0.7213, 1e-10);
}

// F(F⁻¹(u)) = u for every family, across the range including both tails: the
// CDF and quantile are each other's inverse (absolute 1e-12: u itself is
// known to 1e-16, the slope of F can amplify round-off in x).
TEST(Distribution, CdfInvertsTheQuantile) {
  const std::vector<Distribution> all = {
      Distribution(Normal{2.87e7, 4.13e6}), Distribution(Lognormal{0.913, 0.287}),
      Distribution(Uniform{-0.0713, 0.3391}), Distribution(TruncatedNormal{1.06, 0.21, 0.83, 1.47}),
      Distribution(TruncatedNormal{0.4, 0.35, 0.0, kInf})};
  for (const auto& distribution : all) {
    SCOPED_TRACE(uq::describe(distribution));
    for (double u : {1.3e-9, 0.00731, 0.1709, 0.4993, 0.8377, 0.99961, 1.0 - 2.9e-9})
      EXPECT_NEAR(uq::cdf(distribution, uq::quantile(distribution, u)), u, 1e-12);
  }
}

TEST(Distribution, CdfAtKnownPointsAndOutsideTheSupport) {
  EXPECT_NEAR(uq::cdf(Distribution(Lognormal{0.913, 0.287}), 0.7), 0.17731938812234965772, 1e-14);
  const Distribution truncated(TruncatedNormal{1.06, 0.21, 0.83, 1.47});
  EXPECT_NEAR(uq::cdf(truncated, 0.9876), 0.27263978548557566657, 1e-14);
  EXPECT_EQ(uq::cdf(truncated, 0.82), 0.0);
  EXPECT_EQ(uq::cdf(truncated, 1.48), 1.0);
  EXPECT_EQ(uq::cdf(Distribution(Lognormal{0.913, 0.287}), -0.3), 0.0);
  EXPECT_EQ(uq::cdf(Distribution(Normal{0.0, 1.0}), kInf), 1.0);
}

// Means and sds against ∫x f(x) dx and ∫(x − m)² f(x) dx done numerically to
// 40 digits, so the closed forms (Barr & Sherrill for the truncated normal,
// including its one-sided case with β = ∞) are checked, not restated.
TEST(Distribution, MeanAndSdMatchNumericalIntegrals) {
  const Distribution truncated(TruncatedNormal{1.06, 0.21, 0.83, 1.47});
  expect_relative(uq::mean(truncated), 1.1000213949791617015);
  expect_relative(uq::standard_deviation(truncated), 0.15420124454264663859, 1e-11);
  const Distribution one_sided(TruncatedNormal{0.4, 0.35, 0.0, kInf});
  expect_relative(uq::mean(one_sided), 0.48319910510442019971);
  expect_relative(uq::standard_deviation(one_sided), 0.28687674508062789436, 1e-11);
  const Distribution factor(Lognormal{0.913, 0.287});
  expect_relative(uq::mean(factor), 0.95138648697814917154);
  expect_relative(uq::standard_deviation(factor), 0.27876828200776234721);
  const Distribution uniform(Uniform{-0.0713, 0.3391});
  expect_relative(uq::mean(uniform), 0.1339);
  expect_relative(uq::standard_deviation(uniform), 0.4104 / std::sqrt(12.0));
  EXPECT_EQ(uq::mean(Distribution(Normal{2.87e7, 4.13e6})), 2.87e7);
  EXPECT_EQ(uq::standard_deviation(Distribution(Normal{2.87e7, 4.13e6})), 4.13e6);
}

// ln f at points inside (references from mpmath), −∞ outside, and the
// truncated density's normalization: exp(log_density) integrates to 1 over
// [min, max] (Simpson's rule on 2000 panels: error ~1e-13 for this smooth
// integrand, tolerance 1e-9), which checks the −ln Z term.
TEST(Distribution, LogDensityMatchesReferenceAndIntegratesToOne) {
  const Distribution truncated(TruncatedNormal{1.06, 0.21, 0.83, 1.47});
  EXPECT_NEAR(uq::log_density(truncated, 1.2345), 0.4733876599720968563, 1e-13);
  EXPECT_NEAR(uq::log_density(Distribution(Lognormal{0.913, 0.287}), 1.37), -0.98523401368960399099,
              1e-13);
  EXPECT_NEAR(uq::log_density(Distribution(Normal{2.87e7, 4.13e6}), 3.05e7), -16.247702724771580616,
              1e-12);
  EXPECT_NEAR(uq::log_density(Distribution(Uniform{-0.0713, 0.3391}), 0.1), -std::log(0.4104),
              1e-14);
  EXPECT_EQ(uq::log_density(truncated, 0.8299), -kInf);
  EXPECT_EQ(uq::log_density(Distribution(Lognormal{0.913, 0.287}), 0.0), -kInf);
  EXPECT_EQ(uq::log_density(Distribution(Uniform{-0.0713, 0.3391}), 0.34), -kInf);

  const int panels = 2000;
  const double a = 0.83, b = 1.47, h = (b - a) / panels;
  double integral = 0.0;
  for (int i = 0; i <= panels; ++i) {
    const double weight = (i == 0 || i == panels) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
    integral += weight * std::exp(uq::log_density(truncated, a + i * h));
  }
  EXPECT_NEAR(integral * h / 3.0, 1.0, 1e-9);
}

TEST(Distribution, SupportIsInfiniteWhereUnbounded) {
  const auto normal = uq::support(Distribution(Normal{2.87e7, 4.13e6}));
  EXPECT_EQ(normal.lower, -kInf);
  EXPECT_EQ(normal.upper, kInf);
  const auto lognormal = uq::support(Distribution(Lognormal{0.913, 0.287}));
  EXPECT_EQ(lognormal.lower, 0.0);
  EXPECT_EQ(lognormal.upper, kInf);
  const auto uniform = uq::support(Distribution(Uniform{-0.0713, 0.3391}));
  EXPECT_EQ(uniform.lower, -0.0713);
  EXPECT_EQ(uniform.upper, 0.3391);
  const auto one_sided = uq::support(Distribution(TruncatedNormal{0.4, 0.35, 0.0, kInf}));
  EXPECT_EQ(one_sided.lower, 0.0);
  EXPECT_EQ(one_sided.upper, kInf);
}

TEST(Distribution, DescribesItselfForMessages) {
  const Distribution factor(Lognormal{0.913, 0.287});
  EXPECT_EQ(uq::family_name(factor), "lognormal");
  EXPECT_EQ(uq::describe(factor), "lognormal(median 0.913, sigma 0.287)");
  EXPECT_EQ(uq::family_name(Distribution(TruncatedNormal{1.06, 0.21, 0.83, 1.47})),
            "truncated_normal");
}

// Parameters that describe no distribution are refused with a message naming
// the family and the parameter (the job layer adds the variable's name).
TEST(Distribution, RefusesBadParametersWithClearMessages) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto message = refusal([] { (void)Distribution(Normal{0.37, 0.0}); });
  EXPECT_TRUE(mentions(message, "normal") && mentions(message, "sd must be positive")) << message;
  message = refusal([] { (void)Distribution(Normal{0.37, -0.052}); });
  EXPECT_TRUE(mentions(message, "sd must be positive")) << message;
  message = refusal([nan] { (void)Distribution(Normal{nan, 0.052}); });
  EXPECT_TRUE(mentions(message, "mean must be a finite number")) << message;
  message = refusal([] { (void)Distribution(Lognormal{-2.1, 0.3}); });
  EXPECT_TRUE(mentions(message, "lognormal") && mentions(message, "median")) << message;
  message = refusal([] { (void)Distribution(Lognormal{2.1, 0.0}); });
  EXPECT_TRUE(mentions(message, "sigma must be positive")) << message;
  message = refusal([] { (void)Distribution(Uniform{0.57, 0.57}); });
  EXPECT_TRUE(mentions(message, "uniform") && mentions(message, "min must be below max"))
      << message;
  message = refusal([] { (void)Distribution(Uniform{-kInf, 0.57}); });
  EXPECT_TRUE(mentions(message, "min must be a finite number")) << message;
  message = refusal([] { (void)Distribution(TruncatedNormal{1.06, 0.21, 1.47, 0.83}); });
  EXPECT_TRUE(mentions(message, "truncated_normal") && mentions(message, "min must be below max"))
      << message;
  message = refusal([nan] { (void)Distribution(TruncatedNormal{1.06, 0.21, nan, 1.47}); });
  EXPECT_TRUE(mentions(message, "min must be a number")) << message;
}

// [6.7, 9.1] sd above the mean holds 1.04e-11 of a normal's probability, below
// kMinimumTruncatedMass: refused, with the mass in the message; [4.3, 5.1]
// (8.5e-6) is accepted.
TEST(Distribution, RefusesATruncationIntervalWithAlmostNoMass) {
  const auto message = refusal([] { (void)Distribution(TruncatedNormal{0.0, 1.0, 6.7, 9.1}); });
  EXPECT_TRUE(mentions(message, "holds only 1.04") && mentions(message, "bound")) << message;
  EXPECT_NO_THROW((void)Distribution(TruncatedNormal{0.0, 1.0, 4.3, 5.1}));
}

TEST(Distribution, QuantileRefusesProbabilitiesOutsideTheOpenInterval) {
  const Distribution factor(Lognormal{0.913, 0.287});
  for (double u : {0.0, 1.0, -0.2, 1.3, std::numeric_limits<double>::quiet_NaN()}) {
    const auto message = refusal([&] { (void)uq::quantile(factor, u); });
    EXPECT_TRUE(mentions(message, "not inside (0, 1)")) << message;
  }
}

}  // namespace

}  // namespace test_distribution_cpp
