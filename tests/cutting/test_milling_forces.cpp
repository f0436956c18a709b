// The rigid-tool force model against closed-form results.

#include <gtest/gtest.h>

#include <string>

#include <cmath>
#include <iostream>
#include <numbers>

#include "robomill/cutting/average_forces.hpp"
#include "robomill/cutting/milling_forces.hpp"

namespace test_milling_forces_cpp {

namespace {

using namespace robomill;
using cutting::MillingDirection;
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// 001 Table 1 (Al7075-T6; read as Kac 19.1, Krc 1240.8, Ktc 1661.8 N/mm²,
// Kae 2.3, Kre 15.9, Kte 7.1 N/mm): every coefficient non-zero so each term
// of the average-force expressions is exercised.
const cutting::LinearLaw kAl7075{1661.8e6, 1240.8e6, 19.1e6, 7.1e3, 15.9e3, 2.3e3};

tool::Tool flat_tool(int teeth, double helix_deg, double diameter_m = 12e-3) {
  tool::ToolSpec spec;
  spec.diameter_m = diameter_m;
  spec.teeth = teeth;
  spec.helix_rad = helix_deg * kDeg;
  spec.overhang_m = 60e-3;
  return tool::Tool(spec);
}

cutting::MillingProcess process(double ae, MillingDirection direction, double fz = 0.05e-3,
                                double ap = 3e-3) {
  return {8200.0 * 2.0 * kPi / 60.0, fz, ap, ae, direction};
}

// Relative error of each component against the closed form; components that
// are almost zero are compared with the resultant instead.
void expect_close(const Eigen::Vector3d& simulated, const Eigen::Vector3d& closed, double tolerance,
                  const std::string& label) {
  const double scale = closed.norm();
  double worst = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double reference = std::max(std::abs(closed[c]), 0.01 * scale);
    worst = std::max(worst, std::abs(simulated[c] - closed[c]) / reference);
    EXPECT_LE(std::abs(simulated[c] - closed[c]), tolerance * reference)
        << label << " component "
        << "xyz"[c] << ": simulated " << simulated[c] << " N, closed form " << closed[c] << " N";
  }
  std::cout << "[validation] mean force vs Altintas closed form, " << label
            << ": worst relative error " << worst * 100.0 << " %\n";
}

struct MeanForceCase {
  double ae_over_d;
  MillingDirection direction;
  int teeth;
  double helix_deg;
};

class MeanForces : public ::testing::TestWithParam<MeanForceCase> {};

// Judged point of the foundation issue: time-averaged forces of the
// discretized model equal Altintas' closed-form averages (Manufacturing
// Automation Eq 2.51) within 0.5 % with a fine angular discretization.
TEST_P(MeanForces, MatchAltintasClosedForm) {
  const MeanForceCase c = GetParam();
  const tool::Tool cutter = flat_tool(c.teeth, c.helix_deg);
  const auto proc = process(c.ae_over_d * cutter.diameter_m(), c.direction);
  const int elements = cutting::default_axial_elements(cutter, proc.axial_depth_m);
  const cutting::MillingForceModel model(cutter, kAl7075, proc, elements);
  const auto series = cutting::sample_forces(model, {1, 2000}, 2);
  const auto stats = cutting::summarize(series, proc.spindle_rad_s);
  const Eigen::Vector3d closed = cutting::mean_force_n(
      kAl7075, c.teeth, proc.axial_depth_m, proc.feed_per_tooth_m, model.nominal_engagement());
  expect_close(stats.mean_n, closed, 0.005,
               "ae/D " + std::to_string(c.ae_over_d) +
                   (c.direction == MillingDirection::up ? " up" : " down"));
  // Mean torque = mean tangential force × R; its shear part is the chip
  // volume rate: Ktc fz ap ae N / (2π) per radian... checked via power:
  // P = Ktc · MRR + edge power, with MRR = ae ap fz N Ω / (2π).
  const double mrr = proc.radial_depth_m * proc.axial_depth_m * proc.feed_per_tooth_m * c.teeth *
                     proc.spindle_rad_s / (2.0 * kPi);
  const double engaged_arc =
      model.nominal_engagement().exit_rad - model.nominal_engagement().entry_rad;
  const double edge_power = kAl7075.Kte_n_per_m * proc.axial_depth_m * cutter.radius_m() *
                            proc.spindle_rad_s * c.teeth * engaged_arc / (2.0 * kPi);
  EXPECT_NEAR(stats.mean_power_w, kAl7075.Ktc_pa * mrr + edge_power,
              0.005 * (kAl7075.Ktc_pa * mrr + edge_power));
}

INSTANTIATE_TEST_SUITE_P(SlotAndPartialImmersion, MeanForces,
                         ::testing::Values(MeanForceCase{1.0, MillingDirection::down, 2, 0.0},
                                           MeanForceCase{1.0, MillingDirection::up, 3, 30.0},
                                           MeanForceCase{0.05, MillingDirection::down, 2, 30.0},
                                           MeanForceCase{0.05, MillingDirection::up, 2, 30.0},
                                           MeanForceCase{0.25, MillingDirection::down, 3, 45.0},
                                           MeanForceCase{0.25, MillingDirection::up, 3, 45.0},
                                           MeanForceCase{0.5, MillingDirection::down, 4, 45.0},
                                           MeanForceCase{0.5, MillingDirection::up, 4, 45.0},
                                           MeanForceCase{0.75, MillingDirection::down, 2, 60.0},
                                           MeanForceCase{0.75, MillingDirection::up, 2, 60.0}));

TEST(MeanForces, SlotFormulasWrittenOut) {
  // Altintas' slot averages typed independently of mean_force_matrix():
  //   F̄x = −N ap Krc fz/4 − N ap Kre/π,  F̄y = N ap Ktc fz/4 + N ap Kte/π,
  //   F̄z = −N ap Kac fz/π − N ap Kae/2   (Fz = −Fa on a cylindrical edge).
  const int teeth = 3;
  const double ap = 2e-3, fz = 0.08e-3;
  const cutting::LinearLaw& k = kAl7075;
  const Eigen::Vector3d expected(
      -teeth * ap * k.Krc_pa * fz / 4.0 - teeth * ap * k.Kre_n_per_m / kPi,
      teeth * ap * k.Ktc_pa * fz / 4.0 + teeth * ap * k.Kte_n_per_m / kPi,
      -teeth * ap * k.Kac_pa * fz / kPi - teeth * ap * k.Kae_n_per_m / 2.0);
  const Eigen::Vector3d closed = cutting::mean_force_n(k, teeth, ap, fz, {0.0, kPi});
  EXPECT_NEAR((closed - expected).norm(), 0.0, 1e-9 * expected.norm());

  const tool::Tool cutter = flat_tool(teeth, 30.0);
  const cutting::MillingForceModel model(cutter, k, process(12e-3, MillingDirection::down, fz, ap),
                                         200);
  const auto stats = cutting::summarize(cutting::sample_forces(model, {1, 3600}, 2), 1.0);
  expect_close(stats.mean_n, expected, 0.005, "slot");
}

TEST(InstantaneousForce, SingleStraightToothMatchesHandCalculation) {
  // One straight tooth at φ = 60° in a slot: Ft = (Ktc fz sin φ + Kte) ap,
  // Fx = −Ft cos φ − Fr sin φ, Fy = Ft sin φ − Fr cos φ, Fz = −Fa (002 Eq 29).
  const tool::Tool cutter = flat_tool(1, 0.0);
  const double ap = 2e-3, fz = 0.1e-3, phi = 60.0 * kDeg;
  const cutting::MillingForceModel model(cutter, kAl7075,
                                         process(12e-3, MillingDirection::down, fz, ap), 1);
  const auto load = model.at(phi);
  const cutting::LinearLaw& k = kAl7075;
  const double h = fz * std::sin(phi);
  const double ft = (k.Ktc_pa * h + k.Kte_n_per_m) * ap;
  const double fr = (k.Krc_pa * h + k.Kre_n_per_m) * ap;
  const double fa = (k.Kac_pa * h + k.Kae_n_per_m) * ap;
  EXPECT_NEAR(load.force_n.x(), -ft * std::cos(phi) - fr * std::sin(phi), 1e-9);
  EXPECT_NEAR(load.force_n.y(), ft * std::sin(phi) - fr * std::cos(phi), 1e-9);
  EXPECT_NEAR(load.force_n.z(), -fa, 1e-9);
  EXPECT_NEAR(load.torque_nm, ft * 6e-3, 1e-12);
  // Out of the cut (φ = 200°) the tooth exerts nothing.
  EXPECT_EQ(model.at(200.0 * kDeg).force_n.norm(), 0.0);
}

TEST(InstantaneousForce, EntryFullAndExitPhasesOfPaper004TableA1) {
  // 004 §4.1: D = 24 mm, 2 teeth, helix 60°, ap = 2 mm, ae = 4 mm, up milling.
  // The engaged edge length of one tooth grows linearly while its lag enters
  // the cut (entry phase), stays at ap (stabilization), then shrinks (off
  // stage): Table A1's integration limits. With only an edge coefficient the
  // torque is Kte·R·(engaged length), which exposes that length directly.
  tool::ToolSpec spec;
  spec.diameter_m = 24e-3;
  spec.teeth = 2;
  spec.helix_rad = kPi / 3.0;
  spec.overhang_m = 50e-3;
  const tool::Tool cutter(spec);
  const double radius = 12e-3, ap = 2e-3, ae = 4e-3;
  const cutting::LinearLaw edge_only{1e-9, 0.0, 0.0, 1000.0, 0.0, 0.0};
  const cutting::MillingForceModel model(
      cutter, edge_only, {1000.0 * 2.0 * kPi / 60.0, 0.12e-3, ap, ae, MillingDirection::up}, 4000);
  const double lag = ap * std::tan(kPi / 3.0) / radius;  // 16.5°
  const double exit = std::acos(1.0 - ae / radius);      // 48.2°
  ASSERT_LT(lag, exit);
  auto engaged_length = [&](double rotation) {
    return model.at(rotation).torque_nm / (1000.0 * radius);
  };
  const double per_radian = radius / std::tan(kPi / 3.0);  // engaged z per radian of rotation
  for (double fraction : {0.2, 0.5, 0.9}) {
    const double entry_angle = fraction * lag;
    EXPECT_NEAR(engaged_length(entry_angle), entry_angle * per_radian, 2e-6) << "entry phase";
    const double full_angle = lag + fraction * (exit - lag);
    EXPECT_NEAR(engaged_length(full_angle), ap, 2e-6) << "stabilization stage";
    const double off_angle = exit + fraction * lag;
    EXPECT_NEAR(engaged_length(off_angle), ap - (off_angle - exit) * per_radian, 2e-6)
        << "off stage";
  }
  EXPECT_NEAR(engaged_length(exit + lag + 0.01), 0.0, 1e-12);
}

TEST(InstantaneousForce, RunoutChipThicknessAndToothSkipping) {
  // Two straight teeth, slot, runout offset along tooth 0: at φ = 90° tooth 0
  // cuts h = fz + (r0 − r1) ≈ fz + 2ρ; when 2ρ > fz tooth 1 cuts nothing and
  // tooth 0 removes the material of both, h = 2 fz.
  const double fz = 0.05e-3, ap = 1e-3;
  for (double offset : {0.01e-3, 0.04e-3}) {
    tool::ToolSpec spec;
    spec.diameter_m = 10e-3;
    spec.teeth = 2;
    spec.overhang_m = 40e-3;
    spec.runout = {offset, 0.0};
    const tool::Tool cutter(spec);
    const cutting::LinearLaw shear_only{1000e6, 0.0, 0.0, 0.0, 0.0, 0.0};
    const cutting::MillingForceModel model(cutter, shear_only,
                                           {1000.0, fz, ap, 10e-3, MillingDirection::down}, 1);
    const double r0 = cutter.edge_radius_with_runout_m(0, 0.0);
    const double r1 = cutter.edge_radius_with_runout_m(1, 0.0);
    const double expected_tooth0 = std::min(fz + (r0 - r1), 2.0 * fz);
    const double expected_tooth1 = std::max(0.0, std::min(fz + (r1 - r0), 2.0 * fz));
    // Fy = Ft at φ = 90° (tooth 0 at 90°, tooth 1 at 270° is outside the slot).
    EXPECT_NEAR(model.at(kPi / 2.0).force_n.y() / (1000e6 * ap), expected_tooth0, 1e-12);
    EXPECT_NEAR(model.at(kPi / 2.0 + kPi).force_n.y() / (1000e6 * ap), expected_tooth1, 1e-12);
  }
}

TEST(InstantaneousForce, RunoutChipComesFromTheLeadingTooth) {
  // Three straight teeth, runout along tooth 2: edge j sits at θ + 2πj/3, so
  // tooth j + 1 passes a workpiece angle one tooth period before tooth j and
  // left the surface tooth j cuts: h_j = fz + r_j − r_{j+1} (tooth 1 cuts
  // behind the long tooth 2, tooth 2 behind the short tooth 0). Slot, φ = 90°.
  const double fz = 0.05e-3, ap = 1e-3, offset = 0.01e-3;
  tool::ToolSpec spec;
  spec.diameter_m = 10e-3;
  spec.teeth = 3;
  spec.overhang_m = 40e-3;
  spec.runout = {offset, 4.0 * kPi / 3.0};
  const tool::Tool cutter(spec);
  const cutting::LinearLaw shear_only{1000e6, 0.0, 0.0, 0.0, 0.0, 0.0};
  const cutting::MillingForceModel model(cutter, shear_only,
                                         {1000.0, fz, ap, 10e-3, MillingDirection::down}, 1);
  const double r[3] = {cutter.edge_radius_with_runout_m(0, 0.0),
                       cutter.edge_radius_with_runout_m(1, 0.0),
                       cutter.edge_radius_with_runout_m(2, 0.0)};
  ASSERT_GT(r[2], r[0] + 1e-6);
  for (int j = 0; j < 3; ++j) {
    // Tooth j at φ = 90°; the others sit at 210° and 330°, outside the slot's [0°, 180°].
    const double rotation = kPi / 2.0 - 2.0 * kPi * j / 3.0;
    const double expected = fz + r[j] - r[(j + 1) % 3];
    EXPECT_NEAR(model.at(rotation).force_n.y() / (1000e6 * ap), expected, 1e-12) << "tooth " << j;
  }
}

TEST(InstantaneousForce, BallEndAxialForceFromNormalComponents) {
  // A ball-end element at κ has radial force with an axial share cos κ
  // (001 Eq 11): with only Krc and one element, Fz / |Fxy| = cos κ / sin κ.
  tool::ToolSpec spec;
  spec.type = tool::ToolType::ball;
  spec.diameter_m = 8e-3;
  spec.teeth = 1;
  spec.overhang_m = 25e-3;
  const tool::Tool cutter(spec);
  const cutting::LinearLaw radial_only{1e-9, 1000e6, 0.0, 0.0, 0.0, 0.0};
  const double ap = 1e-3;  // one element, centred at half the arc (κ = acos(0.75)/2)
  const cutting::MillingForceModel model(cutter, radial_only,
                                         {1000.0, 0.1e-3, ap, 8e-3, MillingDirection::down}, 1);
  ASSERT_EQ(model.elements().size(), 1u);
  const double kappa = model.elements()[0].kappa_rad;
  EXPECT_NEAR(kappa, 0.5 * std::acos(0.75), 1e-12);
  const auto load = model.at(kPi / 2.0);
  EXPECT_NEAR(load.force_n.z() / load.force_n.head<2>().norm(), std::cos(kappa) / std::sin(kappa),
              1e-9);
  EXPECT_GT(load.force_n.z(), 0.0);  // the part pushes the ball nose up into the spindle
}

TEST(ForceSampling, ResultsDoNotDependOnThreadCount) {
  const tool::Tool cutter = flat_tool(3, 45.0);
  const cutting::MillingForceModel model(cutter, kAl7075, process(4e-3, MillingDirection::down),
                                         50);
  const auto one = cutting::sample_forces(model, {2, 100}, 1);
  const auto two = cutting::sample_forces(model, {2, 100}, 2);
  ASSERT_EQ(one.size(), 600u);
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one.force_n[i], two.force_n[i]);
    EXPECT_EQ(one.torque_nm[i], two.torque_nm[i]);
  }
  // Tooth-passing periodicity: the history repeats every tooth period.
  for (std::size_t i = 0; i + 100 < one.size(); ++i) {
    EXPECT_NEAR((one.force_n[i] - one.force_n[i + 100]).norm(), 0.0, 1e-9);
  }
}

}  // namespace

