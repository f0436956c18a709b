// The `dynamics:` section beyond the modal table: mode shapes along the tool
// (000 Table 2), measured FRF files, fit bands and which source the analyses
// use. Valid input reaches SI values; malformed input is an InputError naming
// the field and its line.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "job/expect_input_error.hpp"
#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"

namespace test_dynamics_section_cpp {

namespace {

using robomill::InputError;
using robomill::dynamics::FrfKind;
using robomill::job::FrfFileSpec;
using robomill::job::Job;
using robomill::job::parse_job;

using robomill::test::expect_error;
using robomill::test::parse_error;

// 000 Table 2, mode x: fn 2060.49 Hz, ζ 2.37 %, shape 3.232, 2.264, 1.738,
// 1.075 1/√kg at 3, 12, 24, 36 mm from the free end.
TEST(DynamicsSection, ShapeAlongTheToolGivesTheTipMass) {
  const Job job = parse_job(R"(dynamics:
  modes:
    - direction: x
      fn: 2060.49 Hz
      zeta: 2.37 %
      shape: [{at: 3 mm, value: 3.232}, {at: 12 mm, value: 2.264},
              {at: 24 mm, value: 1.738}, {at: 36 mm, value: 1.075}]
)",
                            "job.yaml");
  ASSERT_EQ(job.modes.size(), 1u);
  const auto& mode = job.modes[0];
  EXPECT_DOUBLE_EQ(mode.shape.at(12e-3), 2.264);
  // Tip value extrapolated from 3 and 12 mm: 3.232 + (3.232 − 2.264)/3.
  const double tip = 3.232 + (3.232 - 2.264) / 3.0;
  EXPECT_NEAR(mode.mass_kg, 1.0 / (tip * tip), 1e-12);
  const double omega = 2.0 * std::numbers::pi * 2060.49;
  EXPECT_NEAR(mode.stiffness_n_per_m, omega * omega / (tip * tip), 1e-6);
}

// A mode moving the tip obliquely couples x and y: H_xy = e_x e_y / (m (ωn² − ω² + 2iζωnω)).
TEST(DynamicsSection, ModeAlongAGeneralDirectionCouplesTheAxes) {
  const Job job = parse_job(R"(dynamics:
  modes:
    - {direction: [3, 4, 0], fn: 100 Hz, zeta: 0.02, k: 1e6 N/m}
    - {direction: z, fn: 300 Hz, zeta: 0.02, m: 2 kg}
)",
                            "job.yaml");
  EXPECT_EQ(job.modes[0].direction, 'v');
  EXPECT_NEAR(job.modes[0].direction_vector.x(), 0.6, 1e-15);
  EXPECT_NEAR(job.modes[0].direction_vector.y(), 0.8, 1e-15);
  const auto modes = robomill::job::modal_model(job);
  // Static compliance (ω → 0): H = e eᵀ / k for the first mode.
  const Eigen::Matrix3cd h = modes.receptance(1e-9);
  EXPECT_NEAR(h(0, 1).real(), 0.6 * 0.8 / 1e6, 1e-15);
  EXPECT_NEAR(h(0, 0).real(), 0.36 / 1e6, 1e-15);
  EXPECT_NEAR(h(2, 2).real(), 1.0 / (2.0 * std::pow(2.0 * std::numbers::pi * 300.0, 2)), 1e-15);
  expect_error("dynamics:\n  modes: [{direction: [1, 0], fn: 1 Hz, zeta: 0.1, k: 1 N/m}]\n",
               "dynamics.modes[0].direction", 2, "three components");
  expect_error("dynamics:\n  modes: [{direction: [0, 0, 0], fn: 1 Hz, zeta: 0.1, k: 1 N/m}]\n",
               "dynamics.modes[0].direction", 2, "must not be zero");
  expect_error("dynamics:\n  modes: [{direction: [1, a, 0], fn: 1 Hz, zeta: 0.1, k: 1 N/m}]\n",
               "dynamics.modes[0].direction[1]", 2, "not a finite number");
}

