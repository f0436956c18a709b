// The `uncertainty:` section (docs/uncertainty.md, "From a job"): variables
// resolved against the job's own fields, parameters read in the fields' units
// and converted to SI, the defaults, and every refusal naming its field and
// line.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <variant>
#include <vector>

#include "job/expect_input_error.hpp"
#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"
#include "robomill/job/units.hpp"
#include "robomill/uncertainty/distribution.hpp"

namespace test_uncertainty_section_cpp {

namespace {

using robomill::job::Job;
using robomill::job::Override;
using robomill::job::parse_job;
using robomill::job::UncertaintySettings;
using robomill::test::expect_error;
namespace dims = robomill::job::dimensions;
namespace unc = robomill::uncertainty;

// Five lines, so the uncertainty: section below starts on line 6. The modes'
// values are written with and without units (k: 9.3e6 is N/m, Krc: 290 is
// N/mm^2, the fields' documented units).
const std::string kBase = R"(dynamics:
  modes:
    - {direction: x, fn: 2060 Hz, zeta: 2.4 %, k: 8.1e6 N/m}
    - {direction: y, fn: 2150 Hz, zeta: 0.021, k: 9.3e6}
cutting: {law: linear, Ktc: 855 N/mm^2, Krc: 290}
)";

Job with_section(const std::string& section, const std::vector<Override>& set = {}) {
  return parse_job(kBase + section, "cell/job.yaml", set);
}

void expect_section_error(const std::string& section, const std::string& field, int line,
                          const std::string& fragment) {
  expect_error(kBase + section, field, line, fragment);
}

// Relative to the value: the SI conversions multiply by exact powers of ten
// (in long double) and the % by 0.01, a few ulps at most.
void expect_relative(double actual, double expected) {
  EXPECT_NEAR(actual, expected, std::abs(expected) * 1e-14) << "expected " << expected;
}

TEST(UncertaintySection, ReadsEveryFamilyInTheFieldsUnitsWithTheJobsValuesAsDefaults) {
  const Job job = with_section(R"(uncertainty:
  variables:
    - name: k_tip
      path: ["dynamics.modes[0].k", dynamics.modes.1.k]
      mode: scale
      distribution: lognormal
      sigma: 0.2
    - name: zeta_x
      path: dynamics.modes[0].zeta
      distribution: normal
      sd: 10 %
    - name: ktc
      path: cutting.Ktc
      distribution: truncated_normal
      mean: 870
      sd: 90 N/mm^2
      min: 0
    - name: krc
      path: cutting.Krc
      distribution: uniform
      min: 250
      max: 0.33 GPa
)");
  ASSERT_TRUE(job.uncertainty.has_value());
  const UncertaintySettings& u = *job.uncertainty;
  EXPECT_EQ(u.samples, 1000);
  EXPECT_EQ(u.seed, 1u);
  EXPECT_EQ(u.sampling, unc::DrawSettings::Sampling::sobol);
  EXPECT_FALSE(u.correlation.has_value());
  EXPECT_TRUE(u.posterior.empty());
  EXPECT_EQ(u.line, 6);
  ASSERT_EQ(u.variables.size(), 4u);

  // A scale variable on two paths: both resolved to the bracket form, each
  // with its own nominal value (written with and without the unit).
  const auto& k = u.variables[0];
  EXPECT_EQ(k.name, "k_tip");
  EXPECT_EQ(k.line, 8);
  EXPECT_EQ(k.mode, UncertaintySettings::Mode::scale);
  ASSERT_EQ(k.targets.size(), 2u);
  EXPECT_EQ(k.targets[0].path, "dynamics.modes[0].k");
  EXPECT_EQ(k.targets[1].path, "dynamics.modes[1].k");
  EXPECT_EQ(k.targets[0].nominal_si, 8.1e6);
  EXPECT_EQ(k.targets[1].nominal_si, 9.3e6);
  EXPECT_EQ(k.targets[1].dimension, dims::stiffness);
  EXPECT_EQ(k.targets[1].line, 9);
  const auto* lognormal = std::get_if<unc::Lognormal>(&*k.distribution);
  ASSERT_NE(lognormal, nullptr);
  EXPECT_EQ(lognormal->median, 1.0);  // a factor's default
  EXPECT_EQ(lognormal->sigma, 0.2);

  // Value mode: the mean defaults to the job's 2.4 %, "10 %" is of the mean.
  const auto& zeta = u.variables[1];
  EXPECT_EQ(zeta.mode, UncertaintySettings::Mode::value);
  EXPECT_EQ(zeta.targets[0].dimension, dims::none);
  const auto* normal = std::get_if<unc::Normal>(&*zeta.distribution);
  ASSERT_NE(normal, nullptr);
  expect_relative(normal->mean, 0.024);
  expect_relative(normal->sd, 0.0024);

  // Bare numbers in the field's unit (N/mm^2), units converted, one bound.
  const auto* truncated = std::get_if<unc::TruncatedNormal>(&*u.variables[2].distribution);
  ASSERT_NE(truncated, nullptr);
  expect_relative(truncated->mean, 8.7e8);
  expect_relative(truncated->sd, 9e7);
  EXPECT_EQ(truncated->min, 0.0);
  EXPECT_EQ(truncated->max, std::numeric_limits<double>::infinity());
  EXPECT_EQ(u.variables[2].targets[0].dimension, dims::pressure);
  expect_relative(u.variables[2].targets[0].nominal_si, 8.55e8);

  const auto* uniform = std::get_if<unc::Uniform>(&*u.variables[3].distribution);
  ASSERT_NE(uniform, nullptr);
  expect_relative(uniform->min, 2.5e8);
  expect_relative(uniform->max, 3.3e8);
  expect_relative(u.variables[3].targets[0].nominal_si, 2.9e8);
}

TEST(UncertaintySection, SettingsCorrelationByNamesAndWhatRebuildsTheJob) {
  const std::vector<Override> set = {{"dynamics.modes[0].k", "7.25e6 N/m"}};
  const std::string section = R"(uncertainty:
  samples: 4096
  seed: 17
  sampling: random
  variables:
    - {name: kx, path: dynamics.modes.0.k, distribution: lognormal, sigma: 0.1}
    - {name: ky, path: dynamics.modes.1.k, distribution: lognormal, sigma: 0.1}
    - {name: zx, path: dynamics.modes.0.zeta, distribution: lognormal, sigma: 0.3}
  correlation:
    ky: {kx: 0.6}
    zx: {kx: -0.25}
)";
  const Job job = with_section(section, set);
  const UncertaintySettings& u = *job.uncertainty;
  EXPECT_EQ(u.samples, 4096);
  EXPECT_EQ(u.seed, 17u);
  EXPECT_EQ(u.sampling, unc::DrawSettings::Sampling::random);
  // The nominal is the job's value after --set.
  EXPECT_EQ(u.variables[0].targets[0].nominal_si, 7.25e6);
  EXPECT_EQ(std::get<unc::Lognormal>(*u.variables[0].distribution).median, 7.25e6);
  ASSERT_TRUE(u.correlation.has_value());
  Eigen::MatrixXd expected = Eigen::MatrixXd::Identity(3, 3);
  expected(0, 1) = expected(1, 0) = 0.6;
  expected(0, 2) = expected(2, 0) = -0.25;
  EXPECT_TRUE(*u.correlation == expected) << *u.correlation;
  EXPECT_EQ(u.correlation_line, 14);
  // The text and the overrides it was read with.
  ASSERT_NE(job.yaml_text, nullptr);
  EXPECT_EQ(*job.yaml_text, kBase + section);
  ASSERT_EQ(job.overrides.size(), 1u);
  EXPECT_EQ(job.overrides[0].value, "7.25e6 N/m");
}

