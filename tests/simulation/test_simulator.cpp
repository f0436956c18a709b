// The time-domain simulation (simulation/simulator.hpp) against the force
// model of the foundation (cutting/milling_forces.hpp), against geometry
// (entry into a part, loss of contact, runout) and against the exact
// discretization of a linear cut.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "robomill/cutting/milling_forces.hpp"
#include "robomill/simulation/response_metrics.hpp"
#include "robomill/simulation/simulator.hpp"

namespace test_simulator_cpp {

namespace {

using namespace robomill;
constexpr double kPi = std::numbers::pi;

tool::Tool cutter(double diameter_m, int teeth, double helix_deg, double runout_m = 0.0,
                  tool::ToolType type = tool::ToolType::flat) {
  tool::ToolSpec spec;
  spec.type = type;
  spec.diameter_m = diameter_m;
  spec.teeth = teeth;
  spec.helix_rad = helix_deg * kPi / 180.0;
  spec.overhang_m = 5.0 * diameter_m;
  spec.runout = {runout_m, 0.3};
  return tool::Tool(spec);
}

double rpm(double value) {
  return value * 2.0 * kPi / 60.0;
}

// A rigid cutter in the steady cut: the chip of (H) is fz sin φ sin κ, so
// every sample equals MillingForceModel::at at the same angle (helix, 20
// elements, edge forces, all three components). Before one revolution the
// memory holds the rigid nominal past, after it the surface cut.
TEST(Simulator, RigidSteadyForcesEqualTheForceModel) {
  const tool::Tool tool = cutter(16e-3, 4, 30.0);
  const cutting::LinearLaw law{700e6, 210e6, 60e6, 20e3, 15e3, 2e3};
  const cutting::MillingProcess process{rpm(6000), 0.05e-3, 4e-3, 16e-3,
                                        cutting::MillingDirection::down};
  const cutting::MillingForceModel reference(tool, law, process, 20);
  simulation::SimulationOptions options;
  options.steps_per_tooth = 50;
  options.axial_elements = 20;
  options.start_angle_rad = 0.2;
  options.duration_s = 3.0 * 2.0 * kPi / process.spindle_rad_s;
  const auto result = simulation::simulate(tool, law, process, simulation::rigid_structure(),
                                           simulation::Workpiece{}, options);
  double peak = 0.0, worst = 0.0;
  for (std::size_t i = 0; i < result.size(); ++i) {
    const double angle = options.start_angle_rad + process.spindle_rad_s * result.time_s[i];
    const Eigen::Vector3d expected = reference.at(angle).force_n;
    peak = std::max(peak, expected.norm());
    worst = std::max(worst, (result.force_n[i] - expected).norm());
  }
  EXPECT_LT(worst, 1e-9 * peak) << "peak " << peak;
  EXPECT_EQ(result.element_evaluations, static_cast<long long>(result.size()) * 20 * 4);
}

// Runout (001 Eq 4) and multiple regeneration: with φ_j = ϕ + 2π j / N
// (001 Eq 2), tooth j + 1 passes an angle one tooth period before tooth j, so
// the chip is min_i (i fz sin φ + r_j − r_{j+i}) — a tooth whose radius is
// short by more than fz sin φ misses the cut and the next one removes two
// feeds. The swept surface gives this without being told; checked here
// against that formula written out, after the first revolution.
// (cutting/milling_forces.hpp pairs r_j with r_{j−i}, the reverse order for
// its own pitch convention: see docs/validation.md.)
TEST(Simulator, RunoutChipIsTheMinimumOverEarlierTeeth) {
  const tool::Tool tool = cutter(16e-3, 4, 0.0, 40e-6);
  const cutting::LinearLaw law{700e6, 210e6, 0.0, 0.0, 0.0, 0.0};
  const cutting::MillingProcess process{rpm(6000), 0.03e-3, 2e-3, 16e-3,
                                        cutting::MillingDirection::down};
  simulation::SimulationOptions options;
  options.steps_per_tooth = 40;
  options.start_angle_rad = 0.01;
  options.duration_s = 3.0 * 2.0 * kPi / process.spindle_rad_s;
  const auto result = simulation::simulate(tool, law, process, simulation::rigid_structure(),
                                           simulation::Workpiece{}, options);
  const int teeth = 4;
  double radius[4];
  for (int j = 0; j < teeth; ++j)
    radius[j] = tool.edge_radius_with_runout_m(j, 1e-3);
  double peak = 0.0, worst = 0.0;
  int missed = 0;
  for (std::size_t i = result.size() / 2; i < result.size(); ++i) {
    const double rotation = options.start_angle_rad + process.spindle_rad_s * result.time_s[i];
    Eigen::Vector3d expected = Eigen::Vector3d::Zero();
    for (int j = 0; j < teeth; ++j) {
      const double phi = std::remainder(rotation + 2.0 * kPi * j / teeth, 2.0 * kPi);
      if (phi <= 0.0)
        continue;  // slot: engaged on (0, π)
      double chip = 1e9;
      for (int k = 1; k <= teeth; ++k)
        chip = std::min(chip, k * process.feed_per_tooth_m * std::sin(phi) + radius[j] -
                                  radius[(j + k) % teeth]);
      if (!(chip > 0.0)) {
        ++missed;
        continue;
      }
      const double ft = law.Ktc_pa * chip * process.axial_depth_m;
      const double fr = law.Krc_pa * chip * process.axial_depth_m;
      expected += Eigen::Vector3d(-ft * std::cos(phi) - fr * std::sin(phi),
                                  ft * std::sin(phi) - fr * std::cos(phi), 0.0);
    }
    peak = std::max(peak, expected.norm());
    worst = std::max(worst, (result.force_n[i] - expected).norm());
  }
  EXPECT_GT(missed, 0) << "the runout should make a tooth miss the cut somewhere";
  EXPECT_LT(worst, 1e-9 * peak) << "peak " << peak;
}

// Partial immersion: the part's band limits the chip geometrically, where
// the force model cuts at the engagement angle; the two differ only at the
// entry step of each pass, so the mean forces agree closely.
TEST(Simulator, PartialImmersionMeanForcesEqualTheForceModel) {
  const tool::Tool tool = cutter(10e-3, 3, 35.0);
  const cutting::LinearLaw law{800e6, 240e6, 0.0, 0.0, 0.0, 0.0};
  for (const auto direction : {cutting::MillingDirection::down, cutting::MillingDirection::up}) {
    const cutting::MillingProcess process{rpm(8000), 0.08e-3, 3e-3, 3e-3, direction};
    const cutting::MillingForceModel reference(tool, law, process, 30);
    const auto expected =
        cutting::summarize(cutting::sample_forces(reference, {1, 400}), process.spindle_rad_s);
    simulation::SimulationOptions options;
    options.steps_per_tooth = 400;
    options.axial_elements = 30;
    options.duration_s = 2.0 * 2.0 * kPi / process.spindle_rad_s;
    const auto result = simulation::simulate(tool, law, process, simulation::rigid_structure(),
                                             simulation::Workpiece{}, options);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    const std::size_t revolution = 3 * 400;
    for (std::size_t i = result.size() - 1 - revolution; i + 1 < result.size(); ++i)
      mean += result.force_n[i];
    mean /= static_cast<double>(revolution);
    EXPECT_NEAR(mean.x(), expected.mean_n.x(), 5e-3 * expected.mean_n.norm());
    EXPECT_NEAR(mean.y(), expected.mean_n.y(), 5e-3 * expected.mean_n.norm());
  }
}

// A ball-end raster (Workpiece::raster_groove): the previous pass's groove
// leaves a strip ae wide at every height, so each edge element of radius
// r_k cuts the arc cos φ ≤ ae / r_k − 1 (down milling) with the chip
// fz sin φ sin κ. The steady mean force of a rigid cut is then the sum over
// the elements of the closed-form integrals over that arc (001 Eq 11 with
// the linear law). Tolerance 0.2 % (measured 0.02 %): at the arc's entry
// the chip is limited by the strip's edge (fz / ae = 0.5 % here). On a flat
// end every element has r = R, so the groove and the straight wall are the
// same cut.
TEST(Simulator, RasterGrooveEngagesEachBallDiskByTheStepover) {
  const cutting::LinearLaw law{800e6, 500e6, 100e6, 0.0, 0.0, 0.0};
  const cutting::MillingProcess process{rpm(6000), 0.005e-3, 2e-3, 1e-3,
                                        cutting::MillingDirection::down};
  simulation::SimulationOptions options;
  options.steps_per_tooth = 2000;
  options.axial_elements = 40;
  options.duration_s = 2.0 * 2.0 * kPi / process.spindle_rad_s;
  simulation::Workpiece groove;
  groove.raster_groove = true;
  const int teeth = 2;
  const std::size_t revolution = static_cast<std::size_t>(teeth * options.steps_per_tooth);
  auto mean_force = [&](const tool::Tool& tool, const simulation::Workpiece& part) {
    const auto result =
        simulation::simulate(tool, law, process, simulation::rigid_structure(), part, options);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (std::size_t i = result.size() - 1 - revolution; i + 1 < result.size(); ++i)
      mean += result.force_n[i];
    return Eigen::Vector3d(mean / static_cast<double>(revolution));
  };

  const tool::Tool ball = cutter(8e-3, teeth, 30.0, 0.0, tool::ToolType::ball);
  Eigen::Vector3d expected = Eigen::Vector3d::Zero();
  for (const tool::EdgeElement& e :
       tool::discretize_edge(ball, process.axial_depth_m, options.axial_elements)) {
    const double sk = std::sin(e.kappa_rad), ck = std::cos(e.kappa_rad);
    const double in = std::acos(std::clamp(process.radial_depth_m / e.radius_m - 1.0, -1.0, 1.0));
    const double out = kPi;
    const double sin_cos = 0.5 * (std::sin(out) * std::sin(out) - std::sin(in) * std::sin(in));
    const double sin_sin =
        0.5 * ((out - std::sin(out) * std::cos(out)) - (in - std::sin(in) * std::cos(in)));
    const double sin_only = std::cos(in) - std::cos(out);
    const double scale = teeth / (2.0 * kPi) * process.feed_per_tooth_m * sk * e.chip_width_m;
    expected += scale * Eigen::Vector3d(
                            -law.Ktc_pa * sin_cos - (sk * law.Krc_pa + ck * law.Kac_pa) * sin_sin,
                            law.Ktc_pa * sin_sin - (sk * law.Krc_pa + ck * law.Kac_pa) * sin_cos,
                            (ck * law.Krc_pa - sk * law.Kac_pa) * sin_only);
  }
  const Eigen::Vector3d raster = mean_force(ball, groove);
  EXPECT_LT((raster - expected).norm(), 0.002 * expected.norm())
      << "simulated " << raster.transpose() << ", closed form " << expected.transpose();
  // The straight wall (band from the tool radius) engages only the disks
  // wider than R − ae: a much smaller cut than the groove's.
  const Eigen::Vector3d wall = mean_force(ball, simulation::Workpiece{});
  EXPECT_LT(wall.norm(), 0.5 * raster.norm());

  const tool::Tool flat = cutter(8e-3, teeth, 30.0);
  EXPECT_LT((mean_force(flat, groove) - mean_force(flat, simulation::Workpiece{})).norm(),
            1e-12 * mean_force(flat, groove).norm());
}

// 002 Case A geometry: entering a part with a straight border, the first
// chip appears when a tooth first passes the border, one tooth cuts at a
// time at first (phase Ia), never more than N/2 + 1 on the way in, and
// nothing cuts before the cutter reaches the border.
TEST(Simulator, EntryIntoAPartWithABorder) {
  const tool::Tool tool = cutter(20e-3, 4, 0.0);
  const cutting::FractionalLaw law{5e6, 1.8e-5, 0.1, 0.3, 0.0};
  const cutting::MillingProcess process{rpm(10000), 1e-4, 0.02e-3, 20e-3,
                                        cutting::MillingDirection::down};
  simulation::SimulationOptions options;
  options.steps_per_tooth = 40;
  options.duration_s = 0.05;
  simulation::Workpiece part;
  part.border_x_m = 10e-3 + 2e-3;  // 2 mm gap: 0.03 s of approach at 4 m/min
  const auto result =
      simulation::simulate(tool, law, process, simulation::rigid_structure(), part, options);
  const double approach_s = 2e-3 / (4.0 / 60.0);
  EXPECT_GT(result.first_contact_s, approach_s);
  EXPECT_LT(result.first_contact_s, approach_s + 2.0 * 1.5e-3);
  for (std::size_t i = 0; i < result.size(); ++i) {
    if (result.time_s[i] < approach_s) {
      ASSERT_EQ(result.force_n[i].norm(), 0.0) << result.time_s[i];
    }
    ASSERT_LE(result.teeth_cutting[i], 1) << "phase Ia at " << result.time_s[i];
  }
}

// Loss of contact (002 Eq 27): in a violently unstable slot the cutter
// jumps out of the cut; chips ≤ 0 give no force, so there are instants with
// no tooth cutting (a stable slot with two teeth always has one in the
// material), and the run stays finite.
TEST(Simulator, NoForceFromNegativeChips) {
  const tool::Tool tool = cutter(10e-3, 2, 0.0);
  const cutting::LinearLaw law{6e8, 2e8, 0.0, 0.0, 0.0, 0.0};
  const cutting::MillingProcess process{rpm(10000), 0.1e-3, 6e-3, 10e-3,
                                        cutting::MillingDirection::down};
  // 6 mm on the benchmark's mode (DESIGN.md §5), about 10 x the slot's limit.
  const double k = 0.03993 * std::pow(2.0 * kPi * 922.0, 2);
  const auto structure = simulation::modal_structure(
      dynamics::ModalModel({dynamics::directional_mode(0, 922.0, 0.011, k)}));
  simulation::SimulationOptions options;
  options.steps_per_tooth = 60;
  options.start_angle_rad = kPi / 120.0;  // half a step: no tooth exactly at φ = 0
  options.duration_s = 0.3;
  const auto result =
      simulation::simulate(tool, law, process, structure, simulation::Workpiece{}, options);
  int idle = 0;
  for (std::size_t i = 0; i < result.size(); ++i) {
    ASSERT_TRUE(result.force_n[i].allFinite());
    if (result.teeth_cutting[i] == 0)
      ++idle;
  }
  EXPECT_GT(idle, static_cast<int>(result.size() / 20));
}

}  // namespace

}  // namespace test_simulator_cpp
