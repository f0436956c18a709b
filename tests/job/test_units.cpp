// Unit parsing: the conversions every job relies on, and the inputs it must reject.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "robomill/job/units.hpp"

namespace test_units_cpp {

namespace {

using robomill::job::Dimension;
using robomill::job::parse_quantity;
using robomill::job::parse_unit;
namespace dims = robomill::job::dimensions;

constexpr double kPi = std::numbers::pi;

// Relative comparison: unit factors are exact to a few ulps, not bit-exact.
void expect_quantity(const std::string& text, double si, const Dimension& dimension) {
  SCOPED_TRACE(text);
  const auto quantity = parse_quantity(text);
  EXPECT_NEAR(quantity.value_si, si, std::abs(si) * 1e-12);
  EXPECT_EQ(quantity.dimension, dimension) << robomill::job::describe(quantity.dimension);
}

std::string rejection_message(const std::string& text) {
  try {
    parse_quantity(text);
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  ADD_FAILURE() << "'" << text << "' was accepted";
  return {};
}

TEST(UnitConversion, Lengths) {
  expect_quantity("4 mm", 4e-3, dims::length);
  expect_quantity("4mm", 4e-3, dims::length);
  expect_quantity("2.5 cm", 0.025, dims::length);
  expect_quantity("1.5 m", 1.5, dims::length);
  expect_quantity("12 um", 12e-6, dims::length);
  expect_quantity("12 \u00b5m", 12e-6, dims::length);
  expect_quantity("12 \u03bcm", 12e-6, dims::length);
  expect_quantity("300 nm", 300e-9, dims::length);
  expect_quantity("0.5 in", 0.0127, dims::length);
  expect_quantity("-2 mm", -2e-3, dims::length);
  expect_quantity("+2e-1 m", 0.2, dims::length);
  expect_quantity("  4 mm  ", 4e-3, dims::length);
}

TEST(UnitConversion, SpindleSpeedInRpmAndRadPerSecond) {
  expect_quantity("8200 rpm", 8200 * 2 * kPi / 60, dims::angular_speed);
  EXPECT_NEAR(parse_quantity("8200 rpm").value_si, 858.70, 0.005);
  expect_quantity("858.7 rad/s", 858.7, dims::angular_speed);
  expect_quantity("1 rev/s", 2 * kPi, dims::angular_speed);
  expect_quantity("60 rev/min", 2 * kPi, dims::angular_speed);
}

TEST(UnitConversion, PressuresAndCoefficients) {
  expect_quantity("855 N/mm^2", 8.55e8, dims::pressure);
  expect_quantity("855 MPa", 8.55e8, dims::pressure);
  expect_quantity("600 GPa", 6e11, dims::pressure);
  expect_quantity("3 kPa", 3e3, dims::pressure);
  expect_quantity("12 Pa", 12, dims::pressure);
  expect_quantity("20 N/mm", 2e4, dims::force_per_length);
  expect_quantity("1.2e7 N/m", 1.2e7, dims::stiffness);
  expect_quantity("1.5e14 N/m^3", 1.5e14, dims::force_per_volume);
  expect_quantity("150 N/mm^3", 1.5e11, dims::force_per_volume);
  expect_quantity("2 kN", 2000, dims::force);
}

TEST(UnitConversion, AnglesRatiosAndTeeth) {
  expect_quantity("45 deg", kPi / 4, dims::angle);
  expect_quantity("0.5 rad", 0.5, dims::angle);
  expect_quantity("1 rev", 2 * kPi, dims::angle);
  expect_quantity("2.37 %", 0.0237, dims::none);
  expect_quantity("2.37%", 0.0237, dims::none);
  expect_quantity("0.05 mm/tooth", 5e-5, dims::length);
  expect_quantity("3", 3, dims::none);
}

TEST(UnitConversion, SpeedsFrequenciesAndTimes) {
  expect_quantity("0.6 m/min", 0.01, dims::speed);
  expect_quantity("600 mm/min", 0.01, dims::speed);
  expect_quantity("2060.49 Hz", 2060.49, dims::frequency);
  expect_quantity("2 kHz", 2000, dims::frequency);
  expect_quantity("50 1/s", 50, dims::frequency);
  expect_quantity("50/s", 50, dims::frequency);
  expect_quantity("2 ms", 2e-3, dims::time);
  expect_quantity("3 us", 3e-6, dims::time);
  expect_quantity("1.5 min", 90, dims::time);
  expect_quantity("2 h", 7200, dims::time);
  expect_quantity("250 g", 0.25, dims::mass);
}

TEST(UnitConversion, CompoundUnitsWithEverySeparator) {
  expect_quantity("3 N*m/rad", 3, dims::rotational_stiffness);
  expect_quantity("3 N.m/rad", 3, dims::rotational_stiffness);
  expect_quantity("3 N m/rad", 3, dims::rotational_stiffness);
  expect_quantity("3 N\u00b7m/rad", 3, dims::rotational_stiffness);
  expect_quantity("2 N*m", 2, dims::torque);
  expect_quantity("0.2 kg*m^2", 0.2, Dimension{2, 1, 0, 0});
  expect_quantity("0.2 kg m^2", 0.2, Dimension{2, 1, 0, 0});
  expect_quantity("5 m^-1", 5, Dimension{-1, 0, 0, 0});
  // Everything after '/' is in the denominator: m/s/s = m/s^2.
  expect_quantity("9.81 m/s/s", 9.81, Dimension{1, 0, -2, 0});
  expect_quantity("9.81 m/s^2", 9.81, Dimension{1, 0, -2, 0});
  expect_quantity("855 N/mm\u00b2", 8.55e8, dims::pressure);
}

TEST(UnitConversion, ParseUnitGivesTheFactorOfOneUnit) {
  EXPECT_DOUBLE_EQ(parse_unit("mm").value_si, 1e-3);
  EXPECT_EQ(parse_unit("mm").dimension, dims::length);
  EXPECT_NEAR(parse_unit("N/mm^2").value_si, 1e6, 1e-6);
  EXPECT_EQ(parse_unit("N/mm^2").dimension, dims::pressure);
  EXPECT_NEAR(parse_unit("rpm").value_si, 2 * kPi / 60, 1e-15);
  EXPECT_EQ(parse_unit("1/s").dimension, dims::frequency);
  EXPECT_EQ(parse_unit("").dimension, dims::none);
  EXPECT_DOUBLE_EQ(parse_unit("").value_si, 1.0);
  EXPECT_THROW(parse_unit("furlong"), std::invalid_argument);
}

TEST(UnitConversion, UnitPartQuotesWhatWasWritten) {
  EXPECT_EQ(robomill::job::unit_part("0.05 mm/tooth"), "mm/tooth");
  EXPECT_EQ(robomill::job::unit_part(" 4 "), "");
  EXPECT_EQ(robomill::job::unit_part("8200rpm"), "rpm");
  EXPECT_EQ(robomill::job::unit_part("1e3 N"), "N");
}

TEST(UnitRejection, UnknownUnitsAreNamed) {
  EXPECT_NE(rejection_message("4 mmm").find("unknown unit 'mmm'"), std::string::npos);
  EXPECT_NE(rejection_message("4 furlong").find("known units"), std::string::npos);
  // Case matters: mPa would be a millipascal, which nobody means.
  EXPECT_NE(rejection_message("4 mpa").find("unknown unit 'mpa'"), std::string::npos);
  EXPECT_NE(rejection_message("4 N/mm^2 x").find("unknown unit 'x'"), std::string::npos);
}

TEST(UnitRejection, EmptyAndMissingNumbers) {
  EXPECT_NE(rejection_message("").find("empty"), std::string::npos);
  EXPECT_NE(rejection_message("   ").find("empty"), std::string::npos);
  EXPECT_NE(rejection_message("mm").find("expected a number"), std::string::npos);
  EXPECT_NE(rejection_message("-").find("expected a number"), std::string::npos);
  EXPECT_NE(rejection_message(".").find("expected a number"), std::string::npos);
  EXPECT_NE(rejection_message("abc").find("expected a number"), std::string::npos);
}

TEST(UnitRejection, NonFiniteNumbers) {
  for (const char* text :
       {"nan", "NaN", ".nan", ".NaN", "inf", ".inf", "-.inf", "+.inf", "Infinity", "inf mm"}) {
    EXPECT_NE(rejection_message(text).find("not a finite number"), std::string::npos) << text;
  }
  EXPECT_NE(rejection_message("1e999").find("out of range"), std::string::npos);
  EXPECT_NE(rejection_message("1e300 GPa^3").find("out of range"), std::string::npos);
}

TEST(UnitRejection, MalformedExpressions) {
  for (const char* text : {"4 mm^", "4 mm^x", "4 mm^12", "4 N//mm", "4 N*/mm", "4 N/", "4 N*",
                           "4 *mm", "4 ^2", "4 mm 5", "0x10", "4 e"}) {
    EXPECT_THROW(parse_quantity(text), std::invalid_argument) << text;
  }
}

TEST(UnitDescription, ReadableNames) {
  using robomill::job::describe;
  EXPECT_EQ(describe(dims::length), "length (m)");
  EXPECT_EQ(describe(dims::pressure), "pressure (N/m^2)");
  EXPECT_EQ(describe(dims::angular_speed), "angular speed (rad/s)");
  EXPECT_EQ(describe(dims::frequency), "frequency (Hz)");
  EXPECT_EQ(describe(dims::rotational_stiffness), "rotational stiffness (N*m/rad)");
  EXPECT_EQ(describe(Dimension{2, 1, 0, 0}), "moment of inertia (kg*m^2)");
  EXPECT_EQ(describe(Dimension{2, 0, 1, 0}), "m^2*s");
  EXPECT_EQ(describe(Dimension{1, 0, -2, 0}), "m/s^2");
  EXPECT_EQ(robomill::job::si_unit(Dimension{-1, 0, 0, 0}), "1/m");
  EXPECT_EQ(robomill::job::typical_units(dims::length), "mm, m, um");
  EXPECT_EQ(robomill::job::dimension_name(dims::none), "dimensionless number");
}

}  // namespace

}  // namespace test_units_cpp