namespace {

// A ball-nose plunge (no lateral feed) with 004's size-dependent law: the
// law's mean chip is the axial feed's 2/π |fz,axial| (milling_forces.cpp),
// so the model exists and pushes the cutter back up its axis; a flat end
// mill's side edges (κ = π/2) have no chip and no force.
TEST(MillingForceModel, PlungeWithTheSizeDependentLawHasAChipFromTheAxialFeed) {
  const cutting::SizeDependentLaw law{387e6, -0.327, 0.0018, -0.224, 1e-3};
  tool::ToolSpec spec;
  spec.type = tool::ToolType::ball;
  spec.diameter_m = 10e-3;
  spec.teeth = 2;
  spec.helix_rad = 30.0 * kDeg;
  spec.overhang_m = 40e-3;
  cutting::GeneralEngagement plunge;
  plunge.spindle_rad_s = 1000.0;
  plunge.feed_per_tooth_m = 0.0;
  plunge.axial_feed_per_tooth_m = -0.05e-3;
  plunge.axial_depth_m = 2e-3;
  plunge.slice_top_m = {2e-3};
  plunge.arcs = {{{0.0, 2.0 * kPi}}};
  const cutting::MillingForceModel ball(tool::Tool(spec), law, plunge, 10);
  EXPECT_NEAR(ball.mean_chip_m(), 2.0 / kPi * 0.05e-3, 1e-15);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int k = 0; k < 360; ++k)
    mean += ball.at(2.0 * kPi * k / 360.0).force_n / 360.0;
  EXPECT_GT(std::abs(mean.z()), 10.0 * mean.head<2>().norm()) << mean.transpose();

