// Ahmadi's linear-equivalent process damping (000 Eq 18-19) inside the
// time-domain methods.

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "benchmark_1dof.hpp"
#include "robomill/stability/lobes.hpp"
#include "robomill/stability/process_damping.hpp"

namespace test_time_domain_damping_cpp {

namespace {

using namespace robomill;

TEST(TimeDomainDamping, PeriodMeanEqualsTheZeroOrderDampingMatrix) {
  // Two independent implementations: the time-varying shape D(ϕ) averaged over
  // a tooth period, times C_eq', must equal minus the period-average damping
  // matrix the zero-order method uses (process_damping_matrix).
  const auto model = test::benchmark_1dof(0.5);
  stability::ProcessDamping params;
  params.model = stability::ProcessDampingModel::linear_equivalent;
  const double spindle = test::rpm(3000.0), depth = 2e-3;
  const Eigen::Matrix3d zero_order =
      stability::process_damping_matrix(model, params, spindle, depth, 900.0);
  Eigen::Matrix3d mean = Eigen::Matrix3d::Zero();
  const int samples = 20000;
  for (int s = 0; s < samples; ++s) {
    mean += model.damping_shape((s + 0.5) * std::numbers::pi / samples, depth, params.friction);
  }
  mean /= samples;
  const double c_unit = params.indentation_n_per_m3 * params.wear_land_m * params.wear_land_m /
                        (4.0 * 5e-3 * spindle);
  EXPECT_LT((c_unit * mean + zero_order).norm(), 1e-3 * zero_order.norm())
      << "time domain:\n"
      << c_unit * mean << "\nzero order:\n"
      << zero_order;
}

TEST(TimeDomainDamping, RaisesLowSpeedLimitsFarMoreThanHighSpeedOnes) {
  // The damping coefficient falls as 1/v: at 2000 rpm it must lift the
  // limit much more than at 20 000 rpm (000 §3.2, 003 §1).
  const auto model = test::benchmark_1dof(1.0);
  stability::LobeOptions options;
  options.steps = 40;
  options.depth_max_m = 10e-3;
  options.threads = 1;
  const std::vector<double> speeds = {test::rpm(2000.0), test::rpm(20000.0)};
  const auto plain = stability::stability_boundary(model, speeds, options);
  options.process_damping = stability::LinearProcessDamping{1.5e14, 10e-6, 0.3};
  const auto damped = stability::stability_boundary(model, speeds, options);
  const double low_gain = damped[0].depth_limit_m / plain[0].depth_limit_m;
  const double high_gain = damped[1].depth_limit_m / plain[1].depth_limit_m;
  std::cout << "[validation] FDM with linear process damping (w = 10 um): 2000 rpm x" << low_gain
            << ", 20000 rpm x" << high_gain << "\n";
  EXPECT_GT(low_gain, 1.3);
  EXPECT_LT(high_gain, 1.1);
  EXPECT_GE(high_gain, 1.0 - 1e-3);
}

}  // namespace

}  // namespace test_time_domain_damping_cpp
