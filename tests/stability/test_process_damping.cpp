// Process damping (000 Eq 18-19, 003 §3.1-3.2) and the multi-mode diagrams
// of the zero-order method.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "robomill/stability/process_damping.hpp"

namespace test_process_damping_cpp {

namespace rs = robomill::stability;
namespace rd = robomill::dynamics;
namespace rc = robomill::cutting;
namespace rt = robomill::tool;

namespace {

constexpr double pi = std::numbers::pi;
constexpr double rpm = 2.0 * pi / 60.0;
constexpr double kFn = 922.0, kZeta = 0.011, kMass = 0.03993;

double benchmark_stiffness() {
  const double wn = 2.0 * pi * kFn;
  return kMass * wn * wn;
}

rt::Tool flat_tool(double diameter, int teeth, double overhang) {
  rt::ToolSpec spec;
  spec.diameter_m = diameter;
  spec.teeth = teeth;
  spec.overhang_m = overhang;
  return rt::Tool(spec);
}

rc::MillingProcess cut(double ae) {
  rc::MillingProcess p;
  p.spindle_rad_s = 1000 * rpm;
  p.feed_per_tooth_m = 0.1e-3;
  p.radial_depth_m = ae;
  p.direction = rc::MillingDirection::down;
  return p;
}

rc::LinearLaw law(double kt, double kr) {
  rc::LinearLaw l;
  l.Ktc_pa = kt;
  l.Krc_pa = kr;
  return l;
}

// DESIGN.md §5 one-DOF benchmark in a slot (D = 10 mm, 2 teeth).
rs::RegenerativeModel benchmark_model() {
  return rs::RegenerativeModel(
      flat_tool(10e-3, 2, 30e-3), law(6e8, 2e8), cut(10e-3),
      rd::ModalModel({rd::directional_mode(0, kFn, kZeta, benchmark_stiffness())}));
}

}  // namespace

// 000 Eq 19 by hand: Ksp = 1.5e14 N/m³, w = 40 µm, dz = 1 mm, D = 12 mm at
// 10 000 rpm: v = 2π · 0.006 · 10000/60 = 6.2832 m/s,
// C_eq = 1.5e14 · (40e-6)² · 1e-3 / (4 · 6.2832) = 240e-3 / 25.1327 = 9.5493 N·s/m.
TEST(ProcessDamping, EquivalentDampingMatchesEq19ByHand) {
  const double v = 2.0 * pi * 0.006 * 10000.0 / 60.0;
  EXPECT_NEAR(v, 6.28319, 1e-5);
  EXPECT_NEAR(rs::equivalent_damping_n_s_per_m(1.5e14, 40e-6, 1e-3, v), 9.5493, 1e-4);
  // Linear in the width and the wear land squared, inverse in the speed.
  EXPECT_NEAR(rs::equivalent_damping_n_s_per_m(1.5e14, 80e-6, 2e-3, 2.0 * v), 4.0 * 9.5493, 4e-4);
  EXPECT_THROW(rs::equivalent_damping_n_s_per_m(1.5e14, 40e-6, 1e-3, 0.0), std::invalid_argument);
}

// The energy balance (EB) of the header: the linear-equivalent coefficient
// times [sin(β/2)/(β/2)]², β = 2π w/λ; Eq 19 when the land is short against
// the wavelength, zero when it spans whole wavelengths, and the numerical
// quadrature (used with a clearance angle) agrees with the closed form.
TEST(ProcessDamping, EnergyBalanceCoefficient) {
  const double ksp = 1.5e14, w = 40e-6, b = 1e-3, v = 1.0;
  const double linear = rs::equivalent_damping_n_s_per_m(ksp, w, b, v);
  // λ = v / f_c: 1 Hz → λ = 1 m ≫ w.
  EXPECT_NEAR(rs::energy_balance_damping_n_s_per_m(ksp, w, b, v, 1.0), linear, 1e-8 * linear);
  // β = π (λ = 2w): sinc²(π/2) = 4/π².
  const double f_half = v / (2.0 * w);
  EXPECT_NEAR(rs::energy_balance_damping_n_s_per_m(ksp, w, b, v, f_half), linear * 4.0 / (pi * pi),
              1e-9 * linear);
  // β = 2π: the land covers one wavelength and dissipates nothing on average.
  EXPECT_NEAR(rs::energy_balance_damping_n_s_per_m(ksp, w, b, v, v / w), 0.0, 1e-9 * linear);
  // Quadrature with a negligible clearance angle against the closed form.
  for (double f : {0.2 * f_half, f_half, 1.5 * f_half}) {
    const double closed = rs::energy_balance_damping_n_s_per_m(ksp, w, b, v, f);
    const double quadrature = rs::energy_balance_damping_n_s_per_m(ksp, w, b, v, f, 1e-12, 10e-6);
    EXPECT_NEAR(quadrature, closed, 2e-3 * linear) << f;
  }
  // A clearance angle reduces the indentation (less damping) and makes it
  // depend on the amplitude: larger vibrations indent more, relatively.
  const double f = 0.2 * f_half;
  const double flat = rs::energy_balance_damping_n_s_per_m(ksp, w, b, v, f);
  const double small = rs::energy_balance_damping_n_s_per_m(ksp, w, b, v, f, 0.05, 1e-6);
  const double large = rs::energy_balance_damping_n_s_per_m(ksp, w, b, v, f, 0.05, 20e-6);
  EXPECT_LT(small, large);
  EXPECT_LT(large, flat);
}

// Slot, straight flutes: C_p = (N c / 4) [[1, μ], [−μ, 1]] from
// (N/2π) c ∫_0^π (n − μ t) nᵀ dφ with ∫ s² = ∫ c² = π/2, ∫ sc = 0; and the
// mode along x gains Δζ = C_xx / (2 m ωn).
TEST(ProcessDamping, SlotDampingMatrixAndModalDamping) {
  const rs::RegenerativeModel model = benchmark_model();
  rs::ProcessDamping params;  // 000's values: Ksp 1.5e14, w 40 µm, μ 0.3
  const double speed = 3000 * rpm, depth = 2e-3;
  const Eigen::Matrix3d c = rs::process_damping_matrix(model, params, speed, depth, 900.0);
  const double per_edge =
      rs::equivalent_damping_n_s_per_m(1.5e14, 40e-6, depth, 0.005 * speed);  // v = R Ω
  Eigen::Matrix3d expected = Eigen::Matrix3d::Zero();
  expected << 1.0, 0.3, 0, -0.3, 1.0, 0, 0, 0, 0;
  expected *= 2.0 * per_edge / 4.0;
  EXPECT_LT((c - expected).norm(), 1e-9 * expected.norm()) << c;

  const rd::Mode& mode = model.modes().modes()[0];
  EXPECT_NEAR(rs::mode_process_damping_n_s_per_m(c, mode), expected(0, 0), 1e-9 * expected(0, 0));
  const rd::ModalModel damped = rs::with_added_damping(model.modes(), c);
  const double wn = 2.0 * pi * kFn;
  EXPECT_NEAR(damped.modes()[0].damping_ratio, kZeta + expected(0, 0) / (2.0 * kMass * wn), 1e-12);
  EXPECT_NEAR(rs::process_damped_modes(model, params, speed, depth, 900.0).modes()[0].damping_ratio,
              damped.modes()[0].damping_ratio, 1e-15);
}

// 003 §1 / 000 §3: process damping matters at low cutting speed. 1-DOF
// benchmark in a slot, w = 10 µm: the limit rises by half at 1000 rpm and by
// about 1 % at 20 000 rpm; with 000's 40 µm land the 1000 rpm cut is stable
// over the whole depth range.
TEST(ProcessDamping, RaisesTheLowSpeedLimitFarMoreThanTheHighSpeedLimit) {
  const rs::RegenerativeModel model = benchmark_model();
  const std::vector<double> speeds = {1000 * rpm, 20000 * rpm};
  rs::ProcessDamping params;
  params.wear_land_m = 10e-6;
  const auto base = rs::process_damped_limits(model, std::nullopt, speeds);
  const auto damped = rs::process_damped_limits(model, params, speeds);
  for (int i = 0; i < 2; ++i) {
    ASSERT_TRUE(base[i].limited && damped[i].limited && damped[i].converged);
  }
  const double low = damped[0].depth_limit_m / base[0].depth_limit_m;
  const double high = damped[1].depth_limit_m / base[1].depth_limit_m;
  EXPECT_GT(low, 1.3);
  EXPECT_GT(high, 1.0);
  EXPECT_LT(high, 1.03);
  std::printf(
      "[          ] w = 10 um: 1000 rpm %.4f -> %.4f mm (x%.3f, %d evaluations), "
      "20000 rpm %.4f -> %.4f mm (x%.4f)\n",
      base[0].depth_limit_m * 1e3, damped[0].depth_limit_m * 1e3, low, damped[0].iterations,
      base[1].depth_limit_m * 1e3, damped[1].depth_limit_m * 1e3, high);

  params.wear_land_m = 40e-6;
  params.model = rs::ProcessDampingModel::energy_balance;
  const auto worn = rs::process_damped_limits(model, params, speeds);
  EXPECT_FALSE(worn[0].limited);
  EXPECT_EQ(worn[0].depth_limit_m, 30e-3);  // depth_max = the overhang
  EXPECT_TRUE(worn[1].limited);
}

// The returned depth is a fixed point: the ZOA limit of the structure damped
// as it would be at that depth and chatter frequency is that depth.
TEST(ProcessDamping, IterationEndsAtAFixedPoint) {
  const rs::RegenerativeModel model = benchmark_model();
  rs::ProcessDamping params;
  params.wear_land_m = 15e-6;
  params.model = rs::ProcessDampingModel::energy_balance;
  for (double n : {1500.0, 2500.0, 6000.0}) {
    const auto r = rs::process_damped_limits(model, params, {n * rpm});
    ASSERT_TRUE(r[0].limited && r[0].converged) << n;
    const rd::ModalModel damped = rs::process_damped_modes(
        model, params, n * rpm, r[0].depth_limit_m, r[0].chatter_frequency_hz);
    const rs::ZeroOrderSolver check(rs::mean_cutting_stiffness_per_depth(model), 2, damped,
                                    rs::ZeroOrderOptions{.depth_max_m = 30e-3});
    const rs::ZeroOrderLimit again = check.limit(n * rpm);
    EXPECT_NEAR(again.depth_limit_m, r[0].depth_limit_m, 1e-3 * r[0].depth_limit_m) << n;
    EXPECT_NEAR(again.chatter_frequency_hz, r[0].chatter_frequency_hz, 1e-2) << n;
  }
}

// Without process damping the coupled diagram is the plain ZOA solver's.
TEST(ProcessDamping, NoDampingGivesThePlainZeroOrderLimits) {
  const rs::RegenerativeModel model = benchmark_model();
  std::vector<double> speeds;
  for (int i = 0; i < 50; ++i)
    speeds.push_back((3000.0 + 400.0 * i) * rpm);
  const auto plain = rs::ZeroOrderSolver(model).limits(speeds);
  const auto coupled = rs::process_damped_limits(model, std::nullopt, speeds);
  for (std::size_t i = 0; i < speeds.size(); ++i) {
    EXPECT_EQ(plain[i].depth_limit_m, coupled[i].depth_limit_m);
    EXPECT_EQ(coupled[i].iterations, 1);
  }
}

// A0 handed over (the stability band's shared basis) replaces the model's
// own average: the same A0 gives the same limits to the bit, and an A0 twice
// as large halves every limit (ap = 1/(2 Re λ), λ an eigenvalue of A0 G).
TEST(ProcessDamping, GivenMeanStiffnessIsTheOneUsed) {
  const rs::RegenerativeModel model = benchmark_model();
  std::vector<double> speeds;
  for (int i = 0; i < 23; ++i)
    speeds.push_back((3130.0 + 517.0 * i) * rpm);
  const Eigen::Matrix3d a0 = rs::mean_cutting_stiffness_per_depth(model);
  const auto own = rs::process_damped_limits(model, std::nullopt, speeds);
  rs::ProcessDampedOptions given_a0;
  given_a0.mean_stiffness_per_depth.emplace(a0);
  const auto given = rs::process_damped_limits(model, std::nullopt, speeds, given_a0);
  rs::ProcessDampedOptions doubled_a0;
  doubled_a0.mean_stiffness_per_depth.emplace(2.0 * a0);
  const auto doubled = rs::process_damped_limits(model, std::nullopt, speeds, doubled_a0);
  int limited = 0;
  for (std::size_t i = 0; i < speeds.size(); ++i) {
    EXPECT_EQ(given[i].depth_limit_m, own[i].depth_limit_m);
    if (!own[i].limited || !doubled[i].limited)
      continue;
    ++limited;
    EXPECT_NEAR(doubled[i].depth_limit_m, 0.5 * own[i].depth_limit_m, 1e-9 * own[i].depth_limit_m);
  }
  EXPECT_GT(limited, 15);
}

// Modes in orthogonal directions (x, y) that A0 does not couple (A0 diagonal):
// A0 G is diagonal, so the coupled eigenvalues are the single-mode ones and
// the envelope of the one-mode diagrams equals the coupled diagram.
TEST(MultiMode, EnvelopeEqualsCoupledWhenAZeroDoesNotCoupleTheModes) {
  const double k = benchmark_stiffness();
  const rd::ModalModel modes(
      {rd::directional_mode(0, kFn, kZeta, k), rd::directional_mode(1, 1.37 * kFn, 0.02, 0.8 * k)});
  Eigen::Matrix3d a0 = Eigen::Matrix3d::Zero();
  a0(0, 0) = -1e8;
  a0(1, 1) = -0.7e8;
  std::vector<double> speeds;
  for (int i = 0; i < 400; ++i)
    speeds.push_back((4000.0 + 60.0 * i) * rpm);
  rs::ZeroOrderOptions options;
  options.depth_max_m = 20e-3;
  const auto coupled = rs::ZeroOrderSolver(a0, 2, modes, options).limits(speeds);
  const auto envelope = rs::envelope_limits(a0, 2, modes, speeds, options);
  int from_each[2] = {0, 0};
  double worst = 0.0;
  for (std::size_t i = 0; i < speeds.size(); ++i) {
    ASSERT_TRUE(coupled[i].limited && envelope[i].limited);
    worst = std::max(worst, std::abs(envelope[i].depth_limit_m / coupled[i].depth_limit_m - 1.0));
    ++from_each[envelope[i].mode];
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(from_each[0], 0);  // both modes govern somewhere
  EXPECT_GT(from_each[1], 0);

  // With a cross-coupling A0 (Kt ≠ 0 in a slot) the diagrams differ: the
  // check above is not vacuous.
  a0(0, 1) = -3e8;
  a0(1, 0) = 3e8;
  const auto coupled2 = rs::ZeroOrderSolver(a0, 2, modes, options).limits(speeds);
  const auto envelope2 = rs::envelope_limits(a0, 2, modes, speeds, options);
  double largest = 0.0;
  for (std::size_t i = 0; i < speeds.size(); ++i) {
    largest =
        std::max(largest, std::abs(envelope2[i].depth_limit_m / coupled2[i].depth_limit_m - 1.0));
  }
  EXPECT_GT(largest, 0.05);
}

// 003 §3.3 (Tab. 1 modes marked *, D 12 mm, 2 teeth, Ktc 1600, Krc 600 MPa,
// half immersion down milling): process damping suppresses the tool modes at
// low speed, so there the robot modes govern the envelope; at high speed the
// tool modes still do. K_d, w, μ from 000 (003 gives none).
TEST(MultiMode, RobotModesGovernTheProcessDampedEnvelopeAtLowSpeed) {
  const rd::ModalModel modes({rd::directional_mode(0, 19.88, 0.0081, 3.65e6),
                              rd::directional_mode(0, 77.17, 0.0515, 5.00e6),
                              rd::directional_mode(0, 4850.0, 0.0315, 4.46e6),
                              rd::directional_mode(1, 17.8, 0.0176, 2.31e6),
                              rd::directional_mode(1, 47.3, 0.0074, 33.6e6),
                              rd::directional_mode(1, 4170.0, 0.0072, 2.85e6)});
  const rs::RegenerativeModel model(flat_tool(12e-3, 2, 50e-3), law(1600e6, 600e6), cut(6e-3),
                                    modes);
  const std::vector<double> speeds = {1500 * rpm, 6000 * rpm};
  rs::ProcessDampedOptions options;
  options.method = rs::MultiModeMethod::envelope;
  options.zero_order.depth_max_m = 10e-3;
  const auto plain = rs::process_damped_limits(model, std::nullopt, speeds, options);
  const auto damped = rs::process_damped_limits(model, rs::ProcessDamping{}, speeds, options);
  auto is_tool = [](int mode) { return mode == 2 || mode == 5; };
  EXPECT_TRUE(is_tool(plain[0].mode)) << plain[0].mode;
  EXPECT_FALSE(is_tool(damped[0].mode)) << damped[0].mode;
  EXPECT_TRUE(is_tool(damped[1].mode)) << damped[1].mode;
  EXPECT_LT(damped[0].chatter_frequency_hz, 100.0);
  EXPECT_GT(damped[1].chatter_frequency_hz, 4000.0);
  for (const auto& r : damped)
    EXPECT_TRUE(r.converged);
  std::printf(
      "[          ] 1500 rpm: %.3f mm (mode %d) -> %.3f mm (mode %d, %.1f Hz); "
      "6000 rpm: %.3f mm -> %.3f mm (mode %d, %.0f Hz)\n",
      plain[0].depth_limit_m * 1e3, plain[0].mode, damped[0].depth_limit_m * 1e3, damped[0].mode,
      damped[0].chatter_frequency_hz, plain[1].depth_limit_m * 1e3, damped[1].depth_limit_m * 1e3,
      damped[1].mode, damped[1].chatter_frequency_hz);
}

}  // namespace test_process_damping_cpp
