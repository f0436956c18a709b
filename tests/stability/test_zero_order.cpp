// Zero-order (Altintas–Budak) stability: the derivation's identities, the
// one-DOF benchmark in closed form, and the characteristic-equation residual.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "robomill/stability/zero_order.hpp"

namespace test_zero_order_cpp {

namespace rs = robomill::stability;
namespace rd = robomill::dynamics;
namespace rc = robomill::cutting;
namespace rt = robomill::tool;

namespace {

constexpr double pi = std::numbers::pi;
constexpr double rpm = 2.0 * pi / 60.0;

// DESIGN.md §5 benchmark: 2 teeth, Kt = 6e8, Kn = 2e8 N/m², fn = 922 Hz,
// ζ = 0.011, m = 0.03993 kg along x; D = 10 mm, slot, down milling.
constexpr double kKt = 6e8, kKr = 2e8, kFn = 922.0, kZeta = 0.011, kMass = 0.03993;

double benchmark_stiffness() {
  const double wn = 2.0 * pi * kFn;
  return kMass * wn * wn;
}

rt::Tool flat_tool(double helix_deg = 0.0, int teeth = 2, double diameter = 10e-3) {
  rt::ToolSpec spec;
  spec.type = rt::ToolType::flat;
  spec.diameter_m = diameter;
  spec.teeth = teeth;
  spec.helix_rad = helix_deg * pi / 180.0;
  spec.overhang_m = 30e-3;
  return rt::Tool(spec);
}

rc::MillingProcess cut(double ae, rc::MillingDirection direction = rc::MillingDirection::down) {
  rc::MillingProcess p;
  p.spindle_rad_s = 10000 * rpm;
  p.feed_per_tooth_m = 0.1e-3;
  p.radial_depth_m = ae;
  p.direction = direction;
  return p;
}

rc::LinearLaw benchmark_law() {
  rc::LinearLaw law;
  law.Ktc_pa = kKt;
  law.Krc_pa = kKr;
  return law;
}

rd::ModalModel benchmark_modes() {
  return rd::ModalModel({rd::directional_mode(0, kFn, kZeta, benchmark_stiffness())});
}

rs::RegenerativeModel benchmark_model() {
  return rs::RegenerativeModel(flat_tool(), benchmark_law(), cut(10e-3), benchmark_modes());
}

std::vector<double> speeds(double from_rpm, double to_rpm, int count) {
  std::vector<double> out;
  for (int i = 0; i < count; ++i)
    out.push_back((from_rpm + (to_rpm - from_rpm) * i / (count - 1)) * rpm);
  return out;
}

}  // namespace

// A0 of a straight-flute slot, (N/2π) ∫_0^π W dφ, in closed form:
// W_xx = −Kt sc − Kr s², W_xy = −Kt c² − Kr sc, W_yx = Kt s² − Kr sc,
// W_yy = Kt sc − Kr c²  ⇒  A0 = (N/4) [[−Kr, −Kt], [Kt, −Kr]].
TEST(ZeroOrder, MeanStiffnessOfStraightSlotMatchesClosedForm) {
  const Eigen::Matrix3d a0 = rs::mean_cutting_stiffness_per_depth(benchmark_model());
  Eigen::Matrix3d expected = Eigen::Matrix3d::Zero();
  expected << -kKr, -kKt, 0, kKt, -kKr, 0, 0, 0, 0;
  expected *= 2.0 / 4.0;
  EXPECT_LT((a0 - expected).norm(), 1e-6 * expected.norm()) << a0;
  EXPECT_NEAR(a0(0, 0), -2.0 * kKr / 4.0, 1e-6 * kKr) << "α_xx = −N Kr / 4";
}

// The period average does not depend on the helix: a helical flat end mill's
// A0 per unit depth equals the straight-flute one (half immersion, up milling).
TEST(ZeroOrder, HelicalFlatEndMillHasTheStraightFluteAverage) {
  const rd::ModalModel modes = benchmark_modes();
  const rs::RegenerativeModel straight(flat_tool(0.0, 3), benchmark_law(),
                                       cut(5e-3, rc::MillingDirection::up), modes);
  const rs::RegenerativeModel helical(flat_tool(30.0, 3), benchmark_law(),
                                      cut(5e-3, rc::MillingDirection::up), modes);
  const Eigen::Matrix3d a = rs::mean_cutting_stiffness_per_depth(straight);
  const Eigen::Matrix3d b = rs::mean_cutting_stiffness_per_depth(helical, 4096, 4e-3);
  const Eigen::Matrix3d c = rs::mean_cutting_stiffness_per_depth(helical, 4096, 12e-3);
  EXPECT_LT((a - b).norm(), 2e-3 * a.norm());
  EXPECT_LT((a - c).norm(), 2e-3 * a.norm());
}

// A0 is linear in the shear coefficients (000 Eq 14), so the basis of a cut
// gives the A0 of any coefficients: a helical ball-end mill (A0 has a third
// column) at 0.37 of its radial capacity in up milling, coefficients nobody
// rounded, Kac included, at the default and at an odd reference depth. The
// same terms are summed in another order, so they agree to round-off
// (1e-13 relative), not to the bit.
TEST(ZeroOrder, BasisGivesTheMeanStiffnessOfAnyCoefficients) {
  rt::ToolSpec spec;
  spec.type = rt::ToolType::ball;
  spec.diameter_m = 10e-3;
  spec.teeth = 3;
  spec.helix_rad = 27.0 * pi / 180.0;
  spec.overhang_m = 31e-3;
  const rt::Tool tool(spec);
  const rc::MillingProcess process = cut(3.7e-3, rc::MillingDirection::up);
  for (const double reference_depth_m : {0.0, 2.93e-3}) {
    const rs::RegenerativeModel reference(tool, benchmark_law(), process, benchmark_modes());
    const rs::MeanCuttingStiffnessBasis basis =
        rs::mean_cutting_stiffness_basis(reference, 4096, reference_depth_m);
    for (const auto& [ktc, krc, kac] :
         {std::array{6.13e8, 2.21e8, 0.0}, std::array{1.7392e9, 4.48e8, 1.37e8},
          std::array{3.3e8, 0.0, 0.6e8}}) {
      rc::LinearLaw law;
      law.Ktc_pa = ktc;
      law.Krc_pa = krc;
      law.Kac_pa = kac;
      const rs::RegenerativeModel model(tool, law, process, benchmark_modes());
      const Eigen::Matrix3d direct =
          rs::mean_cutting_stiffness_per_depth(model, 4096, reference_depth_m);
      const Eigen::Matrix3d from_basis = basis(law);
      EXPECT_GT(direct.col(2).norm(), 0.0) << "a ball end's A0 has an axial column";
      EXPECT_LT((from_basis - direct).norm(), 1e-13 * direct.norm())
          << "Ktc " << ktc << ", reference depth " << reference_depth_m << "\n"
          << from_basis << "\nagainst\n"
          << direct;
    }
  }
}

// Eq (2)-(3) of the header on a hand-made λ: ap (1 − e^{−iωτ}) λ = 1.
TEST(ZeroOrder, DepthAndPhaseFormulasSolveTheScalarEquation) {
  for (const std::complex<double> lambda :
       {std::complex<double>(2.0, 1.0), {3.0, -4.0}, {0.5, 0.01}, {1e-3, -7.0}}) {
    const double depth = 0.5 / lambda.real();
    const double eps = pi + 2.0 * std::atan(lambda.imag() / lambda.real());
    for (int k = 0; k < 3; ++k) {
      const double phase = eps + 2.0 * pi * k;
      const std::complex<double> lhs =
          depth * (1.0 - std::exp(std::complex<double>(0.0, -phase))) * lambda;
      EXPECT_NEAR(std::abs(lhs - 1.0), 0.0, 1e-10) << lambda << " k=" << k;
    }
  }
}

// det[I − ap (1 − e^{−iωτ}) A0 G(ω)] vanishes at every returned point, and
// not at a depth 2 % away (the check can fail). Two modes (x and y) with
// different frequencies, half immersion down milling: A0 couples x and y.
TEST(ZeroOrder, CharacteristicDeterminantVanishesAtReturnedPoints) {
  const double k = benchmark_stiffness();
  const rd::ModalModel modes(
      {rd::directional_mode(0, kFn, kZeta, k), rd::directional_mode(1, 1.3 * kFn, 0.02, 1.5 * k)});
  const rs::RegenerativeModel model(flat_tool(), benchmark_law(), cut(5e-3), modes);
  rs::ZeroOrderOptions options;
  options.depth_max_m = 20e-3;
  const rs::ZeroOrderSolver solver(model, options);
  EXPECT_EQ(solver.branches(), 2);  // flat tool: the 2x2 reduction
  const auto limits = solver.limits(speeds(3000, 30000, 301));
  int checked = 0;
  double worst = 0.0;
  for (const rs::ZeroOrderLimit& p : limits) {
    ASSERT_TRUE(p.limited) << p.spindle_rad_s / rpm;
    const double omega = 2.0 * pi * p.chatter_frequency_hz;
    const double tau = 2.0 * pi / (2.0 * p.spindle_rad_s);
    const Eigen::Matrix3cd g = modes.receptance(omega);
    const double residual = std::abs(rs::characteristic_determinant(
        solver.mean_stiffness_per_depth(), g, p.depth_limit_m, omega, tau));
    worst = std::max(worst, residual);
    const double off = std::abs(rs::characteristic_determinant(solver.mean_stiffness_per_depth(), g,
                                                               1.02 * p.depth_limit_m, omega, tau));
    EXPECT_GT(off, 1e-3) << p.spindle_rad_s / rpm;
    ++checked;
  }
  EXPECT_EQ(checked, 301);
  EXPECT_LT(worst, 1e-9);
  std::printf("[          ] max |det| at 301 returned points: %.3g\n", worst);
}

// 1-DOF along x in a slot: λ = A0_xx G_xx with A0_xx = −N Kr/4 and
// G_xx = 1/(k(1 − r² + 2iζr)), so ap = 1/(2 Re λ) = −2/(N Kr Re G), which is
// smallest where Re G is most negative, at r² = 1 + 2ζ:
//   min Re G = −1/(4kζ(1+ζ))  ⇒  a_lim,min = 8 k ζ (1+ζ) / (N Kr),
// with chatter at ωn √(1+2ζ), just above fn.
TEST(ZeroOrder, OneDofBenchmarkAbsoluteLimitMatchesClosedForm) {
  const rs::ZeroOrderSolver solver(benchmark_model());
  const double alpha = solver.mean_stiffness_per_depth()(0, 0);
  EXPECT_NEAR(alpha, -2.0 * kKr / 4.0, 1e-6 * 1e8);
  const double k = benchmark_stiffness();
  const double closed = 1.0 / (2.0 * std::abs(alpha) / (4.0 * k * kZeta * (1.0 + kZeta)));
  EXPECT_NEAR(closed, 8.0 * k * kZeta * (1 + kZeta) / (2.0 * kKr), 1e-12);

  const rs::ZeroOrderLimit minimum = solver.minimum_limit();
  ASSERT_TRUE(minimum.limited);
  EXPECT_NEAR(minimum.depth_limit_m, closed, 1e-6 * closed);
  EXPECT_NEAR(minimum.chatter_frequency_hz, kFn * std::sqrt(1 + 2 * kZeta), 1e-3);

  // The minimum over a dense sweep of speeds reaches it within 1 %.
  const auto limits = solver.limits(speeds(2000, 30000, 20001));
  const auto lowest = std::min_element(limits.begin(), limits.end(), [](auto& a, auto& b) {
    return a.depth_limit_m < b.depth_limit_m;
  });
  EXPECT_NEAR(lowest->depth_limit_m, closed, 0.01 * closed);
  EXPECT_GE(lowest->depth_limit_m, closed * (1 - 1e-9));
  EXPECT_GT(lowest->chatter_frequency_hz, kFn);
  EXPECT_LT(lowest->chatter_frequency_hz, 1.02 * kFn);
  std::printf(
      "[          ] a_lim,min closed form %.6f mm, minimum_limit %.6f mm at %.3f Hz, "
      "sweep min %.6f mm at %.1f rpm, %.3f Hz\n",
      closed * 1e3, minimum.depth_limit_m * 1e3, minimum.chatter_frequency_hz,
      lowest->depth_limit_m * 1e3, lowest->spindle_rad_s / rpm, lowest->chatter_frequency_hz);
}

// Along one lobe the limit dips to its minimum where the chatter frequency is
// just above fn; at the lobe's minimum for lobe k the speed is
// 2π ω_c / (N (ε + 2πk)), ε = π + 2 arg λ.
TEST(ZeroOrder, LobeMinimumChattersJustAboveTheNaturalFrequency) {
  const rs::ZeroOrderSolver solver(benchmark_model());
  for (int lobe = 0; lobe < 4; ++lobe) {
    // Speeds bracketing lobe `lobe`: chatter ≈ fn, tooth period τ ≈ (ε + 2πk)/ω.
    const double center_rpm = 60.0 * kFn / (2.0 * (lobe + 0.75));
    const auto limits = solver.limits(speeds(0.8 * center_rpm, 1.25 * center_rpm, 2001));
    const auto lowest = std::min_element(limits.begin(), limits.end(), [&](auto& a, auto& b) {
      return (a.lobe == lobe ? a.depth_limit_m : 1.0) < (b.lobe == lobe ? b.depth_limit_m : 1.0);
    });
    ASSERT_EQ(lowest->lobe, lobe);
    EXPECT_GT(lowest->chatter_frequency_hz, kFn) << lobe;
    EXPECT_LT(lowest->chatter_frequency_hz, kFn * (1 + 2 * kZeta)) << lobe;
    // Lobe k's speeds lie below 60 f_c / (N k) and above 60 f_c / (N (k + 1)).
    const double n_rpm = lowest->spindle_rad_s / rpm;
    EXPECT_LT(n_rpm, 60.0 * lowest->chatter_frequency_hz / (2.0 * lobe));
    EXPECT_GT(n_rpm, 60.0 * lowest->chatter_frequency_hz / (2.0 * (lobe + 1)));
  }
}

// A measured FRF plugs in as a callable; the same receptance gives the same
// limits (to round-off: the modal solver sums its per-mode 2x2 products, the
// callable's solver multiplies the 3x3 receptance by A0); a depth range below
// every curve gives "not limited".
TEST(ZeroOrder, AnyFrfCallableAndDepthRange) {
  const rs::RegenerativeModel model = benchmark_model();
  const rd::ModalModel modes = benchmark_modes();
  int calls = 0;
  rs::Frf frf = [&](double w) {
    ++calls;
    return modes.receptance(w);
  };
  const rs::ZeroOrderSolver a(model);
  const rs::ZeroOrderSolver b(model, frf, rs::modal_peaks(modes));
  EXPECT_GT(calls, 1000);
  const auto sweep = speeds(5000, 25000, 41);
  const auto la = a.limits(sweep), lb = b.limits(sweep);
  for (std::size_t i = 0; i < sweep.size(); ++i) {
    EXPECT_NEAR(la[i].depth_limit_m, lb[i].depth_limit_m, 1e-12 * lb[i].depth_limit_m);
    EXPECT_NEAR(la[i].chatter_frequency_hz, lb[i].chatter_frequency_hz,
                1e-12 * lb[i].chatter_frequency_hz);
  }
  rs::ZeroOrderOptions shallow;
  shallow.depth_max_m = 0.2e-3;  // below the absolute limit (0.298 mm)
  const rs::ZeroOrderSolver c(model, shallow);
  for (const auto& p : c.limits(sweep)) {
    EXPECT_FALSE(p.limited);
    EXPECT_EQ(p.depth_limit_m, 0.2e-3);
    EXPECT_EQ(p.chatter_frequency_hz, 0.0);
  }
  EXPECT_THROW(a.limit(0.0), std::invalid_argument);
}

// Many speeds are cheap once the curves exist (no pass/fail timing: report).
TEST(ZeroOrder, ManySpeedsFromPrecomputedCurves) {
  const rs::ZeroOrderSolver solver(benchmark_model());
  const auto limits = solver.limits(speeds(1000, 40000, 5000));
  int limited = 0;
  for (const auto& p : limits)
    limited += p.limited ? 1 : 0;
  EXPECT_EQ(limited, 5000);
}

// A ball-end mill's chip normal has a z component, so A0 has a non-zero third
// column and the solver takes the 3x3 eigenvalue path; the residual of (1)
// still vanishes at the returned points (A0 linearized at the reference depth).
TEST(ZeroOrder, BallEndMillUsesTheFullEigenproblem) {
  rt::ToolSpec spec;
  spec.type = rt::ToolType::ball;
  spec.diameter_m = 10e-3;
  spec.teeth = 2;
  spec.helix_rad = 30.0 * pi / 180.0;
  spec.overhang_m = 30e-3;
  rc::LinearLaw l = benchmark_law();
  l.Kac_pa = 1e8;
  const double k = benchmark_stiffness();
  const rd::ModalModel modes({rd::directional_mode(0, kFn, kZeta, k),
                              rd::directional_mode(1, 1.2 * kFn, 0.015, k),
                              rd::directional_mode(2, 1.6 * kFn, 0.02, 0.5 * k)});
  const rs::RegenerativeModel model(rt::Tool(spec), l, cut(3e-3), modes);
  const rs::ZeroOrderSolver solver(model);
  EXPECT_EQ(solver.branches(), 3);
  EXPECT_GT(solver.mean_stiffness_per_depth().col(2).norm(), 0.0);
  int limited = 0;
  double worst = 0.0;
  for (const auto& p : solver.limits(speeds(3000, 30000, 101))) {
    if (!p.limited)
      continue;
    ++limited;
    const double omega = 2.0 * pi * p.chatter_frequency_hz;
    worst = std::max(worst, std::abs(rs::characteristic_determinant(
                                solver.mean_stiffness_per_depth(), modes.receptance(omega),
                                p.depth_limit_m, omega, pi / p.spindle_rad_s)));
  }
  EXPECT_GT(limited, 90);
  EXPECT_LT(worst, 1e-9);
}

// Issue 31, point 2: a bull nose's lobes between its limits. The corner's
// elements enter W with their own κ (the lead angle of the edge sets the
// directional factors, 001 Eq 11 in RegenerativeModel), so a corner radius
// of 0.001 mm must give the helical flat end mill's limits and R − 0.001 mm
// the ball's, to 0.1 % (the tolerance), over a speed range with
// several lobes.
//
// One finding, checked rather than hidden: with an axial (z) mode, however
// small the corner, its elements couple z into the chip (the edge normal's
// −cos κ); the coupling of A0 is of the order r_c / ap, but near the axial
// mode's resonance its receptance is large, so at r_c = 0.001 mm the flat
// limit's lobes still differ by up to 2.5 % there (28 200 rpm, 1454 Hz). The
// difference vanishes linearly with r_c, which is what is asserted for that
// case (ten times smaller corner, at most a fifth of the difference).
namespace {

rt::Tool tool_with_corner(rt::ToolType type, double corner_m) {
  rt::ToolSpec spec;
  spec.type = type;
  spec.diameter_m = 10e-3;
  spec.teeth = 2;
  spec.helix_rad = 30.0 * pi / 180.0;
  spec.overhang_m = 30e-3;
  spec.corner_radius_m = corner_m;
  return rt::Tool(spec);
}

// The largest relative difference of two tools' limits over 3000-30 000 rpm.
double worst_lobe_difference(const rt::Tool& a, const rt::Tool& b, const rd::ModalModel& modes) {
  rc::LinearLaw l = benchmark_law();
  l.Kac_pa = 1e8;
  const rs::ZeroOrderSolver first(rs::RegenerativeModel(a, l, cut(3e-3), modes));
  const rs::ZeroOrderSolver second(rs::RegenerativeModel(b, l, cut(3e-3), modes));
  const auto grid = speeds(3000, 30000, 61);
  const auto la = first.limits(grid), lb = second.limits(grid);
  double worst = 0.0;
  int limited = 0;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    EXPECT_EQ(la[i].limited, lb[i].limited) << grid[i] / rpm << " rpm";
    if (!lb[i].limited)
      continue;
    ++limited;
    worst =
        std::max(worst, std::abs(la[i].depth_limit_m - lb[i].depth_limit_m) / lb[i].depth_limit_m);
  }
  EXPECT_GT(limited, 50);
  return worst;
}

}  // namespace

