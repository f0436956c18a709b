// The likelihood terms of a test cut and the expected information of one
// not yet run (learning/stability_evidence.hpp). Reference values computed
// independently (Python's math.erfc) and written with their derivation.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "robomill/learning/stability_evidence.hpp"

namespace robomill::learning {
namespace {

TEST(StabilityEvidence, TheProbitAroundTheLimit) {
  const VerdictModel model{0.1e-3, 0.05, 0.01};
  // At the limit: ε/2 + (1 − ε)/2 = 1/2 whatever ε.
  EXPECT_DOUBLE_EQ(chatter_probability(2.5e-3, 2.5e-3, model), 0.5);
  // σ = √(0.1² + (0.05 · 2.5)²) mm = 0.160078 mm; ap 0.2 mm above: z = 1.249390,
  // Φ(z) = 0.8942388 (Python), so P = 0.005 + 0.99 · 0.8942388.
  EXPECT_NEAR(verdict_sd_m(2.5e-3, model), 0.16007810593582123e-3, 1e-15);
  EXPECT_NEAR(chatter_probability(2.7e-3, 2.5e-3, model), 0.005 + 0.99 * 0.8942387852946356, 1e-9);
  EXPECT_NEAR(std::exp(log_verdict_likelihood(true, 2.7e-3, 2.5e-3, model)),
              chatter_probability(2.7e-3, 2.5e-3, model), 1e-12);
  EXPECT_NEAR(std::exp(log_verdict_likelihood(false, 2.7e-3, 2.5e-3, model)),
              1.0 - chatter_probability(2.7e-3, 2.5e-3, model), 1e-12);
  // A limit beyond reach (stable at every depth): chatter only by mislabel.
  const double infinite = std::numeric_limits<double>::infinity();
  EXPECT_DOUBLE_EQ(chatter_probability(5e-3, infinite, model), 0.005);
  EXPECT_NEAR(log_verdict_likelihood(true, 5e-3, infinite, model), std::log(0.005), 1e-12);
}

TEST(StabilityEvidence, TheTailsStayFiniteAndAccurate) {
  VerdictModel exact{0.1e-3, 0.0, 0.0};  // σ = 0.1 mm, no mislabel
  // z = −37 (ap 3.7 mm below the limit, chatter): the series branch against
  // erfc, which still holds the number (about 1e-300).
  const double by_erfc = std::log(0.5 * std::erfc(37.0 / std::numbers::sqrt2));
  EXPECT_NEAR(log_verdict_likelihood(true, 1.0e-3, 4.7e-3, exact), by_erfc,
              1e-9 * std::abs(by_erfc));
  // z = −300: far beyond erfc (0 in double), still finite and about −z²/2.
  const double far = log_verdict_likelihood(true, 1.0e-3, 31.0e-3, exact);
  EXPECT_TRUE(std::isfinite(far));
  EXPECT_NEAR(far, -45000.0 - std::log(300.0) - 0.5 * std::log(2.0 * std::numbers::pi), 1e-3);
  // With a mislabel chance the contradicting verdict costs log(ε/2), no more.
  const VerdictModel lapse{0.1e-3, 0.0, 0.02};
  EXPECT_NEAR(log_verdict_likelihood(true, 1.0e-3, 31.0e-3, lapse), std::log(0.01), 1e-9);
}

TEST(StabilityEvidence, TheNearestMemberOfTheChatterFamily) {
  // f_c = 612.3 Hz, 3 teeth at 3000 rpm: f_tooth = 150 Hz. The family
  // |±612.3 + 150 k| is {12.3, 137.7, 162.3, 287.7, 312.3, 437.7, ...}.
  EXPECT_NEAR(nearest_chatter_family_hz(290.0, 612.3, 150.0), 287.7, 1e-9);
  EXPECT_NEAR(nearest_chatter_family_hz(612.0, 612.3, 150.0), 612.3, 1e-9);
  EXPECT_NEAR(nearest_chatter_family_hz(20.0, 612.3, 150.0), 12.3, 1e-9);
  EXPECT_NEAR(nearest_chatter_family_hz(140.1, 612.3, 150.0), 137.7, 1e-9);
  EXPECT_DOUBLE_EQ(nearest_chatter_family_hz(290.0, 612.3, 0.0), 612.3);
  // The density: 20 Hz spread, 2.3 Hz off.
  EXPECT_NEAR(
      log_chatter_frequency_likelihood(290.0, 612.3, 150.0, 20.0),
      -0.5 * (2.3 / 20.0) * (2.3 / 20.0) - std::log(20.0 * std::sqrt(2.0 * std::numbers::pi)),
      1e-12);
}

TEST(StabilityEvidence, ExpectedInformationIsWhereTheSamplesDisagree) {
  EXPECT_DOUBLE_EQ(binary_entropy_bits(0.5), 1.0);
  EXPECT_DOUBLE_EQ(binary_entropy_bits(0.0), 0.0);
  // Every sample unsure in the same way: nothing to learn about θ.
  EXPECT_NEAR(expected_information_bits(std::vector<double>{0.5, 0.5, 0.5}), 0.0, 1e-15);
  // Half the samples sure of chatter, half sure of stable: one bit.
  EXPECT_NEAR(expected_information_bits(std::vector<double>{0.0, 1.0, 0.0, 1.0}), 1.0, 1e-15);
  // H(0.5) − H(0.2) = 0.2780719 bits (Python).
  EXPECT_NEAR(expected_information_bits(std::vector<double>{0.2, 0.8, 0.2, 0.8}),
              0.2780719051126377, 1e-12);
  EXPECT_EQ(expected_information_bits(std::vector<double>{}), 0.0);
}

}  // namespace
}  // namespace robomill::learning
