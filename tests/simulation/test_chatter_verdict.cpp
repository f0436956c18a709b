// The chatter verdict (simulation::detect_chatter, docs/simulation.md "The
// chatter verdict") on synthetic vibrations whose answer is known, and on
// issue 20's one-mode slot, whose simulated vibration is numerical noise.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "robomill/cutting/cutting_law.hpp"
#include "robomill/dynamics/modal_model.hpp"
#include "robomill/simulation/response_metrics.hpp"
#include "robomill/simulation/simulator.hpp"

namespace test_chatter_verdict_cpp {

namespace {

using namespace robomill;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

// A window of 200 forced periods (tooth period 1.5 ms: 4 teeth at
// 10 000 rpm), 40 samples each, fz = 0.1 mm.
constexpr double kPeriod = 1.5e-3;
constexpr int kSamples = 40;
constexpr int kPeriods = 200;
constexpr double kFeed = 1e-4;

/// x(t) = static + forced harmonics at 1/kPeriod + `extra(t)`.
template <typename Extra>
std::vector<Eigen::Vector3d> window(double forced_m, Extra extra) {
  std::vector<Eigen::Vector3d> u;
  const double dt = kPeriod / kSamples;
  for (int i = 0; i < kPeriods * kSamples; ++i) {
    const double t = i * dt;
    const double forced =
        forced_m * (std::sin(kTwoPi * t / kPeriod) + 0.3 * std::cos(2.0 * kTwoPi * t / kPeriod));
    u.emplace_back(-50e-6 + forced + extra(t), 0.5 * forced, 0.0);
  }
  return u;
}

simulation::ChatterVerdict verdict(const std::vector<Eigen::Vector3d>& u, double feed = kFeed) {
  return simulation::detect_chatter(u, kPeriod / kSamples, kPeriod, feed);
}

TEST(ChatterVerdict, ForcedVibrationAloneIsStable) {
  const auto v = verdict(window(5e-6, [](double) { return 0.0; }));
  EXPECT_FALSE(v.chatter);
  EXPECT_LT(v.nonharmonic_rms_m, 1e-12);
  EXPECT_NEAR(v.forced_rms_m, 5e-6 * std::sqrt(1.25 * (1.0 + 0.09) / 2.0), 1e-9);
  EXPECT_EQ(v.floor, simulation::ChatterFloor::feed_per_tooth);
  EXPECT_DOUBLE_EQ(v.floor_m, 0.01 * kFeed);
}

// Issue 20's failure: a vibration that is all noise is 100 % non-harmonic and
// spreads once per period, but it is 1e-8 of fz.
TEST(ChatterVerdict, NumericalNoiseIsStableWhateverItsShare) {
  const auto v =
      verdict(window(0.0, [](double t) { return 1e-12 * std::sin(kTwoPi * 333.0 * t); }));
  EXPECT_GT(v.nonharmonic_fraction, 0.99);
  EXPECT_GT(v.sample_spread, 0.3);
  EXPECT_FALSE(v.chatter);
  EXPECT_LT(v.nonharmonic_rms_m, 1e-6 * v.floor_m);
}

TEST(ChatterVerdict, SustainedNonHarmonicVibrationChattersAtItsFrequency) {
  const double f = 1234.0;  // not a multiple of 666.7 Hz
  const auto v = verdict(window(5e-6, [&](double t) { return 10e-6 * std::sin(kTwoPi * f * t); }));
  EXPECT_TRUE(v.chatter);
  EXPECT_NEAR(v.frequency_hz, f, 1.0 / (kPeriods * kPeriod));
  EXPECT_NEAR(v.nonharmonic_rms_m, 10e-6 / std::sqrt(2.0), 0.02 * 10e-6);
  EXPECT_NEAR(v.persistence, 1.0, 0.02);
}

// A chatter below half the forced frequency (a robot mode under fast teeth)
// counts: the non-harmonic band starts three resolution bins above 0 Hz.
TEST(ChatterVerdict, LowFrequencyChatterCounts) {
  const auto v =
      verdict(window(5e-6, [](double t) { return 10e-6 * std::sin(kTwoPi * 21.0 * t); }));
  EXPECT_TRUE(v.chatter);
  EXPECT_NEAR(v.frequency_hz, 21.0, 2.0 / (kPeriods * kPeriod));
}

// A strong forced vibration does not hide chatter: 5 µm of non-harmonic
// vibration under 200 µm of forced vibration is 0.06 % of the energy (the
// former 10 % threshold missed it) but 5 % of fz.
TEST(ChatterVerdict, ResonantForcedVibrationDoesNotMaskChatter) {
  const auto v =
      verdict(window(200e-6, [](double t) { return 5e-6 * std::sin(kTwoPi * 1234.0 * t); }));
  EXPECT_LT(v.nonharmonic_fraction, 0.01);
  EXPECT_TRUE(v.chatter);
}

// A decaying transient (the settling of a stable cut) is not chatter however
// large: its second half holds e^{-1.5} of the first half's RMS.
TEST(ChatterVerdict, DecayingTransientIsStable) {
  const double window_s = kPeriods * kPeriod, rate = 3.0 / window_s;
  const auto v = verdict(window(
      5e-6, [&](double t) { return 20e-6 * std::exp(-rate * t) * std::sin(kTwoPi * 1234.0 * t); }));
  EXPECT_GT(v.nonharmonic_rms_m, v.floor_m);
  EXPECT_LT(v.persistence, 0.3);
  EXPECT_FALSE(v.chatter);
}

// A drift of the static deviation is not vibration: 20 µm over the window.
TEST(ChatterVerdict, DriftIsNotVibration) {
  const double window_s = kPeriods * kPeriod;
  const auto v = verdict(window(5e-6, [&](double t) { return 20e-6 * t / window_s; }));
  EXPECT_FALSE(v.chatter);
  EXPECT_LT(v.nonharmonic_rms_m, 1e-3 * v.floor_m);
}

// Without a feed the numerical floor, 1e-6 of the vibration's scale, applies.
TEST(ChatterVerdict, WithoutAFeedTheNumericalFloorApplies) {
  const auto noise =
      verdict(window(0.0, [](double t) { return 1e-13 * std::sin(kTwoPi * 333.0 * t); }), 0.0);
  EXPECT_EQ(noise.floor, simulation::ChatterFloor::numerical);
  EXPECT_NEAR(noise.floor_m, 1e-6 * 50e-6, 1e-6 * noise.floor_m);  // |x_s| = 50 µm
  EXPECT_FALSE(noise.chatter);
  const auto real =
      verdict(window(0.0, [](double t) { return 1e-6 * std::sin(kTwoPi * 333.0 * t); }), 0.0);
  EXPECT_TRUE(real.chatter);
}

// A forced period that is not a whole number of samples (a simulation kept
// every k-th step, a recorded signal): the window is cut to whole periods to
// within half a sample, so 100 µm of forced vibration leaks well under the
// floor into the non-harmonic bins.
TEST(ChatterVerdict, NonIntegerSamplesPerPeriodDoNotLeak) {
  const double per_period = 40.333, dt = kPeriod / per_period;
  std::vector<Eigen::Vector3d> u;
  for (int i = 0; i < 8100; ++i) {  // 200.8 periods: the verdict takes the last 200
    const double t = i * dt;
    u.emplace_back(
        100e-6 * std::sin(kTwoPi * t / kPeriod) + 30e-6 * std::cos(2.0 * kTwoPi * t / kPeriod), 0.0,
        0.0);
  }
  const auto v = simulation::detect_chatter(u, dt, kPeriod, kFeed);
  EXPECT_FALSE(v.chatter);
  EXPECT_LT(v.nonharmonic_rms_m, 1e-3 * v.forced_rms_m);  // 4e-4 of it
  EXPECT_LT(v.nonharmonic_rms_m, 0.1 * v.floor_m);
  EXPECT_NEAR(v.forced_rms_m, std::sqrt((100e-6 * 100e-6 + 30e-6 * 30e-6) / 2.0), 1e-7);
}

TEST(ChatterVerdict, RejectsWindowsItCannotJudge) {
  const std::vector<Eigen::Vector3d> few(5, Eigen::Vector3d::Zero());
  EXPECT_THROW(simulation::detect_chatter(few, 1e-4, 1e-3, kFeed), std::invalid_argument);
  const std::vector<Eigen::Vector3d> many(100, Eigen::Vector3d::Zero());
  EXPECT_THROW(simulation::detect_chatter(many, 0.0, 1e-3, kFeed), std::invalid_argument);
  EXPECT_THROW(simulation::detect_chatter(many, 1e-4, 1.0, kFeed), std::invalid_argument);
}

// Issue 20's cut, simulated: one mode (12.99 Hz, k = 8e5 N/m, ζ = 5 %) under a
// four-tooth slot at 10 000 rpm, ap 2 mm, straight flutes, the linear law
// without edge forces. Two teeth always cut and their forces sum to a
// constant, so after 3 s the vibration is noise (1.6e-9 mm peak to peak,
// 2e-8 of the static deviation). The former verdict judged it chatter at
// 335 Hz (non-harmonic fraction 0.998, spread 1.01).
TEST(ChatterVerdict, Issue20SlotThatSettlesIsStable) {
  tool::ToolSpec spec;
  spec.diameter_m = 20e-3;
  spec.teeth = 4;
  spec.overhang_m = 60e-3;
  const tool::Tool cutter(spec);
  const cutting::LinearLaw law{855e6, 270.93e6, 0.0, 0.0, 0.0, 0.0};
  const double spindle = 10000.0 * kTwoPi / 60.0;
  const cutting::MillingProcess process{spindle, 0.1e-3, 2e-3, 20e-3,
                                        cutting::MillingDirection::down};
  const dynamics::ModalModel modes({dynamics::directional_mode(0, 12.99, 0.05, 8e5)});
  simulation::SimulationOptions options;
  options.duration_s = 3.0;
  options.steps_per_tooth = 40;
  const auto result = simulation::simulate(cutter, law, process, simulation::modal_structure(modes),
                                           simulation::Workpiece{}, options);
  simulation::ResponseOptions analysis;
  analysis.spindle_rad_s = spindle;
  analysis.teeth = 4;
  analysis.steady_window_s = 0.2 * options.duration_s;
  analysis.feed_per_tooth_m = process.feed_per_tooth_m;
  const auto metrics = simulation::analyze_response(result, analysis);
  const auto& c = metrics.chatter;
  EXPECT_LT(metrics.direction[0].peak_to_peak_m, 1e-10);
  EXPECT_GT(c.nonharmonic_fraction, 0.9);  // all of nothing is non-harmonic …
  EXPECT_FALSE(c.chatter);                 // … but nothing is not chatter
  EXPECT_LT(c.nonharmonic_rms_m, 1e-6 * c.floor_m);
  EXPECT_EQ(c.floor, simulation::ChatterFloor::feed_per_tooth);
}

}  // namespace

}  // namespace test_chatter_verdict_cpp
