// FRF type: synthesis from modes, kind conversion, interpolation, validation.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "robomill/core/error.hpp"
#include "robomill/dynamics/frf.hpp"

namespace test_frf_cpp {

namespace {

using namespace robomill::dynamics;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

std::vector<double> grid(double first_hz, double step_hz, int count) {
  std::vector<double> f;
  for (int i = 0; i < count; ++i)
    f.push_back(first_hz + step_hz * i);
  return f;
}

TEST(Frf, SynthesisMatchesOneDofClosedForm) {
  const double fn_hz = 922.0, zeta = 0.011, k = 2e7;
  const ModalModel modes({directional_mode(1, fn_hz, zeta, k)});
  const Frf frf = synthesize(modes, 1, 1, grid(0.0, 10.0, 201));
  validate(frf);
  for (std::size_t i = 0; i < frf.frequency_hz.size(); ++i) {
    const double r = frf.frequency_hz[i] / fn_hz;
    // H = 1/k / (1 − r² + 2iζr)
    const std::complex<double> expected = 1.0 / k / std::complex<double>(1 - r * r, 2 * zeta * r);
    EXPECT_NEAR(std::abs(frf.value[i] - expected), 0.0, 1e-12 * std::abs(expected)) << i;
  }
  EXPECT_NEAR(frf.value[0].real(), 1.0 / k, 1e-20);  // static compliance
  // Cross terms vanish for a mode along y only.
  const Frf cross = synthesize(modes, 0, 1, grid(1.0, 10.0, 5));
  for (const auto& v : cross.value)
    EXPECT_EQ(v, std::complex<double>(0.0, 0.0));
}

TEST(Frf, MobilityIsIOmegaTimesReceptance) {
  const ModalModel modes(
      {directional_mode(0, 300.0, 0.03, 5e6), directional_mode(0, 800.0, 0.02, 9e6)});
  const auto f = grid(0.0, 5.0, 300);
  const Frf receptance = synthesize(modes, 0, 0, f);
  const Frf mobility = synthesize(modes, 0, 0, f, FrfKind::mobility);
  const Frf accelerance = convert(receptance, FrfKind::accelerance);
  ASSERT_EQ(accelerance.frequency_hz.size(), f.size());
  for (std::size_t i = 0; i < f.size(); ++i) {
    const std::complex<double> i_omega(0.0, kTwoPi * f[i]);
    EXPECT_NEAR(std::abs(mobility.value[i] - i_omega * receptance.value[i]), 0.0,
                1e-12 * std::abs(mobility.value[i]) + 1e-300);
    EXPECT_NEAR(std::abs(accelerance.value[i] - i_omega * i_omega * receptance.value[i]), 0.0,
                1e-12 * std::abs(accelerance.value[i]) + 1e-300);
  }
}

TEST(Frf, ConversionRoundTripDropsZeroHertz) {
  const ModalModel modes({directional_mode(2, 500.0, 0.05, 1e7)});
  const Frf receptance = synthesize(modes, 2, 2, grid(0.0, 4.0, 100));
  const Frf back = convert(convert(receptance, FrfKind::accelerance), FrfKind::receptance);
  ASSERT_EQ(back.frequency_hz.size(), 99u);  // the 0 Hz point cannot be integrated
  EXPECT_EQ(back.kind, FrfKind::receptance);
  EXPECT_EQ(back.response_axis, 2);
  for (std::size_t i = 0; i < back.value.size(); ++i) {
    EXPECT_EQ(back.frequency_hz[i], receptance.frequency_hz[i + 1]);
    EXPECT_NEAR(std::abs(back.value[i] - receptance.value[i + 1]), 0.0,
                1e-13 * std::abs(receptance.value[i + 1]));
  }
  Frf only_zero = receptance;
  only_zero.frequency_hz = {0.0};
  only_zero.value = {1.0};
  only_zero.kind = FrfKind::mobility;
  EXPECT_THROW(convert(only_zero, FrfKind::receptance), std::invalid_argument);
}

TEST(Frf, InterpolatesLinearlyInsideTheGrid) {
  Frf frf;
  frf.frequency_hz = {10.0, 20.0, 40.0};
  frf.value = {{1.0, -1.0}, {3.0, 1.0}, {-1.0, 0.0}};
  EXPECT_EQ(interpolate(frf, 10.0), std::complex<double>(1.0, -1.0));
  EXPECT_EQ(interpolate(frf, 15.0), std::complex<double>(2.0, 0.0));
  EXPECT_EQ(interpolate(frf, 30.0), std::complex<double>(1.0, 0.5));
  EXPECT_EQ(interpolate(frf, 40.0), std::complex<double>(-1.0, 0.0));
  EXPECT_THROW(interpolate(frf, 9.99), std::invalid_argument);
  EXPECT_THROW(interpolate(frf, 40.01), std::invalid_argument);
  EXPECT_THROW(interpolate(frf, std::nan("")), std::invalid_argument);
}

TEST(Frf, ValidationRejectsBadGridsValuesAndAxes) {
  Frf good;
  good.frequency_hz = {0.0, 1.0};
  good.value = {1.0, 2.0};
  EXPECT_NO_THROW(validate(good));
  auto broken = [&](auto change) {
    Frf frf = good;
    change(frf);
    return frf;
  };
  EXPECT_THROW(validate(broken([](Frf& f) { f.frequency_hz.clear(), f.value.clear(); })),
               std::invalid_argument);
  EXPECT_THROW(validate(broken([](Frf& f) {
                 f.frequency_hz = {1.0, 1.0};
               })),
               std::invalid_argument);
  EXPECT_THROW(validate(broken([](Frf& f) {
                 f.frequency_hz = {-1.0, 1.0};
               })),
               std::invalid_argument);
  EXPECT_THROW(validate(broken([](Frf& f) { f.frequency_hz[1] = INFINITY; })),
               std::invalid_argument);
  EXPECT_THROW(validate(broken([](Frf& f) { f.value.pop_back(); })), std::invalid_argument);
  EXPECT_THROW(validate(broken([](Frf& f) { f.value[0] = {NAN, 0.0}; })), std::invalid_argument);
  EXPECT_THROW(validate(broken([](Frf& f) { f.reference_axis = 3; })), std::invalid_argument);
  EXPECT_THROW(validate(broken([](Frf& f) { f.response_axis = -1; })), std::invalid_argument);
  EXPECT_STREQ(kind_name(FrfKind::accelerance), "accelerance");
  // Dividing a huge value by a tiny ω overflows: refused, never returned as inf.
  Frf huge = broken([](Frf& f) { f.frequency_hz = {1e-300}, f.value = {{1e300, 0.0}}; });
  huge.value.resize(1);
  huge.kind = FrfKind::accelerance;
  EXPECT_THROW(convert(huge, FrfKind::receptance), robomill::NumericalError);
}

}  // namespace

}  // namespace test_frf_cpp
