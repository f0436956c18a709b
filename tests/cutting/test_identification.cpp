// Coefficient identification from mean forces (000 §6.2, 001 §3.2).

#include <gtest/gtest.h>

#include <numbers>

#include "robomill/core/error.hpp"
#include "robomill/cutting/coefficient_identification.hpp"
#include "robomill/cutting/milling_forces.hpp"

namespace test_identification_cpp {

namespace {

using namespace robomill;
constexpr double kPi = std::numbers::pi;

// 001 Table 1 coefficients, SI.
const cutting::LinearLaw kTruth{1661.8e6, 1240.8e6, 19.1e6, 7.1e3, 15.9e3, 2.3e3};

std::vector<cutting::MeanForceMeasurement> synthesize(double ae,
                                                      cutting::MillingDirection direction) {
  // The paper's procedure: slot (or partial) milling at fz = 0.02 … 0.10 mm;
  // "measured" mean forces come from the time-domain force model, not from
  // the closed form the identification inverts.
  tool::ToolSpec spec;
  spec.diameter_m = 8e-3;
  spec.teeth = 2;
  spec.helix_rad = 30.0 * kPi / 180.0;
  spec.overhang_m = 25e-3;
  const tool::Tool cutter(spec);
  std::vector<cutting::MeanForceMeasurement> tests;
  for (double fz_mm : {0.02, 0.04, 0.06, 0.08, 0.10}) {
    const cutting::MillingProcess process{5000.0 * 2.0 * kPi / 60.0, fz_mm * 1e-3, 1e-3, ae,
                                          direction};
    const cutting::MillingForceModel model(cutter, kTruth, process, 100);
    const auto stats = cutting::summarize(cutting::sample_forces(model, {1, 2000}, 2), 1.0);
    tests.push_back({process.feed_per_tooth_m, stats.mean_n, 2, 1e-3, model.nominal_engagement()});
  }
  return tests;
}

void expect_recovered(const cutting::LinearLaw& found, const char* label) {
  // Judged point: the six coefficients within 1 %.
  EXPECT_NEAR(found.Ktc_pa, kTruth.Ktc_pa, 0.01 * kTruth.Ktc_pa) << label;
  EXPECT_NEAR(found.Krc_pa, kTruth.Krc_pa, 0.01 * kTruth.Krc_pa) << label;
  EXPECT_NEAR(found.Kac_pa, kTruth.Kac_pa, 0.01 * kTruth.Kac_pa) << label;
  EXPECT_NEAR(found.Kte_n_per_m, kTruth.Kte_n_per_m, 0.01 * kTruth.Kte_n_per_m) << label;
  EXPECT_NEAR(found.Kre_n_per_m, kTruth.Kre_n_per_m, 0.01 * kTruth.Kre_n_per_m) << label;
  EXPECT_NEAR(found.Kae_n_per_m, kTruth.Kae_n_per_m, 0.01 * kTruth.Kae_n_per_m) << label;
}

TEST(CoefficientIdentification, RecoversCoefficientsFromSlotTests) {
  const auto tests = synthesize(8e-3, cutting::MillingDirection::down);
  const auto fit = cutting::identify_linear_coefficients(tests);
  expect_recovered(fit.coefficients, "slot");
  EXPECT_GT(fit.r_squared, 0.9999);
  ASSERT_EQ(fit.fitted_n.size(), tests.size());
}

TEST(CoefficientIdentification, RecoversCoefficientsFromHalfImmersionUpMilling) {
  const auto fit =
      cutting::identify_linear_coefficients(synthesize(4e-3, cutting::MillingDirection::up));
  expect_recovered(fit.coefficients, "half immersion, up milling");
}

TEST(CoefficientIdentification, ReportsTheResidualOfNoisyData) {
  auto tests = synthesize(8e-3, cutting::MillingDirection::down);
  // ±2 N of alternating "measurement noise" must show in the residual.
  for (std::size_t i = 0; i < tests.size(); ++i) {
    tests[i].mean_force_n += Eigen::Vector3d::Constant(i % 2 ? 2.0 : -2.0);
  }
  const auto fit = cutting::identify_linear_coefficients(tests);
  EXPECT_GT(fit.rms_residual_n, 0.5);
  EXPECT_GT(fit.standard_error[0], 0.0);
}

TEST(CoefficientIdentification, RefusesASingleFeed) {
  auto tests = synthesize(8e-3, cutting::MillingDirection::down);
  for (auto& test : tests)
    test.feed_per_tooth_m = 0.05e-3;
  EXPECT_THROW(cutting::identify_linear_coefficients(tests), InputError);
  EXPECT_THROW(cutting::identify_linear_coefficients({}), InputError);
}

}  // namespace

}  // namespace test_identification_cpp