  const cutting::MillingForceModel flat(flat_tool(2, 30.0, 10e-3), law, plunge, 10);
  for (int k = 0; k < 36; ++k)
    EXPECT_EQ(flat.at(2.0 * kPi * k / 36.0).force_n.norm(), 0.0);
}

// Issue 31, point 2: the bull nose between its limits. `robomill forces`
// (the straight-band model) for a corner radius of 0.001 mm gives the flat
// end mill's loads and for R − 0.001 mm the ball's, to 0.1 % (the issue's
// tolerance): mean force, the largest |F| over a revolution and the mean
// torque. Both models get the same number of axial elements, so what is
// compared is the edge geometry, not the discretization.
tool::Tool shaped_tool(tool::ToolType type, double corner_m) {
  tool::ToolSpec spec;
  spec.type = type;
  spec.diameter_m = 12e-3;
  spec.teeth = 3;
  spec.helix_rad = 30.0 * kDeg;
  spec.overhang_m = 50e-3;
  spec.corner_radius_m = corner_m;
  return tool::Tool(spec);
}

struct LoadFigures {
  Eigen::Vector3d mean;
  double peak = 0.0, torque = 0.0;
};

LoadFigures loads(const tool::Tool& tool, const cutting::MillingProcess& cut, int elements) {
  const cutting::MillingForceModel model(tool, kAl7075, cut, elements);
  const cutting::ForceSeries series = cutting::sample_forces(model, {1, 120}, 1);
  const cutting::ForceStatistics stats = cutting::summarize(series, cut.spindle_rad_s);
  LoadFigures figures{stats.mean_n, 0.0, stats.mean_torque_nm};
  for (const Eigen::Vector3d& f : series.force_n)
    figures.peak = std::max(figures.peak, f.norm());
  return figures;
}

