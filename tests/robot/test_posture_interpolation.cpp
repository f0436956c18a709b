// Posture-dependent dynamics by inverse-distance weighting (001 Eq 16-18).

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>
#include <stdexcept>
#include <string>

#include "expect_invalid.hpp"
#include "robomill/robot/posture_interpolation.hpp"

namespace test_posture_interpolation_cpp {

namespace {

using robomill::test::expect_invalid;

using namespace robomill::robot;

// 15 measured postures (as in 001 §3.1) of a 6-joint robot, payloads of 4 values.
struct Library {
  std::vector<Eigen::VectorXd> postures;
  std::vector<Eigen::VectorXd> payloads;
};

Library random_library(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> angle(-2.0, 2.0);
  std::uniform_real_distribution<double> value(-5.0, 20.0);
  Library library;
  for (int i = 0; i < 15; ++i) {
    library.postures.push_back(Eigen::VectorXd::NullaryExpr(6, [&] { return angle(rng); }));
    library.payloads.push_back(Eigen::VectorXd::NullaryExpr(4, [&] { return value(rng); }));
  }
  return library;
}

TEST(PostureInterpolation, ExactAtEachMeasuredPosture) {
  const Library lib = random_library(1);
  for (std::size_t i = 0; i < lib.postures.size(); ++i) {
    for (double power : {1.0, 2.0, 3.5}) {
      const IdwResult r =
          idw_interpolate(lib.postures, lib.payloads, lib.postures[i], {power, {}, 1e-12});
      EXPECT_EQ(r.exact_index, static_cast<int>(i));
      EXPECT_EQ(r.value, lib.payloads[i]);  // bit-exact
      EXPECT_EQ(r.weights[static_cast<Eigen::Index>(i)], 1.0);
      EXPECT_EQ(r.weights.sum(), 1.0);
    }
  }
}

TEST(PostureInterpolation, ConvexCombinationElsewhere) {
  const Library lib = random_library(2);
  Eigen::VectorXd low = lib.payloads[0];
  Eigen::VectorXd high = lib.payloads[0];
  for (const auto& v : lib.payloads) {
    low = low.cwiseMin(v);
    high = high.cwiseMax(v);
  }
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-2.5, 2.5);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::VectorXd q = Eigen::VectorXd::NullaryExpr(6, [&] { return angle(rng); });
    IdwOptions options;
    options.power = trial % 2 == 0 ? 1.0 : 2.0;
    const IdwResult r = idw_interpolate(lib.postures, lib.payloads, q, options);
    EXPECT_EQ(r.exact_index, -1);
    EXPECT_GE(r.weights.minCoeff(), 0.0);
    EXPECT_NEAR(r.weights.sum(), 1.0, 1e-14);
    Eigen::VectorXd expected = Eigen::VectorXd::Zero(4);
    for (std::size_t i = 0; i < lib.payloads.size(); ++i)
      expected += r.weights[static_cast<Eigen::Index>(i)] * lib.payloads[i];
    EXPECT_LT((r.value - expected).norm(), 1e-12);
    EXPECT_TRUE((r.value.array() >= low.array() - 1e-12).all());
    EXPECT_TRUE((r.value.array() <= high.array() + 1e-12).all());
  }
}

TEST(PostureInterpolation, WeightsFollowPaperEq18) {
  // α_i = (1/d_i) / Σ 1/d_j with p = 1 (001 Eq 18), d the Euclidean joint distance (Eq 17).
  const Library lib = random_library(4);
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(6, 0.3);
  const IdwResult r = idw_weights(lib.postures, q);
  double total = 0.0;
  for (const auto& p : lib.postures)
    total += 1.0 / (q - p).norm();
  for (std::size_t i = 0; i < lib.postures.size(); ++i) {
    EXPECT_NEAR(r.weights[static_cast<Eigen::Index>(i)], 1.0 / (q - lib.postures[i]).norm() / total,
                1e-15);
  }
  // Closer postures weigh more, and more so for a higher power.
  const std::vector<Eigen::VectorXd> two{Eigen::VectorXd::Zero(2), Eigen::VectorXd::Ones(2)};
  const Eigen::VectorXd near_first = Eigen::VectorXd::Constant(2, 0.25);
  const double w1 = idw_weights(two, near_first, {1.0, {}, 1e-12}).weights[0];
  const double w2 = idw_weights(two, near_first, {2.0, {}, 1e-12}).weights[0];
  EXPECT_NEAR(w1, 0.75, 1e-15);  // d = (0.25, 0.75)·√2 → (4, 4/3)/(16/3)
  EXPECT_NEAR(w2, 0.9, 1e-15);   // (16, 16/9)/(160/9)
}

