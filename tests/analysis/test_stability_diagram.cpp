// analysis::stability_diagram on the 1-DOF slot benchmark (DESIGN.md §5,
// examples/benchmark_1dof_slot.yaml) against the closed form, and the
// diagram helpers (interpolated_limit_m, diagram_figures, compare_experiments).

#include "robomill/analysis/stability_diagram.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <variant>

#include "robomill/analysis/deflection_sweep.hpp"
#include "robomill/core/error.hpp"
#include "robomill/deflection/contact_boundary.hpp"
#include "robomill/job/job.hpp"

namespace test_stability_diagram_cpp {

namespace ra = robomill::analysis;
namespace job = robomill::job;

namespace {

constexpr double pi = std::numbers::pi;

job::Job example(const char* name, const std::vector<job::Override>& overrides = {}) {
  return job::load_job(std::string(ROBOMILL_SOURCE_DIR) + "/examples/" + name, overrides);
}

ra::StabilityLimit limit(double spindle_rad_s, double depth_m, bool limited = true,
                         ra::Bifurcation bifurcation = ra::Bifurcation::hopf) {
  ra::StabilityLimit l;
  l.spindle_rad_s = spindle_rad_s;
  l.depth_limit_m = depth_m;
  l.limited = limited;
  l.chatter_frequency_hz = limited ? 900.0 : 0.0;
  l.bifurcation = limited ? bifurcation : ra::Bifurcation::none;
  return l;
}

}  // namespace

// The slot benchmark by the zero-order method: one mode along x, so the
// characteristic equation is scalar, 1 = ap (1 − e^{−iωτ}) A0_xx G_xx, and
// ap = 1 / (2 A0_xx Re G): the limit is smallest where Re G is most
// negative, a_lim,min = −1 / (2 Ks Re G_min) with Ks = |A0_xx| the mean
// cutting stiffness per depth along x. For a straight-flute slot A0 =
// (N/4) [[−Kr, −Kt], [Kt, −Kr]] (tests/stability/test_zero_order.cpp), so
// Ks = N Kr / 4; G = 1/(k (1 − r² + 2iζr)) has min Re G = −1/(4kζ(1+ζ)) at
// r² = 1 + 2ζ. Every number below comes from the job file.
TEST(StabilityDiagram, OneDofSlotMinimumMatchesClosedForm) {
  const int count = 401;
  const job::Job job =
      example("benchmark_1dof_slot.yaml",
              {{"stability.method", "zoa"}, {"stability.speeds.count", std::to_string(count)}});
  ASSERT_EQ(job.modes.size(), 1u);
  const job::ModeSpec& mode = job.modes.front();
  ASSERT_EQ(mode.direction, 'x');
  const double k = mode.stiffness_n_per_m, zeta = mode.damping_ratio;
  const double fn = mode.natural_frequency_hz;
  const int teeth = job.tool->teeth;
  const auto& law = std::get<robomill::cutting::LinearLaw>(*job.cutting);
  ASSERT_NEAR(job.process->radial_depth_m, job.tool->diameter_m, 1e-12) << "a slot";

  const double ks = teeth * law.Krc_pa / 4.0;
  const double min_re_g = -1.0 / (4.0 * k * zeta * (1.0 + zeta));
  // The closed-form minimum of Re G against a dense scan of the FRF.
  double scanned = 0.0;
  for (int i = 0; i <= 200000; ++i) {
    const double r = 0.9 + 0.2 * i / 200000.0;
    scanned =
        std::min(scanned, std::real(1.0 / (k * std::complex<double>(1.0 - r * r, 2.0 * zeta * r))));
  }
  EXPECT_NEAR(scanned, min_re_g, 1e-6 * std::abs(min_re_g));
  const double closed = -1.0 / (2.0 * ks * min_re_g);

  const ra::StabilityDiagram diagram = ra::stability_diagram(job, 2);
  EXPECT_EQ(diagram.method, job::StabilitySettings::Method::zoa);
  ASSERT_TRUE(diagram.modes.has_value());
  EXPECT_EQ(diagram.modes->size(), 1);
  ASSERT_EQ(diagram.coupled.size(), static_cast<std::size_t>(count));
  EXPECT_EQ(diagram.speeds_rad_s.size(), static_cast<std::size_t>(count));
  EXPECT_TRUE(diagram.envelope.empty());
  EXPECT_TRUE(diagram.variants.empty());
  EXPECT_FALSE(diagram.map.has_value());
  EXPECT_FALSE(diagram.discretization.has_value()) << "zoa takes no time step";
  EXPECT_EQ(&diagram.primary(), &diagram.coupled);
  for (std::size_t i = 0; i < diagram.coupled.size(); ++i) {
    const ra::StabilityLimit& l = diagram.coupled[i];
    EXPECT_DOUBLE_EQ(l.spindle_rad_s, diagram.speeds_rad_s[i]);
    EXPECT_EQ(l.mode, -1);
    EXPECT_EQ(l.bifurcation, l.limited ? ra::Bifurcation::hopf : ra::Bifurcation::none);
    EXPECT_GE(l.depth_limit_m, closed * (1.0 - 1e-9)) << "below the absolute minimum";
  }
  const auto lowest = std::min_element(
      diagram.coupled.begin(), diagram.coupled.end(),
      [](const auto& a, const auto& b) { return a.depth_limit_m < b.depth_limit_m; });
  ASSERT_TRUE(lowest->limited);
  EXPECT_NEAR(lowest->depth_limit_m, closed, 0.01 * closed);
  // Chatter just above fn (at fn √(1 + 2ζ) at the lobe's bottom).
  EXPECT_GT(lowest->chatter_frequency_hz, fn);
  EXPECT_LT(lowest->chatter_frequency_hz, 1.02 * fn);

  const ra::DiagramFigures figures = ra::diagram_figures(diagram.primary());
  EXPECT_DOUBLE_EQ(figures.min_limit_m, lowest->depth_limit_m);
  EXPECT_DOUBLE_EQ(figures.min_limit_spindle_rad_s, lowest->spindle_rad_s);
  EXPECT_EQ(figures.speeds_period_doubling, 0) << "zoa knows only Hopf";
  std::printf("[          ] a_lim,min closed form %.6f mm, diagram minimum %.6f mm at %.1f rpm\n",
              closed * 1e3, lowest->depth_limit_m * 1e3, lowest->spindle_rad_s * 30.0 / pi);
}

// The job's cutting tests against the diagram: inside the range each is
// compared at the interpolated limit; outside it is left uncompared.
TEST(StabilityDiagram, ExperimentsAreJudgedAtTheInterpolatedLimit) {
  const job::Job job =
      example("benchmark_1dof_slot.yaml", {{"stability.method", "zoa"},
                                           {"stability.speeds.count", "41"},
                                           {"experiments",
                                            "[{spindle: 10000 rpm, depth: 0.01 mm, chatter: false},"
                                            " {spindle: 10000 rpm, depth: 9 mm, chatter: false},"
                                            " {spindle: 30000 rpm, depth: 1 mm, chatter: true}]"}});
  const ra::StabilityDiagram diagram = ra::stability_diagram(job, 2);
  const ra::ExperimentComparison& c = diagram.experiments;
  ASSERT_EQ(c.tests.size(), 3u);
  EXPECT_EQ(c.compared, 2);
  EXPECT_EQ(c.agree, 1);
  const double at = 10000.0 * pi / 30.0;
  ASSERT_TRUE(c.tests[0].limit_m.has_value());
  EXPECT_DOUBLE_EQ(*c.tests[0].limit_m, *ra::interpolated_limit_m(diagram.coupled, at));
  EXPECT_FALSE(c.tests[0].predicted_chatter);
  EXPECT_TRUE(c.tests[0].agrees);
  EXPECT_TRUE(c.tests[1].predicted_chatter);
  EXPECT_FALSE(c.tests[1].agrees);
  EXPECT_FALSE(c.tests[2].limit_m.has_value()) << "outside 5000-25000 rpm";
  EXPECT_EQ(c.tests[0].governing_mode, -1) << "a coupled diagram blames no single mode";
}

TEST(StabilityDiagram, InterpolatedLimitIsLinearBetweenSpeedsAndEmptyOutside) {
  const std::vector<ra::StabilityLimit> limits = {limit(100.0, 1e-3), limit(200.0, 3e-3),
                                                  limit(400.0, 2e-3, false)};
  EXPECT_DOUBLE_EQ(*ra::interpolated_limit_m(limits, 100.0), 1e-3);
  EXPECT_DOUBLE_EQ(*ra::interpolated_limit_m(limits, 150.0), 2e-3);
  EXPECT_DOUBLE_EQ(*ra::interpolated_limit_m(limits, 125.0), 1.5e-3);
  EXPECT_DOUBLE_EQ(*ra::interpolated_limit_m(limits, 200.0), 3e-3);
  EXPECT_DOUBLE_EQ(*ra::interpolated_limit_m(limits, 300.0), 2.5e-3);
  EXPECT_DOUBLE_EQ(*ra::interpolated_limit_m(limits, 400.0), 2e-3);
  EXPECT_FALSE(ra::interpolated_limit_m(limits, 99.999).has_value());
  EXPECT_FALSE(ra::interpolated_limit_m(limits, 400.001).has_value());
  EXPECT_FALSE(ra::interpolated_limit_m({}, 150.0).has_value());
  // One speed: an answer only there.
  const std::vector<ra::StabilityLimit> one = {limit(300.0, 4e-3)};
  EXPECT_DOUBLE_EQ(*ra::interpolated_limit_m(one, 300.0), 4e-3);
  EXPECT_FALSE(ra::interpolated_limit_m(one, 301.0).has_value());
}

TEST(StabilityDiagram, FiguresCountUnlimitedAndPeriodDoublingSpeeds) {
  const std::vector<ra::StabilityLimit> limits = {limit(100.0, 2e-3),
                                                  limit(200.0, 1e-3, true, ra::Bifurcation::flip),
                                                  limit(300.0, 5e-3, false), limit(400.0, 4e-3)};
  const ra::DiagramFigures f = ra::diagram_figures(limits);
  EXPECT_DOUBLE_EQ(f.min_limit_m, 1e-3);
  EXPECT_DOUBLE_EQ(f.min_limit_spindle_rad_s, 200.0);
  EXPECT_DOUBLE_EQ(f.max_limit_m, 5e-3);
  EXPECT_EQ(f.speeds_stable_to_depth_max, 1);
  EXPECT_EQ(f.speeds_period_doubling, 1);
  EXPECT_TRUE(std::isinf(ra::diagram_figures({}).min_limit_m));
  EXPECT_STREQ(ra::to_string(ra::Bifurcation::flip), "flip");
  EXPECT_STREQ(ra::to_string(ra::Bifurcation::none), "none");
}

// The method checks name the field.
TEST(StabilityDiagram, UnsupportedCombinationsNameTheField) {
  const job::Job map_by_zoa =
      example("benchmark_1dof_slot.yaml", {{"stability.method", "zoa"}, {"stability.mode", "map"}});
  try {
    ra::stability_diagram(map_by_zoa, 1);
    FAIL() << "a map by zoa";
  } catch (const robomill::InputError& e) {
    EXPECT_EQ(e.field(), "stability.mode");
  }
}

// robomill deflection's sweep (000 Eq 22): without deflection.depths the
// sweep ends at 1.5 ap_lim (or the overhang) in equal steps from to/count.
TEST(DeflectionSweep, AutomaticDepthsSpanBothContactCases) {
  const job::Job job = example("demo.yaml");
  const ra::DeflectionSweep sweep = ra::deflection_sweep(job, 2);
  ASSERT_EQ(sweep.depths_m.size(), sweep.boundaries.size());
  ASSERT_GE(sweep.depths_m.size(), 2u);
  const double ap_lim = robomill::deflection::critical_depth_m(
      sweep.setup.tool_radius_m, sweep.setup.radial_depth_m, sweep.setup.helix_rad);
  ASSERT_TRUE(std::isfinite(ap_lim));
  EXPECT_DOUBLE_EQ(sweep.critical_depth_m, ap_lim);
  const double to = std::min(1.5 * ap_lim, sweep.setup.overhang_m);
  const auto n = static_cast<double>(sweep.depths_m.size());
  EXPECT_NEAR(sweep.depths_m.back(), to, 1e-12);
  EXPECT_NEAR(sweep.depths_m.front(), to / n, 1e-12);
  EXPECT_TRUE(std::is_sorted(sweep.depths_m.begin(), sweep.depths_m.end()));
  EXPECT_GT(sweep.max_deflection_m, 0.0);
  EXPECT_GE(sweep.max_entry_increase_rad, 0.0);
}

}  // namespace test_stability_diagram_cpp
