// The `stability:` section: a complete section reaches SI values, omitted
// fields take their documented defaults, and every malformed section is an
// InputError naming the field path and its line.

#include <gtest/gtest.h>

#include <numbers>
#include <string>

#include "job/expect_input_error.hpp"
#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"

namespace test_stability_section_cpp {

namespace {

using robomill::InputError;
using robomill::job::Job;
using robomill::job::parse_job;
using robomill::job::StabilitySettings;

constexpr double kPi = std::numbers::pi;
constexpr double kRpm = 2 * kPi / 60;

// Tool (overhang 50 mm) and one 922 Hz mode, lines 1-6; the stability
// section starts on line 7.
constexpr const char* kBase = R"(tool:
  diameter: 10 mm
  teeth: 2
  overhang: 50 mm
dynamics:
  modes: [{direction: x, fn: 922 Hz, zeta: 0.011, m: 0.03993 kg}]
)";

std::string with_stability(const std::string& section) {
  return std::string(kBase) + "stability:\n" + section;
}

// A minimal valid section body (lines 8-9).
constexpr const char* kMinimal =
    "  speeds: {from: 5000 rpm, to: 25000 rpm, count: 200}\n  depth_max: 10 mm\n";

using robomill::test::expect_error;
using robomill::test::parse_error;

TEST(StabilitySection, CompleteSectionReachesSIValues) {
  const Job job = parse_job(with_stability(R"(  method: sdm
  mode: map
  modes: both
  speeds: {from: 5000 rpm, to: 25000, count: 200}
  depth_max: 10 mm
  depths: 150
  depth_tolerance: 0.1 %
  discretization: 60
  process_damping:
    model: energy_balance
    Ksp: 1.5e14 N/m^3
    wear_land: 40 um
    mu: 0.25
)"),
                            "job.yaml");
  ASSERT_TRUE(job.stability.has_value());
  const StabilitySettings& s = *job.stability;
  EXPECT_EQ(s.method, StabilitySettings::Method::sdm);
  EXPECT_EQ(s.mode, StabilitySettings::Mode::map);
  EXPECT_EQ(s.modes, StabilitySettings::Modes::both);
  EXPECT_NEAR(s.speed_from_rad_s, 5000 * kRpm, 1e-9);
  EXPECT_NEAR(s.speed_to_rad_s, 25000 * kRpm, 1e-9);  // bare number: rpm
  EXPECT_EQ(s.speed_count, 200);
  EXPECT_NEAR(s.depth_max_m, 0.010, 1e-15);
  EXPECT_EQ(s.depth_count, 150);
  EXPECT_NEAR(s.depth_tolerance, 1e-3, 1e-15);  // 0.1 % as a ratio
  EXPECT_EQ(s.discretization, 60);
  EXPECT_EQ(s.process_damping, StabilitySettings::Damping::energy_balance);
  EXPECT_NEAR(s.indentation_n_per_m3, 1.5e14, 1.0);
  EXPECT_NEAR(s.wear_land_m, 40e-6, 1e-18);
  EXPECT_DOUBLE_EQ(s.friction, 0.25);
}

TEST(StabilitySection, OtherUnitsAndChoices) {
  const Job job = parse_job(with_stability(R"(  method: fdm2
  modes: envelope
  speeds: {from: 100 rev/s, to: 2000 rad/s, count: 2}
  depth_max: 0.004 m
  process_damping: {model: linear_equivalent, Ksp: 1.5e5 N/mm^3, wear_land: 0.04 mm}
)"),
                            "");
  const StabilitySettings& s = *job.stability;
  EXPECT_EQ(s.method, StabilitySettings::Method::fdm2);
  EXPECT_EQ(s.modes, StabilitySettings::Modes::envelope);
  EXPECT_NEAR(s.speed_from_rad_s, 200 * kPi, 1e-9);
  EXPECT_DOUBLE_EQ(s.speed_to_rad_s, 2000.0);
  EXPECT_NEAR(s.depth_max_m, 0.004, 1e-15);
  EXPECT_EQ(s.process_damping, StabilitySettings::Damping::linear_equivalent);
  EXPECT_NEAR(s.indentation_n_per_m3, 1.5e14, 1.0);
  EXPECT_NEAR(s.wear_land_m, 40e-6, 1e-18);
  EXPECT_DOUBLE_EQ(s.friction, 0.3);  // default mu
}

TEST(StabilitySection, DefaultsApplyWhenFieldsAreOmitted) {
  const Job job = parse_job(with_stability(kMinimal), "");
  ASSERT_TRUE(job.stability.has_value());
  const StabilitySettings& s = *job.stability;
  EXPECT_EQ(s.method, StabilitySettings::Method::fdm);
  EXPECT_EQ(s.mode, StabilitySettings::Mode::boundary);
  EXPECT_EQ(s.modes, StabilitySettings::Modes::coupled);
  EXPECT_EQ(s.depth_count, 100);
  EXPECT_DOUBLE_EQ(s.depth_tolerance, 1e-3);
  EXPECT_EQ(s.discretization, 40);
  EXPECT_EQ(s.process_damping, StabilitySettings::Damping::none);
  EXPECT_EQ(s.indentation_n_per_m3, 0.0);
  EXPECT_EQ(s.wear_land_m, 0.0);
  EXPECT_EQ(s.friction, 0.0);

  EXPECT_FALSE(parse_job(kBase, "").stability.has_value());
}

TEST(StabilitySection, SingleSpeedMayOmitTo) {
  const Job job =
      parse_job(with_stability("  speeds: {from: 8000, count: 1}\n  depth_max: 5\n"), "");
  EXPECT_NEAR(job.stability->speed_from_rad_s, 8000 * kRpm, 1e-9);
  EXPECT_EQ(job.stability->speed_to_rad_s, job.stability->speed_from_rad_s);
  EXPECT_EQ(job.stability->speed_count, 1);
  const Job same =
      parse_job(with_stability("  speeds: {from: 8000, to: 8000, count: 1}\n  depth_max: 5\n"), "");
  EXPECT_EQ(same.stability->speed_count, 1);
  expect_error(with_stability("  speeds: {from: 8000, to: 9000, count: 1}\n  depth_max: 5\n"),
               "stability.speeds.to", 8, "with count 1 there is a single speed");
}

TEST(StabilitySection, RequireNamesAMissingStabilitySection) {
  const Job job = parse_job(kBase, "");
  try {
    robomill::job::require(job, {robomill::job::Section::stability});
    ADD_FAILURE() << "missing stability section accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), "stability");
  }
  EXPECT_NO_THROW(
      robomill::job::require(parse_job(with_stability(kMinimal), ""),
                             {robomill::job::Section::modes, robomill::job::Section::stability}));
}

// --- errors ----------------------------------------------------------------

TEST(StabilitySection, UnknownMethodModeAndKey) {
  expect_error(with_stability(std::string("  method: nyquist\n") + kMinimal), "stability.method", 8,
               "expected one of: zoa, sdm, fdm, fdm2; got 'nyquist'");
  expect_error(with_stability(std::string("  mode: contour\n") + kMinimal), "stability.mode", 8,
               "expected one of: boundary, map");
  expect_error(with_stability(std::string("  modes: all\n") + kMinimal), "stability.modes", 8,
               "expected one of: coupled, envelope, both");
  expect_error(with_stability(std::string(kMinimal) + "  depht_max: 3\n"), "stability.depht_max",
               10, "unknown key; expected one of: method, mode, modes, speeds, depth_max");
  expect_error(with_stability(std::string(kMinimal) + "  deformation: true\n  method: zoa\n"),
               "stability.deformation", 10, "needs a time-domain method");
  expect_error(with_stability("  speeds: {from: 5000, to: 6000, count: 10, step: 5}\n"
                              "  depth_max: 5\n"),
               "stability.speeds.step", 8, "expected one of: from, to, count");
}

TEST(StabilitySection, SpeedRange) {
  expect_error(with_stability("  speeds: {from: 9000, to: 9000, count: 10}\n  depth_max: 5\n"),
               "stability.speeds.to", 8, "must be greater than from (9000 rpm), got 9000 rpm");
  expect_error(with_stability("  speeds: {from: 9000, to: 5000 rpm, count: 10}\n  depth_max: 5\n"),
               "stability.speeds.to", 8, "must be greater than from");
  expect_error(with_stability("  speeds: {from: 5000, to: 9000, count: 0}\n  depth_max: 5\n"),
               "stability.speeds.count", 8, "must be a positive integer, got 0");
  expect_error(with_stability("  speeds: {from: 5000, to: 9000, count: 100001}\n  depth_max: 5\n"),
               "stability.speeds.count", 8, "from 1 to 100000");
  expect_error(with_stability("  speeds: {from: 0, to: 9000, count: 10}\n  depth_max: 5\n"),
               "stability.speeds.from", 8, "must be positive, got 0 rpm");
  expect_error(with_stability("  speeds: {from: 5000, count: 10}\n  depth_max: 5\n"),
               "stability.speeds.to", 8, "required field missing");
  expect_error(with_stability("  speeds: {from: 5000 Hz, to: 9000, count: 10}\n  depth_max: 5\n"),
               "stability.speeds.from", 8, "expected an angular speed");
  expect_error(with_stability("  depth_max: 5\n"), "stability.speeds", 7, "required field missing");
  expect_error(with_stability("  speeds: [5000, 9000, 10]\n  depth_max: 5\n"), "stability.speeds",
               8, "expected a section");
}

TEST(StabilitySection, DepthRangeAndTolerance) {
  const std::string speeds = "  speeds: {from: 5000, to: 25000, count: 200}\n";  // line 8
  expect_error(with_stability(speeds + "  depth_max: -2 mm\n"), "stability.depth_max", 9,
               "must be positive, got -2 mm");
  expect_error(with_stability(speeds), "stability.depth_max", 7, "required field missing");
  expect_error(with_stability(speeds + "  depth_max: 60 mm\n"), "stability.depth_max", 9,
               "depth search limit 60 mm exceeds the tool overhang 50 mm");
  expect_error(with_stability(speeds + "  depth_max: 5\n  depth_tolerance: 0\n"),
               "stability.depth_tolerance", 10, "0 < depth_tolerance <= 0.1, got 0");
  expect_error(with_stability(speeds + "  depth_max: 5\n  depth_tolerance: 20 %\n"),
               "stability.depth_tolerance", 10, "depth_tolerance <= 0.1, got 20 %");
  expect_error(with_stability(speeds + "  depth_max: 5\n  depths: 1\n"), "stability.depths", 10,
               "from 2 to 100000");
}

TEST(StabilitySection, DiscretizationLimits) {
  expect_error(with_stability(std::string(kMinimal) + "  discretization: 3\n"),
               "stability.discretization", 10, "from 4 to 10000");
  expect_error(with_stability(std::string(kMinimal) + "  discretization: 10001\n"),
               "stability.discretization", 10, "from 4 to 10000");
}

TEST(StabilitySection, DiscretizationTooCoarseForTheHighestMode) {
  // 4850 Hz at 1000 rpm with 2 teeth: τ = 30 ms, m >= 2 · 4850 · 0.03 = 291.
  const std::string job = R"(tool: {diameter: 12, teeth: 2, overhang: 50}
dynamics:
  modes:
    - {direction: x, fn: 19.88 Hz, zeta: 0.0081, k: 3.65e6}
    - {direction: x, fn: 4850 Hz, zeta: 0.0315, k: 4.46e6}
stability:
  method: sdm
  speeds: {from: 1000 rpm, to: 6000 rpm, count: 200}
  depth_max: 5 mm
)";
  expect_error(job + "  discretization: 40\n", "stability.discretization", 10,
               "too coarse for the 4850 Hz mode at 1000 rpm with 2 teeth");
  expect_error(job + "  discretization: 290\n", "stability.discretization", 10,
               "discretization of at least 291");
  // Absent: the default 40 is too coarse; the error points at the section.
  expect_error(job, "stability.discretization", 6, "at least 291");
  EXPECT_EQ(parse_job(job + "  discretization: 291\n", "").stability->discretization, 291);
  // ZOA has no time step: no check.
  const std::string zoa = R"(tool: {diameter: 12, teeth: 2, overhang: 50}
dynamics:
  modes: [{direction: x, fn: 4850 Hz, zeta: 0.0315, k: 4.46e6}]
stability: {method: zoa, speeds: {from: 1000, to: 6000, count: 200}, depth_max: 5}
)";
  EXPECT_EQ(parse_job(zoa, "").stability->method, StabilitySettings::Method::zoa);
  // Beyond what the limit allows: says so.
  const std::string slow = R"(tool: {diameter: 12, teeth: 2, overhang: 50}