void expect_same_loads(const LoadFigures& a, const LoadFigures& b, double tolerance,
                       const std::string& label) {
  EXPECT_LE((a.mean - b.mean).norm(), tolerance * b.mean.norm()) << label;
  EXPECT_NEAR(a.peak, b.peak, tolerance * b.peak) << label;
  EXPECT_NEAR(a.torque, b.torque, tolerance * std::abs(b.torque)) << label;
  std::cout << "[validation] bull nose vs " << label << ": mean force "
            << (a.mean - b.mean).norm() / b.mean.norm() * 100.0 << " %, peak "
            << std::abs(a.peak - b.peak) / b.peak * 100.0 << " %\n";
}

TEST(BullNose, CornerRadiusLimitsAreTheFlatAndTheBallEndMill) {
  const tool::Tool flat = shaped_tool(tool::ToolType::flat, 0.0);
  const tool::Tool ball = shaped_tool(tool::ToolType::ball, 0.0);
  const tool::Tool sharp = shaped_tool(tool::ToolType::bull, 0.001e-3);
  const tool::Tool round = shaped_tool(tool::ToolType::bull, 6e-3 - 0.001e-3);
  for (const double ap : {1.7e-3, 4.3e-3, 8.9e-3}) {
    for (const double ae : {12e-3, 3.1e-3}) {
      const cutting::MillingProcess cut = process(ae, MillingDirection::down, 0.05e-3, ap);
      const std::string label =
          "ap " + std::to_string(ap * 1e3) + " mm, ae " + std::to_string(ae * 1e3) + " mm";
      expect_same_loads(loads(sharp, cut, 600), loads(flat, cut, 600), 1e-3, "flat, " + label);
      expect_same_loads(loads(round, cut, 600), loads(ball, cut, 600), 1e-3, "ball, " + label);
    }
  }
}

