// Mode shapes along the tool (000 Table 2, Eq 35).

#include <gtest/gtest.h>

#include <cmath>

#include "robomill/dynamics/axial_shape.hpp"

namespace test_axial_shape_cpp {

namespace {

using robomill::dynamics::AxialShape;

// 000 Table 2, mode x: 3.232, 2.264, 1.738, 1.075 1/√kg at 3, 12, 24, 36 mm.
const AxialShape table2_x({3e-3, 12e-3, 24e-3, 36e-3}, {3.232, 2.264, 1.738, 1.075});

TEST(AxialShape, ExactAtTheMeasuredPoints) {
  EXPECT_DOUBLE_EQ(table2_x.at(3e-3), 3.232);
  EXPECT_DOUBLE_EQ(table2_x.at(12e-3), 2.264);
  EXPECT_DOUBLE_EQ(table2_x.at(24e-3), 1.738);
  EXPECT_DOUBLE_EQ(table2_x.at(36e-3), 1.075);
}

TEST(AxialShape, LinearBetweenAndExtrapolatedOutside) {
  EXPECT_NEAR(table2_x.at(18e-3), 0.5 * (2.264 + 1.738), 1e-12);
  // To the tip from the first two points: 3.232 + (3/9)(3.232 − 2.264).
  EXPECT_NEAR(table2_x.at(0.0), 3.232 + (3.232 - 2.264) / 3.0, 1e-12);
  EXPECT_NEAR(table2_x.at(48e-3), 1.075 - (1.738 - 1.075), 1e-12);
  EXPECT_DOUBLE_EQ(AxialShape({5e-3}, {2.0}).at(40e-3), 2.0);
}

TEST(AxialShape, RejectsUnorderedOrNonFinitePoints) {
  EXPECT_THROW(AxialShape({3e-3, 3e-3}, {1.0, 2.0}), std::invalid_argument);
  EXPECT_THROW(AxialShape({3e-3, 1e-3}, {1.0, 2.0}), std::invalid_argument);
  EXPECT_THROW(AxialShape({-1e-3}, {1.0}), std::invalid_argument);
  EXPECT_THROW(AxialShape({1e-3}, {NAN}), std::invalid_argument);
  EXPECT_THROW(AxialShape({1e-3, 2e-3}, {1.0}), std::invalid_argument);
}

}  // namespace

}  // namespace test_axial_shape_cpp