TEST(PostureInterpolation, EquidistantPointGetsTheAverage) {
  const std::vector<Eigen::VectorXd> postures{Eigen::VectorXd::Zero(3),
                                              Eigen::VectorXd::Constant(3, 1.0)};
  const std::vector<Eigen::VectorXd> payloads{Eigen::Vector2d(1.0, -4.0),
                                              Eigen::Vector2d(3.0, 8.0)};
  for (double power : {0.5, 1.0, 2.0}) {
    // The midpoint and any point on the bisecting plane.
    for (const Eigen::Vector3d& q : {Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d(1.0, 0.5, 0.0),
                                     Eigen::Vector3d(2.0, -0.5, 0.0)}) {
      const IdwResult r = idw_interpolate(postures, payloads, q, {power, {}, 1e-12});
      EXPECT_NEAR(r.value[0], 2.0, 1e-14);
      EXPECT_NEAR(r.value[1], 2.0, 1e-14);
      EXPECT_NEAR(r.weights[0], 0.5, 1e-15);
    }
  }
  // Four postures at the corners of a square around the query: the mean.
  std::vector<Eigen::VectorXd> square;
  std::vector<Eigen::VectorXd> values;
  for (int i = 0; i < 4; ++i) {
    const double a = i * std::acos(-1.0) / 2.0;
    square.push_back(Eigen::Vector2d(std::cos(a), std::sin(a)));
    values.push_back(Eigen::VectorXd::Constant(1, static_cast<double>(i)));
  }
  EXPECT_NEAR(idw_interpolate(square, values, Eigen::Vector2d::Zero()).value[0], 1.5, 1e-14);
}

TEST(PostureInterpolation, JointWeightsScaleTheDistance) {
  const std::vector<Eigen::VectorXd> postures{Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(1.0, 1.0)};
  const std::vector<Eigen::VectorXd> payloads{Eigen::VectorXd::Constant(1, 0.0),
                                              Eigen::VectorXd::Constant(1, 1.0)};
  // Query (1, 0): equidistant unweighted; ignoring joint 2 it sits on posture 2.
  const Eigen::Vector2d q(1.0, 0.0);
  EXPECT_NEAR(idw_interpolate(postures, payloads, q).value[0], 0.5, 1e-15);
  IdwOptions options;
  options.joint_weights = Eigen::Vector2d(1.0, 0.0);
  const IdwResult r = idw_interpolate(postures, payloads, q, options);
  EXPECT_EQ(r.exact_index, 1);
  EXPECT_EQ(r.value[0], 1.0);
}

TEST(PostureInterpolation, ModalTablesAverageFrequencyDampingAndCompliance) {
  const std::vector<Eigen::VectorXd> postures{Eigen::VectorXd::Zero(6),
                                              Eigen::VectorXd::Constant(6, 0.4)};
  // Two modes per posture: one along x, one along y (003-like values).
  const std::vector<std::vector<DirectionalModeParameters>> tables{
      {{0, 17.5, 0.05, 1.0e6}, {1, 21.0, 0.04, 2.0e6}},
      {{0, 18.5, 0.03, 3.0e6}, {1, 23.0, 0.06, 1.0e6}}};
  const Eigen::VectorXd mid = Eigen::VectorXd::Constant(6, 0.2);
  const auto by_compliance = interpolate_modal_tables(postures, tables, mid);
  ASSERT_EQ(by_compliance.size(), 2u);
  EXPECT_EQ(by_compliance[0].axis, 0);
  EXPECT_EQ(by_compliance[1].axis, 1);
  EXPECT_NEAR(by_compliance[0].natural_frequency_hz, 18.0, 1e-12);
  EXPECT_NEAR(by_compliance[0].damping_ratio, 0.04, 1e-15);
  EXPECT_NEAR(by_compliance[0].stiffness_n_per_m, 1.5e6, 1e-6);  // 2 / (1/1e6 + 1/3e6)
  EXPECT_NEAR(by_compliance[1].stiffness_n_per_m, 2.0e6 / 1.5, 1e-6);
  const auto by_stiffness =
      interpolate_modal_tables(postures, tables, mid, {}, StiffnessAveraging::kStiffness);
  EXPECT_NEAR(by_stiffness[0].stiffness_n_per_m, 2.0e6, 1e-6);
  EXPECT_NEAR(by_stiffness[1].natural_frequency_hz, 22.0, 1e-12);
  // Exact at a measured posture, whatever the averaging.
  const auto at_second = interpolate_modal_tables(postures, tables, postures[1]);
  EXPECT_EQ(at_second[0].stiffness_n_per_m, 3.0e6);
  EXPECT_EQ(at_second[1].natural_frequency_hz, 23.0);
  // Modes listed in another order are refused.
  auto swapped = tables;
  std::swap(swapped[1][0], swapped[1][1]);
  expect_invalid([&] { interpolate_modal_tables(postures, swapped, mid); }, "same order");
  auto bad = tables;
  bad[0][1].damping_ratio = 1.5;
  expect_invalid([&] { interpolate_modal_tables(postures, bad, mid); }, "posture 1, mode 2");
}

