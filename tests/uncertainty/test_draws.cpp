// Draws of uncertain inputs: the point sets (Boost's Sobol sequence with a
// seeded Cranley-Patterson shift, or mt19937_64), their reproducibility, the
// marginals and the Gaussian-copula correlation they produce, the
// Monte-Carlo error's 1/√n law, and the correlation matrices they refuse.
//
// Statistical checks use fixed seeds, so each is deterministic; each
// tolerance is a multiple (3 or 4) of the estimate's standard error for
// independent draws, so a correct implementation would fail it with a
// probability of about 0.3 % (3 SE) or 6e-5 (4 SE) per seed, and Sobol
// draws, whose errors are smaller, with less.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <boost/random/sobol.hpp>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "robomill/core/constants.hpp"
#include "robomill/uncertainty/distribution.hpp"
#include "robomill/uncertainty/draws.hpp"
#include "robomill/uncertainty/sample_statistics.hpp"
#include "uncertainty/refusal.hpp"

namespace test_draws_cpp {

namespace {

using robomill::uncertainty::Distribution;
using robomill::uncertainty::DrawSettings;
using robomill::uncertainty::Lognormal;
using robomill::uncertainty::Normal;
using robomill::uncertainty::TruncatedNormal;
using robomill::uncertainty::Uniform;
namespace uq = robomill::uncertainty;
using robomill::uncertainty::test_support::mentions;
using robomill::uncertainty::test_support::refusal;
using Sampling = DrawSettings::Sampling;

constexpr double kInf = std::numeric_limits<double>::infinity();

DrawSettings settings_of(int samples, std::uint64_t seed, Sampling sampling) {
  DrawSettings settings;
  settings.samples = samples;
  settings.seed = seed;
  settings.sampling = sampling;
  return settings;
}

std::vector<double> column_of(const Eigen::MatrixXd& draws, Eigen::Index j) {
  return std::vector<double>(draws.col(j).data(), draws.col(j).data() + draws.rows());
}

double pearson(const std::vector<double>& a, const std::vector<double>& b) {
  const double mean_a = uq::sample_mean(a).value, mean_b = uq::sample_mean(b).value;
  double ab = 0.0, aa = 0.0, bb = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ab += (a[i] - mean_a) * (b[i] - mean_b);
    aa += (a[i] - mean_a) * (a[i] - mean_a);
    bb += (b[i] - mean_b) * (b[i] - mean_b);
  }
  return ab / std::sqrt(aa * bb);
}

std::vector<double> ranks_of(const std::vector<double>& values) {
  std::vector<std::size_t> order(values.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t i, std::size_t j) { return values[i] < values[j]; });
  std::vector<double> ranks(values.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    ranks[order[k]] = static_cast<double>(k);
  return ranks;
}

// draws.cpp does not skip a point itself: Boost's sequence starts after the
// all-zero point, at (1/2, 1/2, 1/2), then (3/4, 1/4, 1/4) (Boost's
// documentation). Checked here so that a Boost that changed it would fail.
TEST(Draws, BoostSobolStartsAfterTheAllZeroPoint) {
  boost::random::sobol sequence(3);
  const std::uint64_t half = std::uint64_t{1} << 63;
  for (int j = 0; j < 3; ++j)
    EXPECT_EQ(sequence(), half);
  EXPECT_EQ(sequence(), half + (half >> 1));
  EXPECT_EQ(sequence(), half >> 1);
  EXPECT_EQ(sequence(), half >> 1);
}

// The same seed gives the same points bit for bit; another seed shifts every
// coordinate (all differ); fewer samples give the first rows; no coordinate
// is 0 or 1.
TEST(Draws, SobolPointsAreReproducibleSeededAndInsideTheOpenCube) {
  const auto first = uq::uniform_points(3, settings_of(517, 20240611, Sampling::sobol));
  const auto again = uq::uniform_points(3, settings_of(517, 20240611, Sampling::sobol));
  const auto other = uq::uniform_points(3, settings_of(517, 20240612, Sampling::sobol));
  const auto prefix = uq::uniform_points(3, settings_of(300, 20240611, Sampling::sobol));
  ASSERT_EQ(first.rows(), 517);
  ASSERT_EQ(first.cols(), 3);
  EXPECT_TRUE((first.array() == again.array()).all());
  EXPECT_TRUE((first.array() != other.array()).all());
  EXPECT_TRUE((first.topRows(300).array() == prefix.array()).all());
  EXPECT_GT(first.minCoeff(), 0.0);
  EXPECT_LT(first.maxCoeff(), 1.0);

  const auto random = uq::uniform_points(3, settings_of(517, 20240611, Sampling::random));
  EXPECT_TRUE((random.array() ==
               uq::uniform_points(3, settings_of(517, 20240611, Sampling::random)).array())
                  .all());
  EXPECT_GT(random.minCoeff(), 0.0);
  EXPECT_LT(random.maxCoeff(), 1.0);
}

// Each coordinate of a Sobol sequence is a (0,1)-sequence in base 2: its
// first 1024 points fill 1024 cells of width 1/1024 once each, and a shift
// modulo 1 keeps that, so 64 bins of width 1/64 hold 16 points each (15 to 17
// here, since Boost's point 1024 stands in for the skipped point 0). 1024
// independent points scatter 16 ± 4 per bin: the stratification is what
// makes quasi-random estimates converge faster.
TEST(Draws, ShiftedSobolPointsStayStratified) {
  const auto count_extremes = [](const Eigen::MatrixXd& points, Eigen::Index j) {
    std::vector<int> bins(64, 0);
    for (Eigen::Index i = 0; i < points.rows(); ++i)
      ++bins[static_cast<std::size_t>(points(i, j) * 64.0)];
    return std::pair{*std::min_element(bins.begin(), bins.end()),
                     *std::max_element(bins.begin(), bins.end())};
  };
  const auto sobol = uq::uniform_points(3, settings_of(1024, 9173, Sampling::sobol));
  const auto random = uq::uniform_points(3, settings_of(1024, 9173, Sampling::random));
  for (Eigen::Index j = 0; j < 3; ++j) {
    const auto [fewest, most] = count_extremes(sobol, j);
    EXPECT_GE(fewest, 15);
    EXPECT_LE(most, 17);
    const auto [random_fewest, random_most] = count_extremes(random, j);
    EXPECT_TRUE(random_fewest < 12 || random_most > 20);
  }
}

// A lognormal's median and log-sd come back from 4096 draws within 3
// standard errors: the median's order-statistic SE (≈ √(π/2)·m·s/√n) and the
// sd of a normal sample's SE s/√(2(n − 1)).
TEST(Draws, LognormalMedianAndLogSdAreRecovered) {
  const std::vector<Distribution> stiffness = {Distribution(Lognormal{3.41e7, 0.263})};
  for (const auto sampling : {Sampling::sobol, Sampling::random}) {
    SCOPED_TRACE(sampling == Sampling::sobol ? "sobol" : "random");
    const auto draws = uq::draw(stiffness, settings_of(4096, 4477, sampling));
    const auto values = column_of(draws, 0);
    const auto median = uq::empirical_quantile(values, 0.5);
    EXPECT_NEAR(median.value, 3.41e7, 3.0 * median.standard_error);
    EXPECT_NEAR(median.standard_error, std::sqrt(robomill::kPi / 2.0) * 3.41e7 * 0.263 / 64.0,
                0.25 * median.standard_error);
    std::vector<double> logs(values.size());
    std::transform(values.begin(), values.end(), logs.begin(),
                   [](double x) { return std::log(x); });
    EXPECT_NEAR(uq::sample_standard_deviation(logs), 0.263, 3.0 * 0.263 / std::sqrt(2.0 * 4095.0));
  }
}

// Correlation 0.63 on the normal scale between a normal and a lognormal
// variable: the normal scores (x − μ)/σ and ln(x/m)/s of 2048 draws have
// Pearson correlation 0.63 within 4 SE, SE = (1 − ρ²)/√n (Fisher's
// large-sample SE of r); each score keeps mean 0 (4/√n) and sd 1 (4/√(2n)).
TEST(Draws, CorrelationIsRecoveredOnTheNormalScale) {
  const std::vector<Distribution> variables = {Distribution(Normal{0.0217, 0.0041}),
                                               Distribution(Lognormal{2.9e7, 0.22})};
  const double rho = 0.63, n = 2048.0;
  for (const auto sampling : {Sampling::sobol, Sampling::random}) {
    SCOPED_TRACE(sampling == Sampling::sobol ? "sobol" : "random");
    auto settings = settings_of(2048, 60213, sampling);
    settings.correlation = Eigen::Matrix2d{{1.0, rho}, {rho, 1.0}};
    const auto draws = uq::draw(variables, settings);
    std::vector<double> score_normal(2048), score_lognormal(2048);
    for (Eigen::Index i = 0; i < draws.rows(); ++i) {
      score_normal[static_cast<std::size_t>(i)] = (draws(i, 0) - 0.0217) / 0.0041;
      score_lognormal[static_cast<std::size_t>(i)] = std::log(draws(i, 1) / 2.9e7) / 0.22;
    }
    EXPECT_NEAR(pearson(score_normal, score_lognormal), rho,
                4.0 * (1.0 - rho * rho) / std::sqrt(n));
    for (const auto* scores : {&score_normal, &score_lognormal}) {
      EXPECT_NEAR(uq::sample_mean(*scores).value, 0.0, 4.0 / std::sqrt(n));
      EXPECT_NEAR(uq::sample_standard_deviation(*scores), 1.0, 4.0 / std::sqrt(2.0 * n));
    }
  }
}

// The copula leaves ranks alone: between a uniform and a truncated normal
// variable with normal-scale correlation −0.41, Spearman's rank correlation
// is (6/π)·asin(ρ/2) (Pearson 1907; Kruskal 1958), within 3/√n (three times
// its standard error under independence, 1/√(n − 1), an upper bound here).
TEST(Draws, RankCorrelationFollowsTheGaussianCopula) {
  const std::vector<Distribution> variables = {
      Distribution(Uniform{-0.0713, 0.3391}),
      Distribution(TruncatedNormal{1.06, 0.21, 0.83, 1.47})};
  const double rho = -0.41;
  for (const auto sampling : {Sampling::sobol, Sampling::random}) {
    SCOPED_TRACE(sampling == Sampling::sobol ? "sobol" : "random");
    auto settings = settings_of(2048, 60213, sampling);
    settings.correlation = Eigen::Matrix2d{{1.0, rho}, {rho, 1.0}};
    const auto draws = uq::draw(variables, settings);
    const double spearman = pearson(ranks_of(column_of(draws, 0)), ranks_of(column_of(draws, 1)));
    EXPECT_NEAR(spearman, 6.0 / robomill::kPi * std::asin(rho / 2.0), 3.0 / std::sqrt(2048.0));
    EXPECT_GE(draws.col(1).minCoeff(), 0.83);
    EXPECT_LE(draws.col(1).maxCoeff(), 1.47);
  }
}

// The root-mean-square error of a mean over seeds, against the exact mean.
double rms_error_of_mean(const Distribution& variable, int samples, int seeds, Sampling sampling) {
  const double exact = uq::mean(variable);
  double squares = 0.0;
  for (int seed = 0; seed < seeds; ++seed) {
    const auto draws = uq::draw(
        {variable}, settings_of(samples, 1000 + static_cast<std::uint64_t>(seed), sampling));
    const double error = draws.col(0).mean() - exact;
    squares += error * error;
  }
  return std::sqrt(squares / seeds);
}

// Plain Monte Carlo: the error of a mean is σ/√n, so four times the draws
// halve it. Over 256 seeds the squared RMS error is σ²/n times a χ²₂₅₆/256
// variable (relative sd √(2/256) = 9 %), so the ratio of the RMS errors at
// 1268 and 317 draws is 0.5 times the square root of an F(256, 256) variable:
// the band 0.35-0.65 is 0.5 × (1 ∓ 0.3), more than four times that ratio's
// relative sd (6 %) on either side. Each RMS error is σ/√n within ±20 % (4.5 sd of
// its 4.4 %). Sobol draws (64 shifts) do better than half the Monte-Carlo
// error at 1268 draws: why they are the default.
TEST(Draws, MonteCarloErrorHalvesWithFourTimesTheDraws) {
  const Distribution factor(Lognormal{0.913, 0.287});
  const double sigma = uq::standard_deviation(factor);
  const double error_317 = rms_error_of_mean(factor, 317, 256, Sampling::random);
  const double error_1268 = rms_error_of_mean(factor, 1268, 256, Sampling::random);
  const double ratio = error_1268 / error_317;
  EXPECT_GT(ratio, 0.35);
  EXPECT_LT(ratio, 0.65);
  EXPECT_NEAR(error_317 / (sigma / std::sqrt(317.0)), 1.0, 0.2);
  EXPECT_NEAR(error_1268 / (sigma / std::sqrt(1268.0)), 1.0, 0.2);
  const double sobol_1268 = rms_error_of_mean(factor, 1268, 64, Sampling::sobol);
  EXPECT_LT(sobol_1268, 0.5 * sigma / std::sqrt(1268.0));
}

// Draws stay in the support (a one-sided truncated normal never goes below
// its min, a lognormal never reaches 0) and their mean agrees with the closed
// form within 3 SE.
TEST(Draws, DrawsStayInTheSupportAndMatchTheClosedFormMean) {
  const std::vector<Distribution> variables = {Distribution(TruncatedNormal{0.4, 0.35, 0.0, kInf}),
                                               Distribution(Lognormal{0.913, 0.287})};
  const auto draws = uq::draw(variables, settings_of(4096, 31337, Sampling::sobol));
  EXPECT_GE(draws.col(0).minCoeff(), 0.0);
  EXPECT_GT(draws.col(1).minCoeff(), 0.0);
  for (Eigen::Index j = 0; j < 2; ++j) {
    const auto mean = uq::sample_mean(column_of(draws, j));
    EXPECT_NEAR(mean.value, uq::mean(variables[static_cast<std::size_t>(j)]),
                3.0 * mean.standard_error);
  }
}

// With a correlation the whole matrix is still a function of the seed.
TEST(Draws, CorrelatedDrawsAreReproducible) {
  const std::vector<Distribution> variables = {Distribution(Normal{0.0217, 0.0041}),
                                               Distribution(Lognormal{2.9e7, 0.22}),
                                               Distribution(Uniform{-0.0713, 0.3391})};
  auto settings = settings_of(333, 8675309, Sampling::sobol);
  settings.correlation = Eigen::Matrix3d{{1.0, 0.63, -0.2}, {0.63, 1.0, 0.1}, {-0.2, 0.1, 1.0}};
  const auto first = uq::draw(variables, settings);
  EXPECT_TRUE((first.array() == uq::draw(variables, settings).array()).all());
  settings.seed = 8675310;
  EXPECT_FALSE((first.array() == uq::draw(variables, settings).array()).any());
}

// A correlation matrix that no set of variables can have, or that is not one,
// is refused with the reason.
TEST(Draws, RefusesInvalidCorrelationMatrices) {
  const std::vector<Distribution> two = {Distribution(Normal{0.0217, 0.0041}),
                                         Distribution(Lognormal{2.9e7, 0.22})};
  const std::vector<Distribution> three = {two[0], two[1], Distribution(Uniform{-0.0713, 0.3391})};
  const auto refusal_for = [](const std::vector<Distribution>& variables, Eigen::MatrixXd r) {
    auto settings = settings_of(64, 1, Sampling::sobol);
    settings.correlation = std::move(r);
    return refusal([&] { (void)uq::draw(variables, settings); });
  };
  // Pairwise plausible, jointly impossible: determinant −0.316.
  auto message =
      refusal_for(three, Eigen::Matrix3d{{1.0, 0.9, 0.1}, {0.9, 1.0, 0.8}, {0.1, 0.8, 1.0}});
  EXPECT_TRUE(mentions(message, "not positive definite") && mentions(message, "eigenvalue"))
      << message;
  message = refusal_for(two, Eigen::Matrix2d{{1.0, 1.0}, {1.0, 1.0}});
  EXPECT_TRUE(mentions(message, "not positive definite")) << message;
  message = refusal_for(two, Eigen::Matrix2d{{1.0, 0.3}, {0.35, 1.0}});
  EXPECT_TRUE(mentions(message, "not symmetric") && mentions(message, "(0, 1)")) << message;
  message = refusal_for(two, Eigen::Matrix2d{{1.0, 0.3}, {0.3, 0.97}});
  EXPECT_TRUE(mentions(message, "diagonal entry (1, 1)")) << message;
  message = refusal_for(two, Eigen::Matrix2d{{1.0, 1.2}, {1.2, 1.0}});
  EXPECT_TRUE(mentions(message, "outside [-1, 1]")) << message;
  message = refusal_for(two, Eigen::Matrix3d::Identity());
  EXPECT_TRUE(mentions(message, "3 x 3") && mentions(message, "2 variables")) << message;
}

TEST(Draws, RefusesSettingsThatDrawNothing) {
  const std::vector<Distribution> one = {Distribution(Normal{0.0217, 0.0041})};
  auto message = refusal([&] { (void)uq::draw(one, settings_of(0, 1, Sampling::sobol)); });
  EXPECT_TRUE(mentions(message, "samples must be at least 1")) << message;
  message = refusal([] { (void)uq::draw({}, settings_of(100, 1, Sampling::random)); });
  EXPECT_TRUE(mentions(message, "no variables")) << message;
  message = refusal([] { (void)uq::uniform_points(3668, settings_of(8, 1, Sampling::sobol)); });
  EXPECT_TRUE(mentions(message, "at most 3667")) << message;
}

}  // namespace

}  // namespace test_draws_cpp