// A slot shallower than the corner radius engages the torus corner alone,
// κ from 0 to κm = acos(1 − ap/r_c). With the linear law, h = fz sin φ sin κ,
// db = r_c dκ and r = R − r_c + r_c sin κ, the mean torque and axial force
// over a tooth period of a slot (φ over [0, π], ∫ sin φ dφ = 2) are
//   T = N r_c / 2π ∫ (2 Ktc fz sin κ + π Kte) r dκ
//   Fz = N r_c / 2π ∫ [(2 Krc fz sin κ + π Kre) cos κ − (2 Kac fz sin κ + π Kae) sin κ] dκ
// written out below; the model's elements approximate them to the midpoint
// rule's error (0.1 % asked).
TEST(BullNose, SlotInsideTheCornerMatchesTheClosedForm) {
  const double radius = 6e-3, corner = 2.5e-3, fz = 0.07e-3;
  const tool::Tool bull = shaped_tool(tool::ToolType::bull, corner);
  for (const double ap : {0.37e-3, 1.3e-3, 2.43e-3}) {
    const cutting::MillingProcess cut = process(12e-3, MillingDirection::down, fz, ap);
    const LoadFigures figures = loads(bull, cut, 400);
    const double km = std::acos(1.0 - ap / corner), inner = radius - corner;
    const double sin_int = 1.0 - std::cos(km);                     // ∫ sin κ
    const double sin2_int = 0.5 * km - 0.25 * std::sin(2.0 * km);  // ∫ sin² κ
    const double cos_int = std::sin(km);                           // ∫ cos κ
    const double sincos_int = 0.5 * std::sin(km) * std::sin(km);   // ∫ sin κ cos κ
    const double n = 3.0;
    const double torque = n * corner / (2.0 * kPi) *
                          (2.0 * kAl7075.Ktc_pa * fz * (inner * sin_int + corner * sin2_int) +
                           kPi * kAl7075.Kte_n_per_m * (inner * km + corner * sin_int));
    const double axial =
        n * corner / (2.0 * kPi) *
        (2.0 * kAl7075.Krc_pa * fz * sincos_int + kPi * kAl7075.Kre_n_per_m * cos_int -
         2.0 * kAl7075.Kac_pa * fz * sin2_int - kPi * kAl7075.Kae_n_per_m * sin_int);
    EXPECT_NEAR(figures.torque, torque, 1e-3 * torque) << "ap " << ap;
    EXPECT_NEAR(figures.mean.z(), axial, 1e-3 * std::abs(axial) + 1e-3 * figures.mean.norm())
        << "ap " << ap;
  }
}

}  // namespace

}  // namespace test_milling_forces_cpp