dynamics:
  modes: [{direction: x, fn: 4850 Hz, zeta: 0.0315, k: 4.46e6}]
stability: {method: fdm, speeds: {from: 10, to: 6000, count: 200}, depth_max: 5}
)";
  expect_error(slow, "stability.discretization", 4, "beyond the limit of 10000");
  // Without a tool the tooth period is unknown: no check.
  const std::string no_tool = R"(dynamics:
  modes: [{direction: x, fn: 4850 Hz, zeta: 0.0315, k: 4.46e6}]
stability: {method: fdm, speeds: {from: 1000, to: 6000, count: 200}, depth_max: 5}
)";
  EXPECT_TRUE(parse_job(no_tool, "").stability.has_value());
}

TEST(StabilitySection, ProcessDamping) {
  const std::string base = std::string(kMinimal) + "  process_damping:\n";  // line 10
  expect_error(with_stability(base + "    model: energy_balance\n    wear_land: 40 um\n"),
               "stability.process_damping.Ksp", 10, "required field missing");
  expect_error(with_stability(base + "    model: energy_balance\n    Ksp: 1.5e14\n"),
               "stability.process_damping.wear_land", 10, "required field missing");
  expect_error(with_stability(base + "    Ksp: 1.5e14\n    wear_land: 40\n"),
               "stability.process_damping.model", 10,
               "expected one of: linear_equivalent, energy_balance");
  expect_error(with_stability(base + "    model: viscous\n"), "stability.process_damping.model", 11,
               "got 'viscous'");
  expect_error(with_stability(
                   base + "    model: energy_balance\n    Ksp: 1.5e14 N/m^2\n    wear_land: 40\n"),
               "stability.process_damping.Ksp", 12, "expected a force per volume");
  expect_error(
      with_stability(base + "    model: energy_balance\n    Ksp: 1.5e14\n    wear_land: 0\n"),
      "stability.process_damping.wear_land", 13, "must be positive, got 0 um");
  expect_error(with_stability(base + "    model: energy_balance\n    Ksp: 1.5e14\n"
                                     "    wear_land: 40\n    mu: -0.1\n"),
               "stability.process_damping.mu", 14, "must not be negative");
  expect_error(with_stability(base + "    model: energy_balance\n    Kd: 3\n"),
               "stability.process_damping.Kd", 12, "expected one of: model, Ksp, wear_land, mu");
}

TEST(StabilitySection, NeedsDynamicsModes) {
  const std::string job = std::string("tool: {diameter: 10, teeth: 2}\nstability:\n") + kMinimal;
  expect_error(job, "stability", 2, "the stability command needs dynamics.modes");
  expect_error("stability: {speeds: {from: 5000, to: 6000, count: 2}, depth_max: 5}\n", "stability",
               1, "needs dynamics.modes");
}

TEST(StabilitySection, OverridesReachTheSection) {
  const Job job = parse_job(with_stability(kMinimal), "job.yaml",
                            {{"stability.method", "zoa"}, {"stability.speeds.count", "20"}});
  EXPECT_EQ(job.stability->method, StabilitySettings::Method::zoa);
  EXPECT_EQ(job.stability->speed_count, 20);
  try {
    parse_job(with_stability(kMinimal), "job.yaml", {{"stability.depth_max", "80 mm"}});
    ADD_FAILURE() << "depth_max beyond the overhang accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), "stability.depth_max");
    EXPECT_EQ(error.line(), 0);
    EXPECT_NE(std::string(error.what()).find("(from --set)"), std::string::npos) << error.what();
  }
}

}  // namespace

}  // namespace test_stability_section_cpp