TEST(UncertaintySection, ScaleOnAListFieldSetsEveryEntryAndAPosteriorReplacesDistributions) {
  const std::string robot = R"(robot:
  dh: [{a: 0, alpha: 90, d: 400, theta: 0}, {a: 600, alpha: 0, d: 0, theta: 0}]
  joint_stiffness: [1.2e6, 3.4e6 N*m/rad]
uncertainty:
  posterior: draws/posterior.csv
  variables:
    - {name: kq, path: robot.joint_stiffness, mode: scale}
)";
  const Job job = parse_job(robot, "cell/job.yaml");
  const UncertaintySettings& u = *job.uncertainty;
  ASSERT_EQ(u.variables[0].targets.size(), 2u);
  EXPECT_EQ(u.variables[0].targets[1].path, "robot.joint_stiffness[1]");
  EXPECT_EQ(u.variables[0].targets[1].nominal_si, 3.4e6);
  EXPECT_EQ(u.variables[0].targets[0].dimension, dims::rotational_stiffness);
  EXPECT_FALSE(u.variables[0].distribution.has_value());
  EXPECT_EQ(u.posterior, std::filesystem::path("cell/draws/posterior.csv"));
  EXPECT_EQ(u.posterior_line, 5);
  // In value mode a list is no number.
  expect_error(robot.substr(0, robot.find("  posterior")) +
                   "  variables:\n    - {name: kq, path: robot.joint_stiffness, "
                   "distribution: uniform, min: 1e6, max: 2e6}\n",
               "uncertainty.variables[0].path", 6, "give one entry (robot.joint_stiffness[0])");
}