TEST(ZeroOrder, BullNoseLimitsAreTheFlatAndTheBallLobes) {
  const double k = benchmark_stiffness();
  const rd::ModalModel planar(
      {rd::directional_mode(0, kFn, kZeta, k), rd::directional_mode(1, 1.2 * kFn, 0.015, k)});
  const rd::ModalModel spatial({rd::directional_mode(0, kFn, kZeta, k),
                                rd::directional_mode(1, 1.2 * kFn, 0.015, k),
                                rd::directional_mode(2, 1.6 * kFn, 0.02, 0.5 * k)});
  const rt::Tool flat = tool_with_corner(rt::ToolType::flat, 0.0);
  const rt::Tool ball = tool_with_corner(rt::ToolType::ball, 0.0);
  const rt::Tool sharp = tool_with_corner(rt::ToolType::bull, 0.001e-3);
  const rt::Tool sharper = tool_with_corner(rt::ToolType::bull, 0.0001e-3);
  const rt::Tool round = tool_with_corner(rt::ToolType::bull, 5e-3 - 0.001e-3);

  const double flat_planar = worst_lobe_difference(sharp, flat, planar);
  const double ball_planar = worst_lobe_difference(round, ball, planar);
  const double ball_spatial = worst_lobe_difference(round, ball, spatial);
  EXPECT_LT(flat_planar, 1e-3);
  EXPECT_LT(ball_planar, 1e-3);
  EXPECT_LT(ball_spatial, 1e-3);
  const double flat_spatial = worst_lobe_difference(sharp, flat, spatial);
  const double flat_spatial_sharper = worst_lobe_difference(sharper, flat, spatial);
  EXPECT_LT(flat_spatial_sharper, 0.2 * flat_spatial);
  std::printf(
      "[validation] bull nose lobes: r_c 0.001 mm vs flat %.2e (x-y modes), %.2e (with z: "
      "%.2e at r_c 0.0001 mm); R - 0.001 mm vs ball %.2e (x-y), %.2e (with z)\n",
      flat_planar, flat_spatial, flat_spatial_sharper, ball_planar, ball_spatial);
}

}  // namespace test_zero_order_cpp