TEST(DynamicsSection, FrfFilesWithUnitsFormatsAndAxes) {
  const Job job = parse_job(R"(dynamics:
  frf:
    - {file: hammer/xx.uff, response: x, reference: x}
    - {file: yy.CSV, response: y, units: mm/N}
    - {file: zz.txt, format: csv, response: z, units: m/s^2/N}
    - {file: tip.unv, units: um/N}
  fit:
    max_order: 30
    bands: [{from: 10 Hz, to: 150 Hz}, {from: 3 kHz, to: 6 kHz, max_order: 20}]
)",
                            "/data/cell/job.yaml");
  ASSERT_EQ(job.frf_files.size(), 4u);
  EXPECT_EQ(job.frf_files[0].file, std::filesystem::path("/data/cell/hammer/xx.uff"));
  EXPECT_EQ(job.frf_files[0].format, FrfFileSpec::Format::uff58);
  EXPECT_FALSE(job.frf_files[0].kind.has_value());
  EXPECT_EQ(*job.frf_files[0].response_axis, 0);
  EXPECT_EQ(job.frf_files[1].format, FrfFileSpec::Format::csv);
  EXPECT_EQ(*job.frf_files[1].kind, FrfKind::receptance);
  EXPECT_DOUBLE_EQ(job.frf_files[1].scale_to_si, 1e-3);
  EXPECT_EQ(*job.frf_files[1].reference_axis, 1);  // driving point by default
  EXPECT_EQ(*job.frf_files[2].kind, FrfKind::accelerance);
  EXPECT_EQ(*job.frf_files[2].response_axis, 2);
  EXPECT_EQ(job.frf_files[3].format, FrfFileSpec::Format::uff58);
  EXPECT_DOUBLE_EQ(job.frf_files[3].scale_to_si, 1e-6);
  EXPECT_EQ(job.fit.max_order, 30);
  ASSERT_EQ(job.fit.bands.size(), 2u);
  EXPECT_DOUBLE_EQ(job.fit.bands[1].low_hz, 3000.0);
  EXPECT_EQ(job.fit.bands[1].max_order, 20);
  // Without a modal table the analyses use the fitted modes.
  EXPECT_EQ(job.dynamics_source, Job::DynamicsSource::fit);
}

// DESIGN.md's public form: one file per measured direction.
TEST(DynamicsSection, FrfFilesByDirection) {
  const Job job = parse_job(R"(dynamics:
  frf:
    x: hammer/xx.uff
    y: {file: yy.csv, units: um/N}
)",
                            "/data/cell/job.yaml");
  ASSERT_EQ(job.frf_files.size(), 2u);
  EXPECT_EQ(job.frf_files[0].file, std::filesystem::path("/data/cell/hammer/xx.uff"));
  EXPECT_EQ(*job.frf_files[0].response_axis, 0);
  EXPECT_EQ(*job.frf_files[0].reference_axis, 0);
  EXPECT_EQ(job.frf_files[1].format, FrfFileSpec::Format::csv);
  EXPECT_EQ(*job.frf_files[1].response_axis, 1);
  EXPECT_DOUBLE_EQ(job.frf_files[1].scale_to_si, 1e-6);
  expect_error("dynamics:\n  frf:\n    x: a.csv\n", "dynamics.frf.x", 3, "needs its units");
  expect_error("dynamics:\n  frf:\n    w: a.uff\n", "dynamics.frf.w", 3, "");
}

TEST(DynamicsSection, MalformedEntriesNameTheField) {
  expect_error("dynamics:\n  frf:\n    - {response: x}\n", "dynamics.frf[0].file", 3,
               "required field missing");
  expect_error("dynamics:\n  frf:\n    - {file: a.csv, units: mm/N}\n", "dynamics.frf[0].response",
               3, "required for CSV");
  expect_error("dynamics:\n  frf:\n    - {file: a.csv, response: x}\n", "dynamics.frf[0].units", 3,
               "required for CSV");
  expect_error("dynamics:\n  frf:\n    - {file: a.uff, units: N/mm}\n", "dynamics.frf[0].units", 3,
               "not an FRF unit");
  expect_error("dynamics:\n  frf:\n    - {file: a.uff, response: w}\n", "dynamics.frf[0].response",
               3, "");
  expect_error(
      "dynamics:\n  frf:\n    - {file: a.uff}\n  fit:\n    bands: [{from: 50 Hz, to: 10 Hz}]\n",
      "dynamics.fit.bands[0].to", 5, "must exceed from");
  expect_error(
      "dynamics:\n  modes: [{direction: x, fn: 100 Hz, zeta: 0.01, k: 1e6 N/m}]\n"
      "  use: frf\n",
      "dynamics.use", 3, "lists no measured FRF file");
  expect_error(
      "dynamics:\n  modes:\n    - {direction: x, fn: 100 Hz, zeta: 0.01,\n"
      "       shape: [{at: 12 mm, value: 2}, {at: 3 mm, value: 3}]}\n",
      "dynamics.modes[0].shape[1].at", 4, "from the tip outward");
  expect_error(
      "dynamics:\n  modes:\n    - {direction: x, fn: 100 Hz, zeta: 0.01, k: 1e6 N/m,\n"
      "       shape: [{at: 3 mm, value: 3}]}\n",
      "dynamics.modes[0].shape", 4, "not several");
}

TEST(DynamicsSection, MeasuredFrfsDirectlyOnlyForTheZeroOrderMethod) {
  const std::string base = R"(tool: {diameter: 12 mm, teeth: 2, overhang: 50 mm}
dynamics:
  frf: [{file: xx.uff}]
  use: frf
stability:
  speeds: {from: 1000 rpm, to: 6000 rpm, count: 10}
  depth_max: 5 mm
)";
  expect_error(base + "  method: fdm\n", "stability.method", 8, "only the zero-order method");
  const Job job = parse_job(base + "  method: zoa\n", "job.yaml");
  EXPECT_EQ(job.dynamics_source, Job::DynamicsSource::frf);
}

}  // namespace

}  // namespace test_dynamics_section_cpp