TEST(UncertaintySection, EmptyOrNullSectionIsTheNominalJob) {
  EXPECT_FALSE(with_section("uncertainty:\n").uncertainty.has_value());
  const Job job = with_section(
      "uncertainty:\n  variables: [{name: a, path: cutting.Ktc, distribution: lognormal, "
      "sigma: 0.1}]\n",
      {{"uncertainty", "null"}});
  EXPECT_FALSE(job.uncertainty.has_value());
}

TEST(UncertaintySection, PathsThatAreNoNumberFieldOfTheJobAreRefused) {
  const auto variable = [](const std::string& path) {
    return "uncertainty:\n  variables:\n    - name: v\n      path: " + path +
           "\n      mode: scale\n      distribution: lognormal\n      sigma: 0.1\n";
  };
  const std::string field = "uncertainty.variables[0].path";
  expect_section_error(variable("dynamics.modes[0].kk"), field, 9,
                       "the job has no dynamics.modes[0].kk");
  expect_section_error(variable("dynamics.modes[2].k"), field, 9,
                       "index 2 is out of range: dynamics.modes has 2 entries");
  expect_section_error(variable("tool.diameter"), field, 9, "the job has no tool");
  expect_section_error(variable("dynamics.modes[-1].k"), field, 9, "count from 0, got -1");
  expect_section_error(variable("cutting.law"), field, 9, "cutting.law is a word (linear");
  expect_section_error(variable("dynamics.modes[0]"), field, 9, "is a map, not a number");
  expect_section_error(variable("dynamics.modes[0].direction"), field, 9,
                       "holds 'x', not a number");
  expect_section_error(variable("uncertainty.samples"), field, 9,
                       "cannot set the uncertainty: section");
  // One path of a list: the item is named.
  expect_section_error(variable("[cutting.Ktc, cutting.Kte]"), field + "[1]", 9,
                       "the job has no cutting.Kte");
  // A field set by two variables.
  expect_section_error(R"(uncertainty:
  variables:
    - {name: a, path: cutting.Ktc, distribution: lognormal, sigma: 0.1}
    - {name: b, path: [cutting.Krc, cutting.Ktc], mode: scale, distribution: lognormal, sigma: 0.1}
)",
                       "uncertainty.variables[1].path", 9,
                       "cutting.Ktc is already set by variable 'a' (line 8)");
}