TEST(PostureInterpolation, FrfsAverageRealAndImaginaryParts) {
  const std::vector<Eigen::VectorXd> postures{Eigen::VectorXd::Zero(6),
                                              Eigen::VectorXd::Constant(6, 1.0)};
  const Eigen::VectorXd grid = Eigen::VectorXd::LinSpaced(50, 5.0, 100.0);
  std::vector<PostureFrf> frfs;
  for (double fn : {18.0, 22.0}) {
    PostureFrf frf{grid, Eigen::MatrixXcd(50, 2)};
    for (Eigen::Index l = 0; l < 50; ++l) {
      const double r = grid[l] / fn;
      frf.receptance_m_per_n(l, 0) = 1e-6 / std::complex<double>(1.0 - r * r, 0.1 * r);
      frf.receptance_m_per_n(l, 1) = 2e-6 / std::complex<double>(1.0 - r * r, 0.08 * r);
    }
    frfs.push_back(frf);
  }
  const PostureFrf mid = interpolate_frfs(postures, frfs, Eigen::VectorXd::Constant(6, 0.5));
  EXPECT_EQ(mid.frequency_hz, grid);
  const Eigen::MatrixXcd expected = 0.5 * (frfs[0].receptance_m_per_n + frfs[1].receptance_m_per_n);
  EXPECT_LT((mid.receptance_m_per_n - expected).cwiseAbs().maxCoeff(), 1e-20);
  const PostureFrf at_first = interpolate_frfs(postures, frfs, postures[0]);
  EXPECT_EQ(at_first.receptance_m_per_n, frfs[0].receptance_m_per_n);
  auto shifted = frfs;
  shifted[1].frequency_hz[3] += 0.5;
  expect_invalid([&] { interpolate_frfs(postures, shifted, postures[0]); }, "frequency grid");
  auto noisy = frfs;
  noisy[1].receptance_m_per_n(2, 1) = std::complex<double>(std::nan(""), 0.0);
  expect_invalid([&] { interpolate_frfs(postures, noisy, postures[0]); }, "non-finite");
}

TEST(PostureInterpolation, InvalidInputIsRefused) {
  const Library lib = random_library(5);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
  expect_invalid([&] { idw_interpolate({}, {}, q); }, "empty");
  expect_invalid([&] { idw_weights({}, q); }, "empty");
  expect_invalid([&] { idw_interpolate(lib.postures, lib.payloads, Eigen::VectorXd::Zero(5)); },
                 "posture 1 has 6 joints but the query has 5");
  auto short_payloads = lib.payloads;
  short_payloads[7] = Eigen::VectorXd::Zero(3);
  expect_invalid([&] { idw_interpolate(lib.postures, short_payloads, q); },
                 "payload of posture 8 has 3 values");
  auto fewer = lib.payloads;
  fewer.pop_back();
  expect_invalid([&] { idw_interpolate(lib.postures, fewer, q); }, "one payload per posture");
  auto nan_payload = lib.payloads;
  nan_payload[2][1] = std::nan("");
  expect_invalid([&] { idw_interpolate(lib.postures, nan_payload, q); },
                 "payload of posture 3 has non-finite");
  auto nan_posture = lib.postures;
  nan_posture[4][0] = INFINITY;
  expect_invalid([&] { idw_interpolate(nan_posture, lib.payloads, q); },
                 "posture 5 has non-finite");
  Eigen::VectorXd nan_query = q;
  nan_query[1] = std::nan("");
  expect_invalid([&] { idw_interpolate(lib.postures, lib.payloads, nan_query); }, "query");
  for (double power : {0.0, -1.0, std::nan("")}) {
    expect_invalid(
        [&] {
          idw_interpolate(lib.postures, lib.payloads, q, {power, {}, 1e-12});
        },
        "power must be positive");
  }
  IdwOptions options;
  options.joint_weights = Eigen::VectorXd::Ones(4);
  expect_invalid([&] { idw_interpolate(lib.postures, lib.payloads, q, options); }, "joint weights");
  options.joint_weights = Eigen::VectorXd::Zero(6);
  expect_invalid([&] { idw_interpolate(lib.postures, lib.payloads, q, options); },
                 "at least one must be positive");
}

}  // namespace

}  // namespace test_posture_interpolation_cpp
