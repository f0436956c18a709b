#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "robomill/cutting/cutting_law.hpp"
#include "robomill/cutting/engagement.hpp"

namespace test_cutting_laws_cpp {

namespace {

using namespace robomill::cutting;
constexpr double kPi = std::numbers::pi;

TEST(LinearLaw, ShearPlusEdgeTimesWidth) {  // 000 Eq 13, 001 Eq 12
  const LinearLaw law{855e6, 270.93e6, 100e6, 15.64e3, 14.167e3, 2e3};
  const ResolvedLaw resolved(law, 0.0);
  const EdgeForce f = resolved(50e-6, 1e-3);
  EXPECT_NEAR(f.tangential_n, (855e6 * 50e-6 + 15.64e3) * 1e-3, 1e-9);
  EXPECT_NEAR(f.radial_n, (270.93e6 * 50e-6 + 14.167e3) * 1e-3, 1e-9);
  EXPECT_NEAR(f.axial_n, (100e6 * 50e-6 + 2e3) * 1e-3, 1e-9);
}

TEST(CuttingLaws, NoForceWithoutChip) {  // 002 Eq 27
  const CuttingLaw laws[] = {LinearLaw{855e6, 270e6, 0, 15e3, 14e3, 0},
                             ExponentialLaw{800e3, 0.7, 1e-3, 0.3, 0.0},
                             FractionalLaw{5e6, 1.8e-5, 0.1, 0.3, 0.0},
                             SizeDependentLaw{387e6, -0.327, 0.0018, -0.224, 1e-3}};
  for (const CuttingLaw& law : laws) {
    const ResolvedLaw resolved(law, 40e-6);
    for (double chip : {0.0, -1e-6, -1.0}) {
      const EdgeForce f = resolved(chip, 1e-3);
      EXPECT_EQ(f.tangential_n, 0.0) << law_name(law);
      EXPECT_EQ(f.radial_n, 0.0) << law_name(law);
      EXPECT_EQ(f.axial_n, 0.0) << law_name(law);
    }
  }
}

TEST(FractionalLaw, LimitsOfPaper002Eq26) {
  // 002 §3.1: k0 = 5e6 N/m, hs = 1.8e-5 m, r = 0.1, kr = 0.3.
  const FractionalLaw law{5e6, 1.8e-5, 0.1, 0.3, 0.0};
  const ResolvedLaw resolved(law, 0.0);
  const double width = 1e-3;
  // Small chips: slope k0/hs per unit width (finite, unlike the exponential law).
  const double tiny = 1e-10;
  EXPECT_NEAR(resolved(tiny, width).tangential_n / (tiny * width), 5e6 / 1.8e-5,
              1e-3 * 5e6 / 1.8e-5);
  // At h = hs: k0 (1 + r) / 2.
  EXPECT_NEAR(resolved(1.8e-5, width).tangential_n, 5e6 * width * 1.1 / 2.0, 1e-9);
  // Radial force is kr times the tangential one (002 Eq 28).
  const EdgeForce f = resolved(3e-5, width);
  EXPECT_NEAR(f.radial_n, 0.3 * f.tangential_n, 1e-12);
}

TEST(ExponentialLaw, PowerOfChipThickness) {  // 002 Eq 25
  const ExponentialLaw law{800e3, 0.7, 1e-3, 0.4, 0.1};
  const ResolvedLaw resolved(law, 0.0);
  const EdgeForce f = resolved(0.1e-3, 2e-3);
  EXPECT_NEAR(f.tangential_n, 800e3 * std::pow(0.1, 0.7) * 2e-3, 1e-9);
  EXPECT_NEAR(f.radial_n, 0.4 * f.tangential_n, 1e-12);
  EXPECT_NEAR(f.axial_n, 0.1 * f.tangential_n, 1e-12);
}

TEST(SizeDependentLaw, CoefficientsAtTheMeanChipOfPaper004) {
  // 004 §4.1: up milling, R = 12 mm, ae = 4 mm, ft = 0.12 mm; Eq A3 gives
  // tc = ft (ae/R) / acos(1 − ae/R).
  const double radius = 12e-3, ae = 4e-3, feed = 0.12e-3;
  const Engagement engagement = radial_engagement(radius, radius, ae, MillingDirection::up);
  const double expected_tc = feed * (ae / radius) / std::acos(1.0 - ae / radius);
  EXPECT_NEAR(mean_chip_thickness_m(feed, engagement), expected_tc, 1e-15);

  // Eq A2 with tc in mm and kc1 in N/mm² (our reading; the paper gives no units).
  const SizeDependentLaw law{387e6, -0.327, 0.0018, -0.224, 1e-3};
  const ResolvedLaw resolved(law, expected_tc);
  const double tc_mm = expected_tc * 1e3;
  ASSERT_TRUE(resolved.is_linear());
  EXPECT_NEAR(resolved.linear().Ktc_pa, 387e6 * std::pow(tc_mm, -0.327), 1.0);
  const EdgeForce f = resolved(0.05e-3, 1e-3);
  EXPECT_NEAR(f.radial_n, 0.0018 * std::pow(tc_mm, -0.224) * f.tangential_n, 1e-12);
}

TEST(CuttingLaws, ValidationNamesTheCoefficient) {
  try {
    validate(FractionalLaw{5e6, 0.0, 0.1, 0.3, 0.0});
    FAIL() << "hs = 0 accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("hs"), std::string::npos);
  }
  EXPECT_THROW(validate(LinearLaw{-1.0, 0, 0, 0, 0, 0}), std::invalid_argument);
  EXPECT_THROW(validate(LinearLaw{std::nan(""), 0, 0, 0, 0, 0}), std::invalid_argument);
}

TEST(Engagement, AltintasEntryAndExitAngles) {
  const double radius = 5e-3;
  for (double ratio : {0.1, 0.25, 0.5, 0.75, 1.0}) {
    const double ae = ratio * 2.0 * radius;
    const Engagement up = radial_engagement(radius, radius, ae, MillingDirection::up);
    EXPECT_DOUBLE_EQ(up.entry_rad, 0.0);
    EXPECT_NEAR(up.exit_rad, std::acos(1.0 - 2.0 * ratio), 1e-12);
    const Engagement down = radial_engagement(radius, radius, ae, MillingDirection::down);
    EXPECT_NEAR(down.entry_rad, std::acos(2.0 * ratio - 1.0), 1e-12);
    EXPECT_DOUBLE_EQ(down.exit_rad, kPi);
  }
  // A ball-nose point of radius 1 mm cannot reach a 2 mm-deep band of a 10 mm cutter.
  EXPECT_TRUE(radial_engagement(5e-3, 1e-3, 2e-3, MillingDirection::up).empty());
}

}  // namespace

}  // namespace test_cutting_laws_cpp
