// Job parsing: a complete job reaches SI values, and every malformed job is an
// InputError that names the field path and its line.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <variant>

#include "job/expect_input_error.hpp"
#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"

namespace test_job_parser_cpp {

namespace {

using robomill::InputError;
using robomill::job::Job;
using robomill::job::parse_job;

constexpr double kPi = std::numbers::pi;

// A job using every implemented section; line numbers below refer to it.
constexpr const char* kCompleteJob = R"(name: complete demo
tool:
  type: flat
  diameter: 10 mm
  teeth: 2
  helix: 30 deg
  overhang: 40
  E: 580 GPa
  runout: {offset: 0.01 mm, angle: 15}
cutting:
  law: linear
  Ktc: 855 N/mm^2
  Krc: 285
  Kac: -20 MPa
  Kte: 20 N/mm
  Kre: 15
process:
  spindle: 8200 rpm
  feed_per_tooth: 0.05 mm/tooth
  ap: 2
  ae: 4 mm
  direction: up
forces:
  revolutions: 3
  steps_per_tooth: 120
  axial_elements: 20
dynamics:
  modes:
    - {direction: x, fn: 2060.49 Hz, zeta: 2.37 %, k: 1.2e7 N/m}
    - direction: y
      fn: 1000
      zeta: 0.02
      m: 0.5 kg
experiments:
  - {spindle: 8000, depth: 1.5 mm, chatter: false}
  - {spindle: 10000 rpm, depth: 3, chatter: true}
output:
  dir: results
  formats: [csv, json]
)";

using robomill::test::expect_error;
using robomill::test::parse_error;

constexpr const char* kTool = "tool:\n  diameter: 10\n  teeth: 2\n";  // lines 1-3

TEST(JobConversion, CompleteJobReachesSIValues) {
  const Job job = parse_job(kCompleteJob, "jobs/demo.yaml");
  EXPECT_EQ(job.name, "complete demo");
  EXPECT_EQ(job.source, std::filesystem::path("jobs/demo.yaml"));

  ASSERT_TRUE(job.tool.has_value());
  EXPECT_EQ(job.tool->type, robomill::tool::ToolType::flat);
  EXPECT_NEAR(job.tool->diameter_m, 0.010, 1e-15);
  EXPECT_EQ(job.tool->teeth, 2);
  EXPECT_NEAR(job.tool->helix_rad, kPi / 6, 1e-12);
  EXPECT_NEAR(job.tool->overhang_m, 0.040, 1e-15);
  EXPECT_NEAR(job.tool->youngs_modulus_pa, 580e9, 1e-3);
  EXPECT_NEAR(job.tool->runout.offset_m, 1e-5, 1e-18);
  EXPECT_NEAR(job.tool->runout.angle_rad, 15 * kPi / 180, 1e-12);

  ASSERT_TRUE(job.cutting.has_value());
  const auto* law = std::get_if<robomill::cutting::LinearLaw>(&*job.cutting);
  ASSERT_NE(law, nullptr);
  EXPECT_NEAR(law->Ktc_pa, 8.55e8, 1e-3);
  EXPECT_NEAR(law->Krc_pa, 2.85e8, 1e-3);  // bare number: N/mm^2
  EXPECT_NEAR(law->Kac_pa, -2e7, 1e-6);
  EXPECT_NEAR(law->Kte_n_per_m, 2e4, 1e-9);
  EXPECT_NEAR(law->Kre_n_per_m, 1.5e4, 1e-9);  // bare number: N/mm
  EXPECT_EQ(law->Kae_n_per_m, 0.0);

  ASSERT_TRUE(job.process.has_value());
  EXPECT_NEAR(job.process->spindle_rad_s, 858.70, 0.005);
  EXPECT_NEAR(job.process->feed_per_tooth_m, 5e-5, 1e-18);
  EXPECT_NEAR(job.process->axial_depth_m, 2e-3, 1e-15);
  EXPECT_NEAR(job.process->radial_depth_m, 4e-3, 1e-15);
  EXPECT_EQ(job.process->direction, robomill::cutting::MillingDirection::up);

  EXPECT_EQ(job.forces.revolutions, 3);
  EXPECT_EQ(job.forces.steps_per_tooth, 120);
  EXPECT_EQ(job.forces.axial_elements, 20);

  ASSERT_EQ(job.modes.size(), 2u);
  EXPECT_EQ(job.modes[0].direction, 'x');
  EXPECT_NEAR(job.modes[0].natural_frequency_hz, 2060.49, 1e-9);
  EXPECT_NEAR(job.modes[0].damping_ratio, 0.0237, 1e-15);
  EXPECT_NEAR(job.modes[0].stiffness_n_per_m, 1.2e7, 1e-6);
  const double omega0 = 2 * kPi * 2060.49;
  EXPECT_NEAR(job.modes[0].mass_kg, 1.2e7 / (omega0 * omega0), 1e-12);
  EXPECT_EQ(job.modes[1].direction, 'y');
  EXPECT_NEAR(job.modes[1].mass_kg, 0.5, 1e-15);
  const double omega1 = 2 * kPi * 1000;
  EXPECT_NEAR(job.modes[1].stiffness_n_per_m, 0.5 * omega1 * omega1, 1e-3);

  ASSERT_EQ(job.experiments.size(), 2u);
  EXPECT_NEAR(job.experiments[0].spindle_rad_s, 8000 * 2 * kPi / 60, 1e-9);  // bare: rpm
  EXPECT_NEAR(job.experiments[0].axial_depth_m, 1.5e-3, 1e-15);
  EXPECT_FALSE(job.experiments[0].chatter);
  EXPECT_NEAR(job.experiments[1].axial_depth_m, 3e-3, 1e-15);
  EXPECT_TRUE(job.experiments[1].chatter);

  EXPECT_EQ(job.output.dir, "results");
  EXPECT_TRUE(job.output.csv);
  EXPECT_TRUE(job.output.json);
  EXPECT_FALSE(job.output.html);
}

TEST(JobConversion, DefaultsApplyWhenFieldsAreOmitted) {
  const Job job = parse_job(
      std::string(kTool) + "process: {spindle: 6000, feed_per_tooth: 0.1, ap: 1, ae: 2}\n", "");
  ASSERT_TRUE(job.tool.has_value());
  EXPECT_EQ(job.tool->type, robomill::tool::ToolType::flat);
  EXPECT_EQ(job.tool->helix_rad, 0.0);
  EXPECT_NEAR(job.tool->overhang_m, 0.040, 1e-15);  // 4 × diameter
  EXPECT_EQ(job.tool->youngs_modulus_pa, 600e9);
  EXPECT_EQ(job.tool->runout.offset_m, 0.0);
  EXPECT_FALSE(job.cutting.has_value());
  EXPECT_EQ(job.process->direction, robomill::cutting::MillingDirection::down);
  EXPECT_EQ(job.forces.revolutions, 1);
  EXPECT_EQ(job.forces.steps_per_tooth, 90);
  EXPECT_EQ(job.forces.axial_elements, 0);
  EXPECT_TRUE(job.modes.empty());
  EXPECT_TRUE(job.output.csv && job.output.json && job.output.html);
  EXPECT_TRUE(job.output.dir.empty());
}

TEST(JobConversion, FeedRateIsConvertedWithTeethAndSpindleSpeed) {
  // 600 mm/min at 6000 rpm with 2 teeth: 600 / (2 · 6000) = 0.05 mm per tooth.
  const Job job = parse_job(
      std::string(kTool) + "process: {spindle: 6000 rpm, feed_rate: 600, ap: 1, ae: 2}\n", "");
  EXPECT_NEAR(job.process->feed_per_tooth_m, 5e-5, 1e-15);
  const Job si = parse_job(
      std::string(kTool) + "process: {spindle: 6000 rpm, feed_rate: 0.6 m/min, ap: 1, ae: 2}\n",
      "");
  EXPECT_NEAR(si.process->feed_per_tooth_m, 5e-5, 1e-15);
}

TEST(JobConversion, SpindleInRadiansPerSecond) {
  const Job job = parse_job(
      std::string(kTool) + "process: {spindle: 858.7 rad/s, feed_per_tooth: 0.1, ap: 1, ae: 2}\n",
      "");
  EXPECT_DOUBLE_EQ(job.process->spindle_rad_s, 858.7);
}

TEST(JobConversion, SlottingAtExactlyTheDiameterIsAllowed) {
  const Job job = parse_job(
      std::string(kTool) + "process: {spindle: 6000, feed_per_tooth: 0.1, ap: 1, ae: 10 mm}\n", "");
  EXPECT_NEAR(job.process->radial_depth_m, 0.01, 1e-15);
}

TEST(JobConversion, OtherCuttingLaws) {
  const Job exponential = parse_job(
      "cutting: {law: exponential, kF: 1200 N/mm, exponent: 0.7, kr: 0.4, ka: 10 %}\n", "");
  const auto& e = std::get<robomill::cutting::ExponentialLaw>(*exponential.cutting);
  EXPECT_NEAR(e.kF_n_per_m, 1.2e6, 1e-6);
  EXPECT_DOUBLE_EQ(e.exponent, 0.7);
  EXPECT_DOUBLE_EQ(e.reference_chip_m, 1e-3);
  EXPECT_DOUBLE_EQ(e.radial_ratio, 0.4);
  EXPECT_NEAR(e.axial_ratio, 0.1, 1e-15);

  const Job fractional = parse_job("cutting: {law: fractional, k0: 2e5, hs: 0.02, r: 3}\n", "");
  const auto& f = std::get<robomill::cutting::FractionalLaw>(*fractional.cutting);
  EXPECT_DOUBLE_EQ(f.k0_n_per_m, 2e5);  // bare number: N/m
  EXPECT_NEAR(f.hs_m, 2e-5, 1e-18);
  EXPECT_DOUBLE_EQ(f.r, 3.0);

  const Job sized = parse_job(
      "cutting: {law: size_dependent, kc1: 1700, b1: -0.25, kc2: 0.35, b2: -0.1, chip_unit: 1 "
      "um}\n",
      "");
  const auto& s = std::get<robomill::cutting::SizeDependentLaw>(*sized.cutting);
  EXPECT_NEAR(s.kc1_pa, 1.7e9, 1e-3);
  EXPECT_DOUBLE_EQ(s.b1, -0.25);
  EXPECT_DOUBLE_EQ(s.kc2, 0.35);
  EXPECT_DOUBLE_EQ(s.b2, -0.1);
  EXPECT_NEAR(s.reference_chip_m, 1e-6, 1e-21);
}

TEST(JobConversion, BallEndMillAndYamlBooleansAndEmptySections) {
  const Job job = parse_job(
      "tool: {type: ball, diameter: 8, teeth: 4, overhang: 4}\nforces:\nexperiments:\n"
      "  - {spindle: 3000, depth: 1, chatter: yes}\n",
      "");
  EXPECT_EQ(job.tool->type, robomill::tool::ToolType::ball);
  EXPECT_TRUE(job.experiments[0].chatter);
  EXPECT_EQ(job.forces.revolutions, 1);
}

TEST(JobConversion, ResolveIsRelativeToTheJobFolder) {
  Job job;
  job.source = "/data/cells/job.yaml";
  EXPECT_EQ(job.resolve("frf/x.uff"), std::filesystem::path("/data/cells/frf/x.uff"));
  EXPECT_EQ(job.resolve("/abs/y.csv"), std::filesystem::path("/abs/y.csv"));
  job.source = "job.yaml";
  EXPECT_EQ(job.resolve("x.csv"), std::filesystem::path("x.csv"));
}

TEST(JobConversion, LoadJobReadsAFileAndMissingFilesAreInputErrors) {
  const auto folder = std::filesystem::temp_directory_path() / "robomill_test_io";
  std::filesystem::create_directories(folder);
  const auto file = folder / "job.yaml";
  std::ofstream(file) << kCompleteJob;
  const Job job = robomill::job::load_job(file);
  EXPECT_EQ(job.source, file);
  EXPECT_EQ(job.tool->teeth, 2);

  const auto missing = folder / "does_not_exist.yaml";
  try {
    robomill::job::load_job(missing);
    ADD_FAILURE() << "missing file accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("does_not_exist.yaml"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("not found"), std::string::npos);
  }
  EXPECT_THROW(robomill::job::load_job(folder), InputError);
  std::filesystem::remove_all(folder);
}

TEST(JobConversion, RequireNamesTheFirstMissingSection) {
  const Job job = parse_job(kTool, "");
  EXPECT_NO_THROW(robomill::job::require(job, {robomill::job::Section::tool}));
  try {
    robomill::job::require(job, {robomill::job::Section::tool, robomill::job::Section::cutting,
                                 robomill::job::Section::process});
    ADD_FAILURE() << "missing cutting section accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), "cutting");
    EXPECT_EQ(error.line(), 0);
    EXPECT_NE(std::string(error.what()).find("section required by this command is missing"),
              std::string::npos);
  }
  try {
    robomill::job::require(job, {robomill::job::Section::modes});
    ADD_FAILURE() << "missing modes accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), "dynamics.modes");
  }
}

// --- errors: each names the field path and the line -----------------------

TEST(JobValidation, MissingRequiredField) {
  expect_error("name: x\ntool:\n  teeth: 2\n", "tool.diameter", 2, "required field missing");
  expect_error(std::string(kTool) + "process:\n  spindle: 6000\n  ap: 1\n  ae: 2\n",
               "process.feed_per_tooth", 4, "feed_rate");
  expect_error("cutting:\n  law: linear\n  Krc: 100\n", "cutting.Ktc", 1, "required field missing");
  expect_error("dynamics:\n  modes:\n    - {direction: x, fn: 100, zeta: 0.02}\n",
               "dynamics.modes[0].k", 3, "required field missing");
}

TEST(JobValidation, WrongYamlTypes) {
  expect_error("tool:\n  diameter: {a: 1}\n  teeth: 2\n", "tool.diameter", 2,
               "expected a length (mm, m, um), got a map");
  expect_error("tool:\n  diameter: 10\n  teeth: [2]\n", "tool.teeth", 3,
               "expected an integer, got a list");
  expect_error("tool: 10 mm\n", "tool", 1, "got the value '10 mm'");
  expect_error("dynamics:\n  modes: x\n", "dynamics.modes", 2, "expected a list");
  expect_error("output:\n  formats: csv\n", "output.formats", 2, "expected a list");
  expect_error("name: [a, b]\n", "name", 1, "expected text, got a list");
  expect_error("experiments:\n  - 3\n", "experiments[0]", 2, "got the value '3'");
  expect_error("experiments:\n  - {spindle: 1000, depth: 1, chatter: maybe}\n",
               "experiments[0].chatter", 2, "expected true or false, got 'maybe'");
  expect_error("tool:\n  diameter:\n  teeth: 2\n", "tool.diameter", 2, "no value given");
}

TEST(JobValidation, IntegerFields) {
  expect_error("tool:\n  diameter: 10\n  teeth: -2\n", "tool.teeth", 3,
               "must be a positive integer, got -2");
  // The message format of DESIGN.md §3, verbatim.
  EXPECT_STREQ(parse_error("tool:\n  diameter: 10\n  teeth: -2\n").what(),
               "tool.teeth (line 3): must be a positive integer, got -2");
  expect_error("tool:\n  diameter: 10\n  teeth: 2.5\n", "tool.teeth", 3,
               "must be an integer, got '2.5'");
  expect_error("tool:\n  diameter: 10\n  teeth: 21\n", "tool.teeth", 3,
               "must be an integer from 1 to 20, got 21");
  expect_error("tool:\n  diameter: 10\n  teeth: 99999999999999999999\n", "tool.teeth", 3,
               "from 1 to 20");
  expect_error("forces:\n  steps_per_tooth: 2\n", "forces.steps_per_tooth", 2, "from 4 to 100000");
  expect_error("forces:\n  axial_elements: 0\n", "forces.axial_elements", 2,
               "must be a positive integer, got 0");
  expect_error("forces:\n  revolutions: 1001\n", "forces.revolutions", 2, "from 1 to 1000");
}

TEST(JobValidation, ZeroAndNegativeQuantities) {
  expect_error("tool:\n  diameter: 0\n  teeth: 2\n", "tool.diameter", 2,
               "must be positive, got 0 mm");
  expect_error("tool:\n  diameter: -0.01 m\n  teeth: 2\n", "tool.diameter", 2,
               "must be positive, got -0.01 m");
  expect_error(std::string(kTool) + "  helix: 85\n", "tool.helix", 4,
               "must be in the range 0 deg <= helix <= 80 deg, got 85 deg");
  expect_error(std::string(kTool) + "  runout: {offset: 5 mm}\n", "tool.runout.offset", 4,
               "must be less than the tool radius (5 mm)");
  expect_error("tool: {type: ball, diameter: 10, teeth: 2, overhang: 4}\n", "tool.overhang", 1,
               "at least the ball radius (5 mm)");
  expect_error(
      "dynamics:\n  modes:\n    - direction: x\n      fn: 100\n      zeta: 1.2\n      k: 1e6\n",
      "dynamics.modes[0].zeta", 5, "0 < zeta < 1, got 1.2");
  expect_error("cutting:\n  law: exponential\n  kF: 100\n  exponent: 2\n", "cutting.exponent", 4,
               "exponent <= 1.5");
  expect_error("cutting:\n  Ktc: 800\n  Krc: -3\n", "cutting.Krc", 3, "must not be negative");
}

TEST(JobValidation, UnitsUnknownOrOfTheWrongDimension) {
  expect_error("tool:\n  diameter: 10 mmm\n  teeth: 2\n", "tool.diameter", 2, "unknown unit 'mmm'");
  expect_error("tool:\n  diameter: 10 rpm\n  teeth: 2\n", "tool.diameter", 2,
               "expected a length (mm, m, um), got 'rpm'");
  expect_error(std::string(kTool) + "process:\n  spindle: 140 Hz\n", "process.spindle", 5,
               "expected an angular speed (rpm, rad/s), got 'Hz'");
  expect_error("dynamics:\n  modes:\n    - direction: x\n      fn: 100 rad/s\n",
               "dynamics.modes[0].fn", 4, "expected a frequency");
  expect_error("cutting:\n  Ktc: 855 N/mm\n", "cutting.Ktc", 2, "expected a pressure");
  expect_error("cutting: {law: exponential, kF: 1, exponent: 0.5 mm}\n", "cutting.exponent", 1,
               "expected a dimensionless number");
}

TEST(JobValidation, NonFiniteValues) {
  expect_error("tool:\n  diameter: .nan\n  teeth: 2\n", "tool.diameter", 2, "not a finite number");
  expect_error("tool:\n  diameter: .inf\n  teeth: 2\n", "tool.diameter", 2, "not a finite number");
  expect_error("tool:\n  diameter: 10\n  teeth: .inf\n", "tool.teeth", 3, "must be an integer");
  expect_error("cutting:\n  Ktc: -.inf N/mm^2\n", "cutting.Ktc", 2, "not a finite number");
  expect_error("tool:\n  diameter: 1e308 m\n  teeth: 2\n  overhang: 1e308 km\n", "tool.overhang", 4,
               "unknown unit 'km'");
}

TEST(JobValidation, UnknownKeys) {
  expect_error("tool:\n  diameter: 10\n  teth: 2\n", "tool.teth", 3,
               "unknown key; expected one of: type, corner_radius, diameter, teeth, helix, "
               "overhang, E, runout "
               "(did you mean 'teeth'?)");
  // The list grows with every section robomill learns; its start and the
  // suggestion are what matter.
  expect_error("name: a\nprocesss:\n  ap: 1\n", "processs", 2,
               "unknown key; expected one of: name, tool, cutting, process, forces, dynamics, "
               "stability, experiments, robot, output, ");
  expect_error("name: a\nprocesss:\n  ap: 1\n", "processs", 2, "(did you mean 'process'?)");
  expect_error("surface:\n  grid: [10, 10]\n", "surface", 1,
               "a surface needs the tool: and process: sections");
  expect_error("robot:\n  dh: []\n", "robot.dh", 2, "one row {a, alpha, d, theta} per joint");
  expect_error("dynamics:\n  postures: []\n", "dynamics.postures", 2,
               "must list at least one measured posture");
  expect_error("cutting:\n  law: linear\n  Ktc: 800\n  kF: 3\n", "cutting.kF", 4,
               "unknown key for law 'linear'; expected one of: law, Ktc");
  expect_error(std::string(kTool) + "  runout: {offset: 0, phase: 3}\n", "tool.runout.phase", 4,
               "expected one of: offset, angle");
  expect_error("dynamics:\n  modes:\n    - {direction: x, fn: 1, zeta: 0.1, k: 1, q: 2}\n",
               "dynamics.modes[0].q", 3, "unknown key");
  expect_error("tool:\n  diameter: 10\n  teeth: 2\n  diameter: 12\n", "tool.diameter", 4,
               "duplicate key (first given on line 2)");
}

TEST(JobValidation, ChoicesAreChecked) {
  expect_error("tool:\n  type: conical\n", "tool.type", 2,
               "expected one of: flat, ball, bull; got 'conical'");
  expect_error("cutting:\n  law: magic\n", "cutting.law", 2,
               "expected one of: linear, exponential");
  expect_error("output:\n  formats: [csv, pdf]\n", "output.formats[1]", 2, "unknown format 'pdf'");
}

TEST(JobValidation, SyntaxErrorsCarryTheLine) {
  const InputError error = parse_error("tool:\n  diameter: 10\n  teeth: [2\nprocess:\n");
  EXPECT_EQ(error.field(), "job.yaml");
  EXPECT_GE(error.line(), 3);
  EXPECT_NE(std::string(error.what()).find("YAML syntax error"), std::string::npos) << error.what();

  const InputError tabs = parse_error("tool:\n  diameter: 10\n\tteeth: 2\n");
  EXPECT_EQ(tabs.field(), "job.yaml");
  EXPECT_EQ(tabs.line(), 3) << tabs.what();
}

// The uncertainty section's trap: a path with a list index, unquoted inside
// a flow map, opens a list where the path should be. The syntax error names
// the line and says how to write it; the same path quoted is read.
TEST(JobValidation, IndexedPathInAFlowMapGetsAHint) {
  const std::string head =
      "tool: {type: flat, diameter: 10 mm, teeth: 2}\nuncertainty:\n  variables:\n";
  const InputError error = parse_error(
      head + "    - {name: k, path: dynamics.modes[0].k, distribution: lognormal, sigma: 0.1}\n");
  EXPECT_EQ(error.field(), "job.yaml");
  EXPECT_EQ(error.line(), 4) << error.what();
  const std::string message = error.what();
  EXPECT_NE(message.find("YAML syntax error"), std::string::npos) << message;
  EXPECT_NE(message.find("must be quoted"), std::string::npos) << message;
  EXPECT_NE(message.find("dynamics.modes.0.k"), std::string::npos) << message;
  // Another syntax error on a line without such a path gets no hint.
  const InputError plain = parse_error("tool:\n  diameter: 10\n  teeth: [2\nprocess:\n");
  EXPECT_EQ(std::string(plain.what()).find("must be quoted"), std::string::npos) << plain.what();
}

TEST(JobValidation, EmptyAndNonMapDocuments) {
  expect_error("", "job.yaml", 0, "job is empty");
  expect_error("# only a comment\n", "job.yaml", 0, "job is empty");
  expect_error("- a\n- b\n", "job.yaml", 1, "expected a map of sections");
  expect_error("just text\n", "job.yaml", 1, "expected a map of sections");
  expect_error("name: a\n---\nname: b\n", "job.yaml", 2, "a second YAML document starts here");
}

TEST(JobValidation, CrossFieldChecks) {
  expect_error(std::string(kTool) +
                   "process:\n  spindle: 6000\n  feed_per_tooth: 0.1\n  ap: 1\n  ae: 12 mm\n",
               "process.ae", 8, "radial depth of cut 12 mm exceeds the tool diameter 10 mm");
  expect_error(
      std::string(kTool) + "process:\n  spindle: 6000\n  feed_per_tooth: 0.1\n  ap: 45\n  ae: 2\n",
      "process.ap", 7, "exceeds the tool overhang 40 mm");
  expect_error(std::string(kTool) +
                   "process:\n  spindle: 6000\n  feed_per_tooth: 0.1\n  feed_rate: 600\n  ap: 1\n"
                   "  ae: 2\n",
               "process.feed_rate", 7, "either feed_per_tooth or feed_rate, not both");
  expect_error("process:\n  spindle: 6000\n  feed_rate: 600\n  ap: 1\n  ae: 2\n",
               "process.feed_rate", 3, "needs the number of teeth");
  expect_error("dynamics:\n  modes:\n    - {direction: x, fn: 100, zeta: 0.02, k: 1e6, m: 2}\n",
               "dynamics.modes[0].m", 3,
               "give one of k (modal stiffness), m (modal mass) or shape");
  expect_error("dynamics:\n  modes: []\n", "dynamics.modes", 2, "at least one mode");
  // A hammer test is no cut; a test's place is given once; a test's own ae
  // fits the tool.
  expect_error("experiments:\n  - {frf: {x: a.uff}, spindle: 3000 rpm}\n", "experiments[0].spindle",
               2, "this entry is a hammer test");
  expect_error("experiments:\n  - {frf: []}\n", "experiments[0].frf", 2, "at least one FRF file");
  expect_error(std::string(kTool) +
                   "experiments:\n  - {spindle: 3000, depth: 1, chatter: false, ae: 11 mm}\n",
               "experiments[0].ae", 5, "exceeds the tool diameter 10 mm");
  expect_error("experiments:\n  - {spindle: 3000, depth: 1, chatter: false, position: [1, 2, 3]}\n",
               "experiments[0].position", 2, "needs a robot");
}

TEST(JobValidation, ErrorsInLaterListItemsNameTheirIndex) {
  expect_error(
      "dynamics:\n  modes:\n    - {direction: x, fn: 100, zeta: 0.02, k: 1e6}\n"
      "    - {direction: y, fn: -5, zeta: 0.02, k: 1e6}\n",
      "dynamics.modes[1].fn", 4, "must be positive, got -5 Hz");
  expect_error("experiments:\n  - {spindle: 1000, depth: 1, chatter: false}\n  - {spindle: 1000}\n",
               "experiments[1].depth", 3, "required field missing");
}

TEST(JobValidation, NestingAndSizeGuards) {
  const std::string deep = "name: " + std::string(100, '[') + std::string(100, ']') + "\n";
  expect_error(deep, "job.yaml", 1, "nesting deeper than 64 levels");
  std::string dashes = "experiments:\n";
  for (int i = 0; i < 80; ++i)
    dashes += "- ";
  dashes += "x\n";
  expect_error(dashes, "job.yaml", 2, "nesting deeper");
  const std::string huge = "name: " + std::string(std::size_t{1} << 20, 'a') + "\n";
  expect_error(huge, "job.yaml", 0, "limited to 1 MiB");
}

// Inputs the fuzzer found (fuzz/README.md); each once hung or crashed.
TEST(FuzzRegression, StrayFlowIndicatorDoesNotHang) {
  // yaml-cpp's LoadAll loops forever on a leading ','; the parser must not.
  expect_error(",oall, kF: 12nown}\n", "job.yaml", 1, "YAML syntax error: unexpected ','");
  expect_error(",\n", "job.yaml", 1, "YAML syntax error");
}

}  // namespace

}  // namespace test_job_parser_cpp
