// Cutting-parameter advice (issue 9 item 4): the advised (speed, depth) is
// checked against independent computations — direct Floquet solves, the
// harmonic offset computed at the actual speed, an exhaustive grid search —
// and the redundancy study against the robot's own modes at its posture.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "robomill/analysis/structure.hpp"
#include "robomill/cutting/milling_forces.hpp"
#include "robomill/job/job.hpp"
#include "robomill/planning/cutting_advice.hpp"
#include "robomill/planning/force_harmonics.hpp"
#include "robomill/planning/redundancy_study.hpp"
#include "robomill/robot/kinematics.hpp"
#include "robomill/stability/zero_order.hpp"

namespace robomill::planning {
namespace test_cutting_advice_cpp {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRpm = 2.0 * kPi / 60.0;

// The standard milling benchmark (DESIGN.md §5: 2 teeth, Kt = 6e8 N/m²,
// Kn = 2e8 N/m², fn = 922 Hz, ζ = 0.011, m = 0.03993 kg), made 2-DOF with
// the same mode along x and y, a/D = 0.1, down milling, straight flutes.
struct Benchmark {
  tool::Tool cutter{[] {
    tool::ToolSpec spec;
    spec.diameter_m = 20e-3;
    spec.teeth = 2;
    spec.helix_rad = 0.0;
    spec.overhang_m = 30e-3;
    return spec;
  }()};
  cutting::CuttingLaw law{cutting::LinearLaw{6e8, 2e8, 0.0, 0.0, 0.0, 0.0}};
  cutting::MillingProcess process{0.0, 0.1e-3, 0.0, 2e-3, cutting::MillingDirection::down};
  dynamics::ModalModel modes{[] {
    const double k = 0.03993 * std::pow(2.0 * kPi * 922.0, 2);
    return std::vector<dynamics::Mode>{dynamics::directional_mode(0, 922.0, 0.011, k),
                                       dynamics::directional_mode(1, 922.0, 0.011, k)};
  }()};
};

AdviceLimits benchmark_limits() {
  AdviceLimits limits;
  limits.speed_min_rad_s = 9000 * kRpm;
  limits.speed_max_rad_s = 21000 * kRpm;
  limits.speed_count = 25;
  limits.refine_count = 4;
  limits.depth_step_m = 0.1e-3;
  limits.harmonics = 30;
  limits.samples = 128;
  return limits;
}

AdviceOptions fdm_options() {
  AdviceOptions options;
  options.limit.method = LimitMethod::fdm;
  options.limit.discretization = 40;
  options.limit.depth_max_m = 6e-3;
  options.threads = 2;
  return options;
}

/// The peak steady-state offset at (Ω, ap), computed from scratch at that
/// speed (no period rescaling).
double direct_offset(const Benchmark& b, double spindle, double depth, const AdviceLimits& l) {
  cutting::MillingProcess cut = b.process;
  cut.spindle_rad_s = spindle;
  cut.axial_depth_m = depth;
  const cutting::MillingForceModel force(b.cutter, b.law, cut,
                                         cutting::default_axial_elements(b.cutter, depth));
  OffsetWorkspace workspace;
  return steady_state_offset(modal_dynamics(b.modes), Eigen::Matrix3d::Identity(),
                             force_harmonics(force, l.samples, l.harmonics), workspace)
      .measure(l.measure);
}

/// Exhaustive search on the scan grid: at each speed the deepest Δ-multiple
/// such that every Δ-multiple up to it is stable by a direct FDM solve (the
/// limit is the shallowest unstable depth) and, when given, the offset holds.
double brute_force_mrr(const Benchmark& b, const AdviceLimits& l, const AdviceOptions& o) {
  const stability::RegenerativeModel model(b.cutter, b.law, b.process, b.modes);
  const auto speeds = stability::linear_range(l.speed_min_rad_s, l.speed_max_rad_s, l.speed_count);
  const int steps = static_cast<int>(std::floor(o.limit.depth_max_m / l.depth_step_m + 1e-9));
  double best = 0.0;
  for (const double speed : speeds) {
    int deepest = 0;
    for (int j = 1; j <= steps; ++j) {
      const double depth = j * l.depth_step_m;
      if (spectral_radius_at(model, speed, depth, stability::FloquetMethod::fdm,
                             o.limit.discretization) >= 1.0)
        break;
      if (l.max_offset_m && direct_offset(b, speed, depth, l) > *l.max_offset_m)
        break;
      deepest = j;
    }
    best = std::max(best, material_removal_rate(speed, deepest * l.depth_step_m, b.process, 2));
  }
  return best;
}

TEST(CuttingAdvice, MaterialRemovalRateIsDepthTimesWidthTimesFeedSpeed) {
  cutting::MillingProcess p;
  p.radial_depth_m = 6e-3;
  p.feed_per_tooth_m = 0.05e-3;
  // 3 mm x 6 mm x (0.05 mm x 2 teeth x 10000 rpm = 1000 mm/min) = 18 cm³/min.
  EXPECT_NEAR(material_removal_rate(10000 * kRpm, 3e-3, p, 2) * 1e6 * 60.0, 18.0, 1e-9);
}

TEST(CuttingAdvice, ModalDynamicsReproducesTheReceptance) {
  const Benchmark b;
  const PostureDynamics d = modal_dynamics(b.modes);
  const double omega = 2.0 * kPi * 800.0;
  Eigen::MatrixXcd dynamic = d.stiffness.cast<std::complex<double>>();
  dynamic.real() -= omega * omega * d.mass;
  dynamic.imag() = omega * d.damping;
  const Eigen::Matrix3cd h = d.jacobian.cast<std::complex<double>>() * dynamic.inverse() *
                             d.jacobian.transpose().cast<std::complex<double>>();
  EXPECT_LT((h - b.modes.receptance(omega)).norm(), 1e-9 * b.modes.receptance(omega).norm());
}

TEST(CuttingAdvice, FdmAdviceIsStableTheNextStepIsNotAndNoGridPointIsBetter) {
  const Benchmark b;
  const AdviceLimits limits = benchmark_limits();
  const AdviceOptions options = fdm_options();
  const CuttingAdvice advice =
      advise_cutting(b.cutter, b.law, b.process, {b.modes}, limits, options);
  ASSERT_TRUE(advice.feasible);
  const SpeedAdvice& best = advice.best;
  // Inside the computed diagram and a multiple of the depth step.
  EXPECT_LE(best.depth_m, best.limit_depth_m * (1.0 + 1e-9));
  EXPECT_NEAR(best.depth_m / limits.depth_step_m, std::round(best.depth_m / limits.depth_step_m),
              1e-9);
  EXPECT_GE(advice.margin_to_chatter, 1.0);
  // Independent Floquet check by the other method (SDM) at the same time
  // step: stable at the advice, unstable one depth step deeper. (The limit
  // itself moves with the time step: at 80 steps both depths are stable, so
  // the stable side is also checked there.)
  const stability::RegenerativeModel model(b.cutter, b.law, b.process, b.modes);
  const int steps = options.limit.discretization;
  EXPECT_LT(spectral_radius_at(model, best.spindle_rad_s, best.depth_m,
                               stability::FloquetMethod::sdm, steps),
            1.0);
  EXPECT_GT(spectral_radius_at(model, best.spindle_rad_s, best.depth_m + limits.depth_step_m,
                               stability::FloquetMethod::sdm, steps),
            1.0);
  EXPECT_LT(spectral_radius_at(model, best.spindle_rad_s, best.depth_m,
                               stability::FloquetMethod::sdm, 2 * steps),
            1.0);
  EXPECT_TRUE(advice.check.done);
  EXPECT_LT(advice.check.spectral_radius, 1.0);
  EXPECT_TRUE(advice.check.next_done);
  EXPECT_GE(advice.check.next_spectral_radius, 1.0);
  // MRR reported = ap ae vf, and the best scanned row is not beaten by any.
  EXPECT_NEAR(best.mrr_m3_per_s,
              material_removal_rate(best.spindle_rad_s, best.depth_m, b.process, 2), 1e-18);
  for (const SpeedAdvice& row : advice.scan)
    EXPECT_LE(row.mrr_m3_per_s, best.mrr_m3_per_s);
  // Exhaustive grid: nothing better than the advice within one depth step.
  const double brute = brute_force_mrr(b, limits, options);
  EXPECT_GE(best.mrr_m3_per_s, brute * (1.0 - 1e-12));
  EXPECT_LE(best.mrr_m3_per_s - brute,
            material_removal_rate(limits.speed_max_rad_s, limits.depth_step_m, b.process, 2) +
                1e-15 + (best.stage == 1 ? best.mrr_m3_per_s : 0.0));
  // Runner-ups: local maxima of the scan, best first, all feasible.
  ASSERT_FALSE(advice.peaks.empty());
  for (std::size_t i = 1; i < advice.peaks.size(); ++i)
    EXPECT_GE(advice.peaks[i - 1].mrr_m3_per_s, advice.peaks[i].mrr_m3_per_s);
}

TEST(CuttingAdvice, OffsetLimitHoldsAndBindsWithoutLosingToTheGrid) {
  const Benchmark b;
  AdviceLimits limits = benchmark_limits();
  const AdviceOptions options = fdm_options();
  const CuttingAdvice free_cut =
      advise_cutting(b.cutter, b.law, b.process, {b.modes}, limits, options);
  ASSERT_TRUE(free_cut.feasible);
  // A limit at half the unconstrained advice's offset must bind somewhere.
  limits.max_offset_m = 0.5 * free_cut.best.offset_m;
  const CuttingAdvice advice =
      advise_cutting(b.cutter, b.law, b.process, {b.modes}, limits, options);
  ASSERT_TRUE(advice.feasible);
  const SpeedAdvice& best = advice.best;
  // The expected offset, recomputed at the advised speed from scratch.
  const double offset = direct_offset(b, best.spindle_rad_s, best.depth_m, limits);
  EXPECT_NEAR(best.offset_m, offset, 1e-9 * offset);
  EXPECT_LE(offset, *limits.max_offset_m);
  if (best.offset_limited) {
    EXPECT_GT(direct_offset(b, best.spindle_rad_s, best.depth_m + limits.depth_step_m, limits),
              *limits.max_offset_m);
  }
  EXPECT_LT(best.mrr_m3_per_s, free_cut.best.mrr_m3_per_s);
  for (const SpeedAdvice& row : advice.scan) {
    EXPECT_LE(row.offset_m, *limits.max_offset_m);
    EXPECT_LE(row.depth_m, row.stable_depth_m + 1e-15);
  }
  EXPECT_GE(best.mrr_m3_per_s, brute_force_mrr(b, limits, options) * (1.0 - 1e-12));
}

TEST(CuttingAdvice, ZeroOrderAdviceKeepsTheSafetyFactorAtEverySpeed) {
  const Benchmark b;
  AdviceLimits limits = benchmark_limits();
  limits.stability_margin = 0.8;
  AdviceOptions options = fdm_options();
  options.limit.method = LimitMethod::zoa;
  const CuttingAdvice advice =
      advise_cutting(b.cutter, b.law, b.process, {b.modes}, limits, options);
  ASSERT_TRUE(advice.feasible);
  EXPECT_GE(advice.margin_to_chatter, 1.0 / 0.8 - 1e-9);
  stability::ZeroOrderOptions zoa;
  zoa.depth_max_m = options.limit.depth_max_m;
  const stability::ZeroOrderSolver solver(
      stability::RegenerativeModel(b.cutter, b.law, b.process, b.modes), zoa);
  for (const SpeedAdvice& row : advice.scan) {
    const double limit = solver.limit(row.spindle_rad_s).depth_limit_m;
    EXPECT_NEAR(row.limit_depth_m, limit, 1e-12);
    EXPECT_LE(row.depth_m, 0.8 * limit * (1.0 + 1e-9));
    // The deepest step: one more would leave s · a_lim.
    EXPECT_GT(row.depth_m + limits.depth_step_m, 0.8 * limit);
  }
  EXPECT_TRUE(advice.check.done);  // the independent FDM solve at the advice
  EXPECT_EQ(advice.check.method, "fdm");
}

TEST(CuttingAdvice, SeveralStationsTakeTheWeakest) {
  const Benchmark b;
  const double k = 0.03993 * std::pow(2.0 * kPi * 922.0, 2);
  const dynamics::ModalModel soft({dynamics::directional_mode(0, 922.0, 0.011, 0.5 * k),
                                   dynamics::directional_mode(1, 922.0, 0.011, 0.5 * k)});
  AdviceLimits limits = benchmark_limits();
  limits.refine_count = 0;
  AdviceOptions options = fdm_options();
  options.limit.method = LimitMethod::zoa;
  const CuttingAdvice both =
      advise_cutting(b.cutter, b.law, b.process, {b.modes, soft}, limits, options);
  const CuttingAdvice alone = advise_cutting(b.cutter, b.law, b.process, {soft}, limits, options);
  ASSERT_EQ(both.scan.size(), alone.scan.size());
  for (std::size_t i = 0; i < both.scan.size(); ++i) {
    EXPECT_DOUBLE_EQ(both.scan[i].limit_depth_m, alone.scan[i].limit_depth_m);
    EXPECT_EQ(both.scan[i].station, 1);
  }
}

TEST(CuttingAdvice, RejectsBadLimits) {
  const Benchmark b;
  AdviceLimits limits = benchmark_limits();
  const AdviceOptions options = fdm_options();
  limits.stability_margin = 1.5;
  EXPECT_THROW(advise_cutting(b.cutter, b.law, b.process, {b.modes}, limits, options),
               std::invalid_argument);
  limits = benchmark_limits();
  limits.depth_step_m = 1.0;
  EXPECT_THROW(advise_cutting(b.cutter, b.law, b.process, {b.modes}, limits, options),
               std::invalid_argument);
  EXPECT_THROW(advise_cutting(b.cutter, b.law, b.process, {}, benchmark_limits(), options),
               std::invalid_argument);
}

/// The KR270-class example: its robot and cut.
job::Job kr270_job() {
  return job::load_job(std::string(ROBOMILL_SOURCE_DIR) +
                       "/examples/003_kr270_cutting_advice.yaml");
}

TEST(RedundancyStudy, AngleZeroIsTheRobotPostureAndTheBestConstantAngleIsTheMaxMin) {
  const job::Job job = kr270_job();
  const robot::RobotModel robot(job.robot->description);
  const Eigen::VectorXd q0 =
      Eigen::Map<const Eigen::VectorXd>(job.robot->posture_rad.data(), robot.dof());
  const Eigen::Isometry3d pose = robot::tool_pose(robot, q0);
  // Two stations: the posture itself and a point 100 mm further along x.
  std::vector<PlacedPoint> points = {
      {pose.translation(), pose.linear()},
      {pose.translation() + Eigen::Vector3d(0.1, 0, 0), pose.linear()}};
  RedundancyOptions options;
  options.angles_rad = {-60 * kPi / 180, -30 * kPi / 180, 0.0, 30 * kPi / 180, 60 * kPi / 180};
  options.spindle_rad_s = {job.process->spindle_rad_s};
  options.limit.method = LimitMethod::zoa;
  options.limit.depth_max_m = 8e-3;
  options.threads = 2;
  const RedundancyStudy study = redundancy_study(robot, points, q0, tool::Tool(*job.tool),
                                                 *job.cutting, *job.process, options);
  ASSERT_EQ(study.points.size(), 2u);
  // ψ = 0 at the posture's own pose: the IK returns the posture, and the
  // limit equals the one from the job's from_robot modes (analysis::structure_modes).
  const RedundancySample& zero = study.points[0].samples[2];
  ASSERT_TRUE(zero.reachable);
  EXPECT_LT((zero.q - q0).norm(), 1e-6);
  stability::ZeroOrderOptions zoa;
  zoa.depth_max_m = 8e-3;
  const stability::ZeroOrderSolver direct(
      stability::RegenerativeModel(tool::Tool(*job.tool), *job.cutting, *job.process,
                                   analysis::structure_modes(job)),
      zoa);
  EXPECT_NEAR(zero.min_limit_m, direct.limit(job.process->spindle_rad_s).depth_limit_m,
              1e-6 * zero.min_limit_m);
  // Per point: the best angle has the largest a_min; the constant angle
  // maximizes the weakest point's a_min.
  for (const PointRedundancy& p : study.points) {
    ASSERT_GE(p.best, 0);
    for (const RedundancySample& s : p.samples) {
      if (s.reachable) {
        EXPECT_LE(s.min_limit_m, p.samples[std::size_t(p.best)].min_limit_m);
      }
    }
  }
  ASSERT_GE(study.best_constant, 0);
  for (std::size_t a = 0; a < options.angles_rad.size(); ++a) {
    const double weakest =
        std::min(study.points[0].samples[a].min_limit_m, study.points[1].samples[a].min_limit_m);
    EXPECT_LE(weakest, study.constant_min_limit_m);
  }
  // Turning the robot about the tool axis changes its modes in the cutting
  // frame, so the limit depends on the angle.
  double lowest = INFINITY, highest = 0.0;
  for (const RedundancySample& s : study.points[0].samples) {
    lowest = std::min(lowest, s.min_limit_m);
    highest = std::max(highest, s.min_limit_m);
  }
  EXPECT_GT(highest, 1.01 * lowest);
}

TEST(RedundancyStudy, AThreeJointRobotHasNoRedundancy) {
  const job::Job job = job::load_job(std::string(ROBOMILL_SOURCE_DIR) +
                                     "/examples/004_kr300_pose_optimization.yaml");
  const robot::RobotModel robot(job.robot->description);
  RedundancyOptions options;
  options.angles_rad = {0.0};
  options.spindle_rad_s = {job.process->spindle_rad_s};
  options.limit.depth_max_m = 5e-3;
  EXPECT_THROW(redundancy_study(robot, {PlacedPoint{}}, Eigen::VectorXd::Zero(robot.dof()),
                                tool::Tool(*job.tool), *job.cutting, *job.process, options),
               std::invalid_argument);
}

}  // namespace
}  // namespace test_cutting_advice_cpp
}  // namespace robomill::planning