TEST(UncertaintySection, DistributionsAndTheirParametersAreChecked) {
  const auto variable = [](const std::string& rest) {
    return "uncertainty:\n  variables:\n    - name: kx\n      path: dynamics.modes[0].k\n" + rest;
  };
  const std::string v = "uncertainty.variables[0]";
  expect_section_error(variable("      distribution: gamma\n"), v + ".distribution", 10,
                       "expected one of: normal, lognormal, uniform, truncated_normal");
  expect_section_error(variable(""), v + ".distribution", 8, "required: normal, lognormal");
  expect_section_error(variable("      distribution: normal\n"), v + ".sd", 8,
                       "required for normal");
  expect_section_error(variable("      distribution: lognormal\n      sd: 1e5\n"), v + ".sd", 11,
                       "is not a parameter of lognormal, which takes median, sigma");
  expect_section_error(variable("      distribution: uniform\n      min: 9e6\n      max: 8e6\n"),
                       v + ".distribution", 10, "min must be below max");
  expect_section_error(variable("      distribution: normal\n      sd: 0.3 mm\n"), v + ".sd", 11,
                       "expected a force per length");
  expect_section_error(variable("      distribution: normal\n      sd: -2e5\n"), v + ".sd", 11,
                       "must be positive");
  expect_section_error(variable("      distribution: truncated_normal\n      sd: 1e6\n"),
                       v + ".min", 8, "needs min, max or both");
  expect_section_error(variable("      mode: scale\n      distribution: uniform\n      min: 0.9\n"
                                "      max: 1.1 N/m\n"),
                       v + ".max", 13, "expected a dimensionless number");
  expect_section_error(variable("      mode: both\n      distribution: lognormal\n"), v + ".mode",
                       10, "expected one of: value, scale");
  expect_section_error(variable("      distribution: lognormal\n      sigma: 0.1\n      sd: 2\n"),
                       v + ".sd", 12, "is not a parameter of lognormal");
  expect_section_error(
      variable("      distribution: lognormal\n      sigma: 0.1\n      spread: 2\n"), v + ".spread",
      12, "unknown key");
  // Two fields with different values: no common default mean.
  expect_section_error(R"(uncertainty:
  variables:
    - name: k
      path: ["dynamics.modes[0].k", "dynamics.modes[1].k"]
      distribution: normal
      sd: 1e5
)",
                       v + ".mean", 8, "dynamics.modes[0].k is 8.1e+06 N/m but");
}

TEST(UncertaintySection, NamesSamplesAndCorrelationsAreChecked) {
  const std::string two = R"(uncertainty:
  variables:
    - {name: kx, path: dynamics.modes.0.k, distribution: lognormal, sigma: 0.1}
    - {name: ky, path: dynamics.modes.1.k, distribution: lognormal, sigma: 0.1}
)";
  expect_section_error(R"(uncertainty:
  variables:
    - {name: k, path: dynamics.modes.0.k, distribution: lognormal, sigma: 0.1}
    - {name: k, path: dynamics.modes.1.k, distribution: lognormal, sigma: 0.1}
)",
                       "uncertainty.variables[1].name", 9,
                       "'k' is already the name of uncertainty.variables[0] (line 8)");
  expect_section_error(R"(uncertainty:
  variables:
    - {name: 2k, path: dynamics.modes.0.k, distribution: lognormal, sigma: 0.1}
)",
                       "uncertainty.variables[0].name", 8, "'2k' is not a name");
  expect_section_error("uncertainty:\n  samples: 0\n" + two.substr(13), "uncertainty.samples", 7,
                       "must be a positive integer");
  expect_section_error("uncertainty:\n  samples: 10\n", "uncertainty.variables", 6,
                       "at least one variable");
  expect_section_error(two + "  correlation: {kx: {kz: 0.5}}\n", "uncertainty.correlation.kx.kz",
                       10, "'kz' is not a variable; the variables are kx, ky");
  expect_section_error(two + "  correlation: {kx: {kx: 0.5}}\n", "uncertainty.correlation.kx.kx",
                       10, "correlation with itself is 1");
  expect_section_error(two + "  correlation: {kx: {ky: 1.2}}\n", "uncertainty.correlation.kx.ky",
                       10, "must be in the range");
  expect_section_error(two + "  correlation:\n    kx: {ky: 0.5}\n    ky: {kx: 0.5}\n",
                       "uncertainty.correlation.ky.kx", 12, "given twice (also on line 11)");
  // Pairwise plausible, jointly impossible: 0.9, 0.8 and 0.1 have determinant −0.316.
  expect_section_error(
      two + R"(    - {name: zx, path: dynamics.modes.0.zeta, distribution: lognormal, sigma: 0.1}
  correlation:
    kx: {ky: 0.9, zx: 0.8}
    ky: {zx: 0.1}
)",
      "uncertainty.correlation", 11, "not positive definite");
}

}  // namespace

}  // namespace test_uncertainty_section_cpp
