// The `simulation:` section of a job (src/job/job_parser_simulation.cpp):
// units converted once, fixation matrices, and errors naming the field.

#include <gtest/gtest.h>

#include <string>

#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"

namespace test_simulation_section_cpp {

namespace {

using namespace robomill;

const std::string kCut =
    "tool: {diameter: 20 mm, teeth: 4}\n"
    "cutting: {law: fractional, k0: 5e6 N/m, hs: 0.018 mm, r: 0.1, kr: 0.3}\n"
    "process: {spindle: 10000 rpm, feed_rate: 4000 mm/min, ap: 0.02 mm, ae: 20 mm}\n";

void expect_error(const std::string& simulation, const std::string& field,
                  const std::string& fragment) {
  try {
    job::parse_job(kCut + simulation, "job.yaml");
    ADD_FAILURE() << "accepted: " << simulation;
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), field) << error.what();
    EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos) << error.what();
  }
}

TEST(SimulationSection, ReadsAFixationInSiUnits) {
  const job::Job job = job::parse_job(
      kCut +
          "simulation:\n  model: 2dof\n  fixation: {mass: [100 kg, 0, 0, 100 kg], stiffness: "
          "[0.3 N/um, 3e5], damping_ratio: 0.05}\n  revolutions: 200\n  workpiece: {border: "
          "1.5}\n",
      "job.yaml");
  ASSERT_TRUE(job.simulation);
  const job::SimulationSettings& s = *job.simulation;
  EXPECT_EQ(s.model, job::SimulationSettings::Model::fixation);
  EXPECT_DOUBLE_EQ(s.stiffness_n_per_m(0, 0), 3e5);
  EXPECT_DOUBLE_EQ(s.mass_kg(1, 1), 100.0);
  EXPECT_NEAR(s.damping_n_s_per_m(1, 1), 2.0 * 0.05 * std::sqrt(3e5 * 100.0), 1e-9);
  EXPECT_NEAR(s.duration_s, 200 * 60.0 / 10000.0, 1e-12);
  EXPECT_NEAR(*s.border_gap_m, 1.5e-3, 1e-15);
  EXPECT_NEAR(s.steady_window_s, 40 * 60.0 / 10000.0, 1e-12);  // 20 % of the run
}

TEST(SimulationSection, ErrorsNameTheField) {
  expect_error("simulation: {model: 1dof, duration: 1 s}\n", "simulation.fixation",
               "required for model 1dof");
  expect_error(
      "simulation: {model: 2dof, duration: 1 s, fixation: {mass: [1, 2, 3], stiffness: 1, "
      "damping: 1}}\n",
      "simulation.fixation.mass", "expected 2 values");
  expect_error("simulation: {duration: 1 s, revolutions: 3, model: rigid}\n",
               "simulation.revolutions", "not both");
  expect_error("simulation: {model: rigid}\n", "simulation", "duration");
  expect_error("simulation: {duration: 1 s}\n", "simulation.model", "no dynamics");
  expect_error("simulation: {model: rigid, duration: 1 s, steady_revolutions: 500}\n",
               "simulation.steady_revolutions", "at least 3 s");
  expect_error(
      "simulation: {model: 1dof, duration: 1 s, fixation: {mass: 1, stiffness: -4, damping: "
      "0}}\n",
      "simulation.fixation.stiffness", "");
  expect_error("simulation: {model: rigid, duration: 1 s, stepz: 3}\n", "simulation.stepz",
               "unknown key");
}

}  // namespace

}  // namespace test_simulation_section_cpp
