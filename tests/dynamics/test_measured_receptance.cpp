// Measured FRFs assembled into the tool-tip receptance matrix.

#include <gtest/gtest.h>

#include <numbers>

#include "robomill/dynamics/measured_receptance.hpp"
#include "robomill/stability/lobes.hpp"

namespace test_measured_receptance_cpp {

namespace {

using namespace robomill::dynamics;

ModalModel two_direction_model() {
  // A coupled mode (shape in x and y) and one along x.
  Mode coupled;
  coupled.natural_frequency_hz = 120.0;
  coupled.damping_ratio = 0.03;
  coupled.shape = {0.02, 0.01, 0.0};
  return ModalModel({coupled, directional_mode(0, 300.0, 0.02, 5e6)});
}

TEST(MeasuredReceptance, EqualsTheModalReceptanceAtMeasuredFrequencies) {
  const ModalModel model = two_direction_model();
  const auto grid = robomill::stability::linear_range(0.0, 600.0, 1201);
  MeasuredReceptance measured({synthesize(model, 0, 0, grid), synthesize(model, 1, 1, grid),
                               synthesize(model, 0, 1, grid, FrfKind::accelerance)});
  EXPECT_DOUBLE_EQ(measured.min_frequency_hz(), 0.5);  // 0 Hz dropped
  for (const double f : {0.5, 100.0, 120.0, 300.5, 600.0}) {
    const double omega = 2.0 * std::numbers::pi * f;
    const Eigen::Matrix3cd expected = model.receptance(omega);
    const Eigen::Matrix3cd h = measured(omega);
    for (int r = 0; r < 2; ++r) {
      for (int s = 0; s < 2; ++s) {
        EXPECT_LT(std::abs(h(r, s) - expected(r, s)), 1e-9 * std::abs(expected(r, s)) + 1e-18)
            << f << " Hz, entry " << r << s;
      }
    }
    // z was never measured: no coupling, no compliance.
    EXPECT_EQ(h(2, 2), std::complex<double>(0.0, 0.0));
    EXPECT_EQ(h(0, 2), std::complex<double>(0.0, 0.0));
  }
  // Reciprocity filled H_yx from H_xy.
  EXPECT_EQ(measured(700.0)(1, 0), measured(700.0)(0, 1));
  // Held at the ends of the range.
  EXPECT_EQ(measured(2.0 * std::numbers::pi * 900.0), measured(2.0 * std::numbers::pi * 600.0));
}

TEST(MeasuredReceptance, RejectsDuplicatesAndDisjointRanges) {
  const ModalModel model = two_direction_model();
  const auto low = robomill::stability::linear_range(1.0, 100.0, 100);
  const auto high = robomill::stability::linear_range(200.0, 300.0, 100);
  EXPECT_THROW(MeasuredReceptance({synthesize(model, 0, 0, low), synthesize(model, 0, 0, low)}),
               std::invalid_argument);
  EXPECT_THROW(MeasuredReceptance({synthesize(model, 0, 0, low), synthesize(model, 1, 1, high)}),
               std::invalid_argument);
  EXPECT_THROW(MeasuredReceptance({}), std::invalid_argument);
  // H_xy and H_yx both measured is fine: each fills its own entry.
  EXPECT_NO_THROW(MeasuredReceptance({synthesize(model, 0, 1, low), synthesize(model, 1, 0, low)}));
}

}  // namespace

}  // namespace test_measured_receptance_cpp
