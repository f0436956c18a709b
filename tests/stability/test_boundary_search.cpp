// The boundary search of stability_boundary (lobes.hpp): continuation from the
// previous speed, the coarse island scan and the safeguarded regula falsi must
// find the same limits as a plain scan and a dense spectral-radius map.

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "benchmark_1dof.hpp"
#include "robomill/stability/lobes.hpp"

namespace test_boundary_search_cpp {

namespace {

using namespace robomill;

stability::LobeOptions benchmark_options() {
  stability::LobeOptions options;
  options.depth_max_m = 10e-3;
  options.depth_tolerance = 1e-3;
  return options;
}

int total_evaluations(const std::vector<stability::LobePoint>& points) {
  int total = 0;
  for (const auto& p : points)
    total += p.evaluations;
  return total;
}

// Continuation must change the cost, not the answer: at every one of 400
// speeds of the benchmark window (a/D 1 has period-doubling lobes and cusps between
// lobes, a/D 0.05 flip islands) both searches bracket the same crossing, so
// the limits agree within the two brackets' widths (2 × 0.1 %).
TEST(BoundarySearch, ContinuationFindsTheSameLimits) {
  for (const double immersion : {1.0, 0.05}) {
    const auto model = test::benchmark_1dof(immersion);
    const auto speeds = stability::linear_range(test::rpm(5000.0), test::rpm(25000.0), 400);
    auto options = benchmark_options();
    options.continuation = true;
    const auto continued = stability::stability_boundary(model, speeds, options);
    options.continuation = false;
    const auto plain = stability::stability_boundary(model, speeds, options);
    for (std::size_t i = 0; i < speeds.size(); ++i) {
      ASSERT_EQ(continued[i].limited, plain[i].limited);
      EXPECT_NEAR(continued[i].depth_limit_m, plain[i].depth_limit_m, 2e-3 * plain[i].depth_limit_m)
          << "a/D " << immersion << ", speed " << i;
      EXPECT_EQ(continued[i].bifurcation, plain[i].bifurcation) << "a/D " << immersion << ", " << i;
    }
    // A measurement, not a property: the predictor saves solves only where the
    // limits vary smoothly at the speed spacing (docs/theory.md).
    std::cout << "[benchmark] a/D " << immersion << ": Floquet solves for 400 limits, "
              << total_evaluations(continued) << " with continuation, " << total_evaluations(plain)
              << " without\n";
  }
}

// Results do not depend on the thread count (continuation chains restart at
// fixed chunks of speeds, not at thread boundaries): bit-identical limits.
TEST(BoundarySearch, LimitsDoNotDependOnTheThreadCount) {
  const auto model = test::benchmark_1dof(0.05);
  const auto speeds = stability::linear_range(test::rpm(5000.0), test::rpm(25000.0), 57);
  auto options = benchmark_options();
  options.threads = 1;
  const auto one = stability::stability_boundary(model, speeds, options);
  for (const int threads : {2, 3, 7}) {
    options.threads = threads;
    const auto many = stability::stability_boundary(model, speeds, options);
    for (std::size_t i = 0; i < speeds.size(); ++i) {
      EXPECT_EQ(one[i].depth_limit_m, many[i].depth_limit_m) << threads << " threads, " << i;
      EXPECT_EQ(one[i].evaluations, many[i].evaluations) << threads << " threads, " << i;
    }
  }
}

// Against a dense map (400 depths over 10 mm, 25 µm apart): the limit is the
// first depth where the spectral radius reaches 1, so every map depth below
// the limit is stable and the first map depth above it (by more than the
// tolerance) is unstable — no crossing below the reported limit is missed.
TEST(BoundarySearch, NoUnstableDepthBelowTheLimitInADenseMap) {
  const auto model = test::benchmark_1dof(1.0);
  const auto speeds = stability::linear_range(test::rpm(5000.0), test::rpm(25000.0), 60);
  const auto options = benchmark_options();
  const auto limits = stability::stability_boundary(model, speeds, options);
  const auto depths = stability::linear_range(10e-3 / 400, 10e-3, 400);
  const auto map = stability::stability_map(model, speeds, depths, options);
  for (std::size_t i = 0; i < speeds.size(); ++i) {
    for (std::size_t j = 0; j < depths.size(); ++j) {
      const bool unstable =
          map.spectral_radius(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) >= 1.0;
      if (depths[j] < limits[i].depth_limit_m * (1.0 - 1e-3)) {
        EXPECT_FALSE(unstable) << "speed " << i << ": unstable at " << depths[j] * 1e3
                               << " mm below the limit " << limits[i].depth_limit_m * 1e3;
      } else if (depths[j] > limits[i].depth_limit_m * (1.0 + 1e-3)) {
        EXPECT_TRUE(unstable) << "speed " << i << ": stable at " << depths[j] * 1e3
                              << " mm just above the limit " << limits[i].depth_limit_m * 1e3;
        break;
      }
    }
  }
}

}  // namespace

}  // namespace test_boundary_search_cpp
