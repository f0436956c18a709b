// Paper 004 (workpiece pose optimization, KR300-class 3-joint robot), Table 2
// and §4.3: d_m (Eq 6) at the six listed workpiece poses, and the optimum.
//
//   paper: Table 2, d_m = 0.73, 0.32, 0.54, 0.25, 0.25, 0.22 mm at
//          p = [0.6, 0.2, π/3], [0.2, 0.3, π/6], [0.3, −0.4, π/3],
//          [0.5, −0.5, 0], [0, 0, 0], [0, −0.46, 0] (the last: its optimum)
//   ours : examples/004_kr300_pose_optimization.yaml, d_i read as the
//          largest offset after the cut starts on the robot at rest
//          (measure: startup, the maximum an lsim run from rest shows)
//   tolerance: each within 30 % of the paper; pose 1 the worst; poses 1 > 3 >
//          2 > 4 > {5, 6} as in the paper. Poses 5 and 6 tie within 3 % in our
//          model where the paper has 6 better by 12 % (documented disagreement,
//          docs/validation.md); the optimizer's pose is at least as good as
//          pose 6, and CRS2 runs with different seeds agree within 2 %.
//   assumptions (docs/planning.md): joint 3's zero with the forearm ⊥ the upper
//          arm (with the straight-arm zero, ±60° makes poses 2, 3, 5, 6
//          unreachable); tilt about the part's yw; groove = closed 160 × 80 mm
//          rectangle, point 1 a corner, counterclockwise; z_w = 0; Appendix A's
//          tc in mm, kc1 in N/mm².

#include <gtest/gtest.h>

#include <cstdio>
#include <numbers>

#include "robomill/job/job.hpp"
#include "robomill/planning/pose_optimization.hpp"
#include "support/case004.hpp"
#include "support/validation_record.hpp"

namespace paper004_pose_optimization_test_cpp {

namespace {

using namespace robomill;
constexpr double kPi = std::numbers::pi;

// The example job's case with the job's own measure (startup).
struct Table2 : test::Case004 {
  planning::PlacementProblem problem = Case004::problem();
};

const double kPaperDm[6] = {0.73e-3, 0.32e-3, 0.54e-3, 0.25e-3, 0.25e-3, 0.22e-3};

TEST(Paper004, Table2MeanOffsetAtTheSixPoses) {
  const Table2 t;
  ASSERT_EQ(t.job.optimize->poses.size(), 6u);
  ASSERT_EQ(t.problem.measure, planning::OffsetMeasure::startup);
  double dm[6];
  for (int i = 0; i < 6; ++i) {
    const auto path = planning::evaluate_path(t.robot, t.problem, t.job.optimize->poses[i]);
    ASSERT_TRUE(path.reachable()) << "pose " << i + 1;
    dm[i] = path.dm_m;
    double peak = 0.0;
    for (const auto& p : path.points)
      peak += p.offset.peak_m / 20.0;
    std::printf(
        "[validation] 004 Table 2 pose %d: paper %.2f mm, ours %.3f mm (%+.0f %%); "
        "steady-state peak %.3f mm\n",
        i + 1, kPaperDm[i] * 1e3, dm[i] * 1e3, 100.0 * (dm[i] / kPaperDm[i] - 1.0), peak * 1e3);
    EXPECT_NEAR(dm[i], kPaperDm[i], 0.3 * kPaperDm[i]) << "pose " << i + 1;
    test::record_relative("004", "Tab. 2 pose " + std::to_string(i + 1), "mean tool-tip offset d_m",
                          "mm", kPaperDm[i] * 1e3, dm[i] * 1e3, 0.3,
                          "offset from rest (measure: startup); link masses of "
                          "examples/004_kr300_pose_optimization.yaml");
  }
  // The paper's order 1 > 3 > 2 > 4 ≥ 5 > 6.
  EXPECT_GT(dm[0], dm[2]);
  EXPECT_GT(dm[2], dm[1]);
  EXPECT_GT(dm[1], dm[3]);
  EXPECT_GT(dm[3], dm[4]);
  EXPECT_GT(dm[3], dm[5]);
  // Disagreement kept visible: 5 and 6 tie in our model (paper: 6 is 12 % better).
  EXPECT_NEAR(dm[5], dm[4], 0.03 * dm[4]);
  const bool order =
      dm[0] > dm[2] && dm[2] > dm[1] && dm[1] > dm[3] && dm[3] > dm[4] && dm[3] > dm[5];
  test::record_check("004", "Tab. 2", "order of the six poses", "", "1 > 3 > 2 > 4 >= 5 > 6",
                     order ? "1 > 3 > 2 > 4 > 5, 6" : "different", "same order (5, 6 may tie)",
                     order, "poses 5 and 6 tie in our model (paper: 6 is 12 % better)");
}

TEST(Paper004, OptimumIsAtLeastAsGoodAsThePapersAndSeedsAgree) {
  const Table2 t;
  const double paper_optimum_dm =
      planning::evaluate_path(t.robot, t.problem, {0.0, -0.46, 0.0}).dm_m;
  planning::PoseOptimizationOptions options = t.job.optimize->options;
  options.threads = 2;
  const auto direct =
      planning::optimize_workpiece_pose(t.robot, t.problem, t.job.optimize->bounds, options);
  ASSERT_TRUE(direct.found);
  std::printf(
      "[validation] 004 §4.3 optimum: paper [0, -0.46, 0] (ours %.4f mm there); DIRECT-L "
      "+ BOBYQA [%.4f, %.4f, %.4f] dm %.4f mm, %zu evaluations, %.2f s\n",
      paper_optimum_dm * 1e3, direct.best.x_m, direct.best.y_m, direct.best.theta_rad,
      direct.dm_m * 1e3, direct.evaluations.size(), direct.elapsed_s);
  EXPECT_LE(direct.dm_m, paper_optimum_dm);
  test::record_check("004", "§4.3 optimum", "d_m at the optimum", "mm",
                     "[0, -0.46, 0]: " + test::sig4(paper_optimum_dm * 1e3) + " (ours there)",
                     test::sig4(direct.dm_m * 1e3), "<= d_m at the paper's optimum",
                     direct.dm_m <= paper_optimum_dm, "DIRECT-L + BOBYQA over 004 Eq 9's bounds");
  EXPECT_LT(direct.best.theta_rad, kPi / 12);  // flat is best, as in the paper

  options.global = planning::GlobalMethod::crs2;
  for (unsigned seed : {3u, 11u}) {
    options.seed = seed;
    const auto crs =
        planning::optimize_workpiece_pose(t.robot, t.problem, t.job.optimize->bounds, options);
    ASSERT_TRUE(crs.found);
    std::printf("[validation] CRS2 seed %u: [%.4f, %.4f, %.4f] dm %.4f mm\n", seed, crs.best.x_m,
                crs.best.y_m, crs.best.theta_rad, crs.dm_m * 1e3);
    EXPECT_NEAR(crs.dm_m, direct.dm_m, 0.02 * direct.dm_m) << "seed " << seed;
  }
}

}  // namespace

}  // namespace paper004_pose_optimization_test_cpp
