// The robot along the program (issue 19, "How it will be judged"): a straight
// cut reduces to the single-cut zero-order limit of `robomill stability` at
// the sample's posture (the same regenerative model, the robot's modes at that
// posture, process_damped_limits as the stability command calls it); the
// shortcut's interpolated limits against the direct ones at every sample; the
// deflection's sign in down and up milling; postures by inverse kinematics;
// unreachable samples reported by program line.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <numbers>
#include <sstream>
#include <tuple>

#include <fmt/format.h>

#include "robomill/analysis/deflection_sweep.hpp"
#include "robomill/analysis/robot_path_setup.hpp"
#include "robomill/core/error.hpp"
#include "robomill/cutting/milling_forces.hpp"
#include "robomill/job/job.hpp"
#include "robomill/planning/path_performance.hpp"
#include "robomill/robot/joint_dynamics.hpp"
#include "robomill/robot/kinematics.hpp"
#include "robomill/robot/stiffness.hpp"
#include "robomill/robot_path/deflection_compensation.hpp"
#include "robomill/robot_path/program_optimization.hpp"
#include "robomill/robot_path/robot_along_path.hpp"
#include "robomill/stability/process_damping.hpp"
#include "robomill/stability/regenerative_model.hpp"
#include "support/case004.hpp"
#include "support/kr270_cell.hpp"

namespace robomill::robot_path {
namespace test_robot_along_path_cpp {
namespace {

constexpr double kPi = std::numbers::pi;
const std::filesystem::path kSource = ROBOMILL_SOURCE_DIR;

// The KR 270 of examples/toolpath_robot_pocket.yaml, its modes from the model.
job::Job kr270_job(const std::string& extra = "",
                   const std::vector<job::Override>& overrides = {}) {
  return job::parse_job(support::kr270_cell_yaml() + extra, kSource / "tests" / "job.yaml",
                        overrides);
}

using support::side_cut_sample;

struct Fixture {
  job::Job job;
  analysis::RobotPathSetup setup;
  toolpath::Tooling tooling;
  explicit Fixture(const std::string& extra = "", const std::vector<job::Override>& overrides = {})
      : job(kr270_job(extra, overrides)), setup(std::move(*analysis::robot_path_setup(job, 2))) {
    tooling.emplace(0, tool::Tool(*job.tool));
  }
  RobotAlongPath along() const {
    return RobotAlongPath(*setup.model, setup.structure, tooling, *job.cutting, setup.stability,
                          setup.settings);
  }
};

// A recorded sample an angle search returned: its posture turns the tool
// by ψ about the (vertical) axis, its margin is the direct limit there, at
// least the search's smallest.
void expect_at_angle(const Fixture& f, const RobotAlongPath& along, const RecordedSample& r,
                     double psi_rad, double min_margin) {
  const Eigen::Isometry3d pose = robot::tool_pose(*f.setup.model, r.q_rad);
  EXPECT_LT((pose.linear() - robot::tool_orientation_about_axis(Eigen::Vector3d::UnitZ(), psi_rad))
                .norm(),
            1e-6);
  const double direct = along.direct_limit(r.sample, r.q_rad).depth_limit_m / 3e-3;
  EXPECT_NEAR(r.margin, direct, 1e-9 * direct);
  EXPECT_GE(r.margin, min_margin * (1.0 - 1e-12));
}

TEST(RobotAlongPath, StraightCutReducesToTheSingleCutLimitAtItsPosture) {
  // Down milling, ae = 2.5 mm on a 10 mm cutter: entry π − acos(1 − ae/R).
  const double entry = kPi - std::acos(1.0 - 2.5 / 5.0);
  Fixture f;
  RobotAlongPath along = f.along();
  std::vector<toolpath::PathSample> samples;
  for (int i = 0; i < 9; ++i)
    samples.push_back(side_cut_sample((10.0 + 5.0 * i) * 1e-3, entry, kPi));
  std::vector<RobotSample> out(samples.size());
  along.evaluate(samples, out);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    ASSERT_TRUE(out[i].reachable) << i;
    ASSERT_TRUE(out[i].stability) << i;
    // `robomill stability` at this posture: the robot's modes along its own
    // tool axes (analysis::structure_modes, from_robot), the job's cut with this
    // ae, the zero-order diagram through process_damped_limits.
    const Eigen::VectorXd q = out[i].q_rad;
    const dynamics::ModalModel modes = robot::tool_tip_modal_model(
        *f.setup.model, q, robot::tool_pose(*f.setup.model, q).linear().transpose());
    cutting::MillingProcess process;
    process.spindle_rad_s = samples[i].spindle_rad_s;
    process.feed_per_tooth_m = samples[i].feed_per_tooth_m;
    process.radial_depth_m = 2.5e-3;
    process.direction = cutting::MillingDirection::down;
    const stability::RegenerativeModel model(tool::Tool(*f.job.tool), *f.job.cutting, process,
                                             modes);
    stability::ProcessDampedOptions options;
    options.zero_order.depth_max_m = 10e-3;
    const stability::ZeroOrderLimit single =
        stability::process_damped_limits(model, std::nullopt, {process.spindle_rad_s}, options)
            .front();
    // Exact samples are the single-cut computation; interpolated ones are
    // within the tolerance (2 %).
    const double tolerance = out[i].exact ? 1e-9 : 0.02;
    EXPECT_NEAR(out[i].depth_limit_m, single.depth_limit_m, tolerance * single.depth_limit_m)
        << "sample " << i << (out[i].exact ? " (exact)" : " (interpolated)");
    if (out[i].exact && single.limited) {
      EXPECT_NEAR(out[i].chatter_frequency_hz, single.chatter_frequency_hz,
                  1e-9 * single.chatter_frequency_hz);
    }
    EXPECT_NEAR(out[i].margin, out[i].depth_limit_m / 3e-3, 1e-12);
    EXPECT_EQ(out[i].chatter, 3e-3 >= out[i].depth_limit_m);
  }
  EXPECT_TRUE(out.front().exact);
  EXPECT_TRUE(out.back().exact);
}

TEST(RobotAlongPath, InterpolatedLimitsStayWithinTheToleranceOfTheDirectOnes) {
  // A long straight cut across the part (the posture moves), then a change
  // of engagement: every interpolated limit against the direct one.
  Fixture f("robot_path: {tolerance: 1 %, max_span: 200, check_every: 0}\n");
  RobotAlongPath along = f.along();
  const double entry = kPi - std::acos(1.0 - 2.5 / 5.0);
  std::vector<toolpath::PathSample> samples;
  for (int i = 0; i < 240; ++i) {
    const double x = -150e-3 + 1.5e-3 * i;
    samples.push_back(side_cut_sample(x, i < 160 ? entry : 0.0, i < 160 ? kPi : kPi, 10 + i / 40));
  }
  std::vector<RobotSample> out(samples.size());
  along.evaluate(samples, out);
  int interpolated = 0;
  double worst = 0.0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    ASSERT_TRUE(out[i].stability);
    if (out[i].exact)
      continue;
    ++interpolated;
    const double direct = along.direct_limit(samples[i], out[i].q_rad).depth_limit_m;
    worst = std::max(worst, std::abs(out[i].depth_limit_m - direct) / direct);
  }
  const RobotPathSummary summary = along.finish();
  EXPECT_GT(interpolated, 100) << "the shortcut should save most solves on a smooth cut";
  EXPECT_LT(summary.exact_limits, samples.size() / 2);
  EXPECT_LE(worst, 0.01) << "largest interpolation error " << worst;
}

// analysis::BlockSharing (MPI ranks): a block computed by another process
// (its postures walked there too, its results packed and unpacked) gives the
// results and totals of the single process, bit for bit.
TEST(RobotAlongPath, BlocksComputedElsewhereGiveTheSameResults) {
  Fixture f("robot_path: {tolerance: 1 %, max_span: 20, check_every: 5}\n");
  const double entry = kPi - std::acos(1.0 - 2.5 / 5.0);
  std::vector<std::vector<toolpath::PathSample>> blocks(3);
  for (int i = 0; i < 150; ++i)
    blocks[static_cast<std::size_t>(i / 50)].push_back(
        side_cut_sample(-100e-3 + 1.5e-3 * i, i < 90 ? entry : 0.0, kPi, 10 + i / 20));
  RobotAlongPath alone = f.along(), root = f.along(), other = f.along();
  const int dof = f.setup.model->dof();
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    std::vector<RobotSample> expected(blocks[b].size()), here(blocks[b].size()),
        there(blocks[b].size());
    alone.evaluate(blocks[b], expected);
    root.postures(blocks[b], here);
    other.postures(blocks[b], there);
    ShortcutChecks checks;
    if (b == 1) {  // computed by the other process, sent packed
      checks = other.compute(blocks[b], there);
      std::vector<double> message(packed_size(dof) * there.size());
      for (std::size_t i = 0; i < there.size(); ++i)
        pack(there[i], dof, message.data() + i * packed_size(dof));
      for (std::size_t i = 0; i < here.size(); ++i)
        here[i] = unpack(message.data() + i * packed_size(dof), dof);
    } else {
      checks = root.compute(blocks[b], here);
    }
    root.record(blocks[b], here, checks);
    for (std::size_t i = 0; i < here.size(); ++i) {
      std::vector<double> a(packed_size(dof)), c(packed_size(dof));
      pack(expected[i], dof, a.data());
      pack(here[i], dof, c.data());
      ASSERT_EQ(a, c) << "block " << b << " sample " << i;
      ASSERT_EQ(expected[i].q_rad, here[i].q_rad);
    }
  }
  const RobotPathSummary a = alone.finish(), c = root.finish();
  EXPECT_GT(a.checked, 0u);
  EXPECT_EQ(a.exact_limits, c.exact_limits);
  EXPECT_EQ(a.checked, c.checked);
  EXPECT_EQ(a.shortcut_max_error, c.shortcut_max_error);
  EXPECT_EQ(a.min_margin, c.min_margin);
  EXPECT_EQ(a.min_margin_line, c.min_margin_line);
  EXPECT_EQ(a.max_form_error_m, c.max_form_error_m);
  ASSERT_EQ(a.worst_lines.size(), c.worst_lines.size());
  for (std::size_t k = 0; k < a.worst_lines.size(); ++k)
    EXPECT_EQ(a.worst_lines[k].line, c.worst_lines[k].line);
}

TEST(RobotAlongPath, DownMillingLeavesMaterialUpMillingTakesIt) {
  // The mean force pushes the tool away from the wall in down milling (the
  // wall at −y of the milling frame) and pulls it in in up milling.
  Fixture f;
  RobotAlongPath along = f.along();
  const double ae = 2.5e-3, r = 5e-3;
  toolpath::PathSample down = side_cut_sample(30e-3, kPi - std::acos(1.0 - ae / r), kPi);
  toolpath::PathSample up = side_cut_sample(30e-3, 0.0, std::acos(1.0 - ae / r));
  // The mean forces on the tool of the two cuts by `robomill forces`'s
  // mechanism (the milling frame is the workpiece frame here: feed +x).
  auto mean_force = [&](cutting::MillingDirection direction) {
    cutting::MillingProcess process;
    process.spindle_rad_s = down.spindle_rad_s;
    process.feed_per_tooth_m = down.feed_per_tooth_m;
    process.axial_depth_m = 3e-3;
    process.radial_depth_m = ae;
    process.direction = direction;
    const tool::Tool cutter(*f.job.tool);
    const cutting::MillingForceModel model(cutter, *f.job.cutting, process,
                                           cutting::default_axial_elements(cutter, 3e-3));
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int k = 0; k < 720; ++k)
      mean += model.at(2.0 * kPi * k / 720.0).force_n;
    return Eigen::Vector3d(mean / 720.0);
  };
  down.force_mean_n = mean_force(cutting::MillingDirection::down);
  up.force_mean_n = mean_force(cutting::MillingDirection::up);
  EXPECT_GT(down.force_mean_n.y(), 0.0) << "down milling pushes the tool off the wall at -y";
  EXPECT_GT(up.force_mean_n.y(), 0.0) << "up milling pulls the tool into the wall at +y";
  std::vector<toolpath::PathSample> samples = {down, up};
  std::vector<RobotSample> out(2);
  along.evaluate(samples, out);
  ASSERT_TRUE(out[0].wall && out[1].wall);
  EXPECT_GT(out[0].form_error_m, 0.0);
  EXPECT_LT(out[1].form_error_m, 0.0);
  // The deflection is the robot's compliance plus the tool's, along +y.
  EXPECT_GT(out[0].deflection_m.y(), 0.0);
  const Eigen::Matrix3d c =
      robot::translational_compliance(*f.setup.model, Eigen::VectorXd(out[0].q_rad));
  const double robot_only = (c * down.force_mean_n).y();
  EXPECT_GT(out[0].deflection_m.y(), robot_only);  // the tool adds, never cancels
}

TEST(RobotAlongPath, ContactDeflectionReducesToTheDeflectionCommandAtItsPosture) {
  // robot_path.deflection: contact — at a straight down-milling wall the
  // sample's deflection and form error are `robomill deflection`'s node
  // solution (000 §4, analysis::deflection_sweep) for a job at the sample's
  // posture, feed, ae and ap, to round-off. The feed runs along the tool
  // frame's x at ψ = 0, so the two frames are the same (checked first).
  const double ae = 2.5e-3, radius = 5e-3;
  Fixture f("robot_path: {deflection: contact}\n");
  RobotAlongPath along = f.along();
  toolpath::PathSample sample = side_cut_sample(30e-3, kPi - std::acos(1.0 - ae / radius), kPi);
  sample.radial_width_m = ae;
  std::vector<toolpath::PathSample> samples = {sample};
  std::vector<RobotSample> out(1);
  along.evaluate(samples, out);
  ASSERT_TRUE(out[0].reachable);
  ASSERT_TRUE(out[0].contact);
  const Eigen::VectorXd q(out[0].q_rad);
  const Eigen::Matrix3d tool = robot::tool_pose(*f.setup.model, q).linear();
  ASSERT_LT((tool - Eigen::Matrix3d::Identity()).norm(), 1e-9) << tool;

  std::string posture = "[";
  for (int j = 0; j < q.size(); ++j)
    posture += fmt::format("{}{:.17g} deg", j ? ", " : "", q[j] * 180.0 / kPi);
  const job::Job single = kr270_job(
      "process: {spindle: 8000 rpm, feed_per_tooth: 0.05 mm, ap: 3 mm, ae: 2.5 mm, "
      "direction: down}\n"
      "deflection: {depths: {from: 3 mm, to: 4 mm, count: 1}}\n",
      {{"robot.posture", posture + "]"}});
  const analysis::DeflectionSweep sweep = analysis::deflection_sweep(single, 1);
  ASSERT_EQ(sweep.boundaries.size(), 1u);
  const deflection::ContactBoundary& boundary = sweep.boundaries.front();
  double worst = 0.0;
  for (int k = 1; k <= static_cast<int>(boundary.positions.size()); ++k) {
    const double dy = boundary.generating(k).deflection_m.y();
    worst = std::abs(dy) > std::abs(worst) ? dy : worst;
  }
  // Round-off here: the command's frame is the tool frame at q, the
  // sample's the milling frame, equal to the IK's orientation tolerance
  // (1e-9 rad; measured 1.2e-12 relative on the tip's x).
  EXPECT_GT(worst, 0.0) << "down milling leaves material";
  EXPECT_NEAR(out[0].form_error_m, worst, 1e-9 * std::abs(worst));
  const Eigen::Vector2d tip = boundary.generating(1).deflection_m;
  EXPECT_NEAR(out[0].deflection_m.x(), tip.x(), 1e-9 * tip.norm());
  EXPECT_NEAR(out[0].deflection_m.y(), tip.y(), 1e-9 * tip.norm());
  // The static model at the same sample, for the record: the same sign, a
  // different model (a point load at mid-depth, the tip's deflection).
  Fixture s;
  RobotAlongPath static_along = s.along();
  std::vector<RobotSample> static_out(1);
  static_along.evaluate(samples, static_out);
  EXPECT_FALSE(static_out[0].contact);
}

// Issue 19, "How it will be judged": 004's rectangle path at 004's poses
// gives `robomill optimize`'s d_m. examples/004_kr300_pose_optimization.yaml
// (the 3-joint flexible robot, the size-dependent law, the startup measure
// with 60 harmonics and 256 instants) with `robot_path: {offset: {}}`: the
// 20 points of 004's groove (§4.1, Fig. 5b) as program samples with the job's
// cut (up milling, ae = 4 mm, ap = 2 mm, fz = 0.12 mm, 1000 rpm) as their
// engagement, placed at each of Table 2's six poses. The program's d_i and
// their mean against planning::evaluate_path — what `robomill optimize`
// reports for its listed poses. Both take 004 Eq 1-2 at the posture found by
// position-only inverse kinematics: optimize's from the job's posture at
// every point, the program's from the posture before, so the two postures
// agree to the IK's tolerance (1e-9 m) and the offsets to 1e-7 relative.
TEST(RobotAlongPath, RectanglePathOf004GivesTheOptimizeCommandsDm) {
  std::ifstream file(kSource / "examples" / "004_kr300_pose_optimization.yaml");
  std::stringstream buffer;
  buffer << file.rdbuf();
  const std::string example = buffer.str();
  const std::size_t at = example.find("workpiece:\n");
  ASSERT_NE(at, std::string::npos);
  const double poses[][3] = {{600, 200, 60}, {200, 300, 30}, {300, -400, 60},
                             {500, -500, 0}, {0, 0, 0},      {0, -460, 0}};
  for (const auto& p : poses) {
    std::string text = example;
    text.insert(at + 11,
                fmt::format("  pose: {{x: {} mm, y: {} mm, theta: {} deg}}\n", p[0], p[1], p[2]));
    text += "robot_path: {offset: {}}\n";
    const job::Job job = job::parse_job(text, kSource / "examples" / "004.yaml");
    analysis::RobotPathSetup setup = std::move(*analysis::robot_path_setup(job, 2));
    ASSERT_TRUE(setup.settings.offset.enabled);
    ASSERT_EQ(setup.settings.offset.measure, job.optimize->measure);
    toolpath::Tooling tooling;
    tooling.emplace(0, tool::Tool(*job.tool));
    RobotAlongPath along(*setup.model, setup.structure, tooling, *job.cutting, setup.stability,
                         setup.settings);

    // 004's own evaluation (compute_optimize's problem, tests/support/case004.hpp).
    const test::Case004 case004;
    const planning::PathPerformance reference =
        planning::evaluate_path(case004.robot, case004.problem(), *job.workpiece->pose, 2);
    ASSERT_TRUE(reference.reachable());

    // The same path as program samples.
    const double radius = 0.5 * case004.cutter.diameter_m();
    std::vector<toolpath::PathSample> samples;
    for (std::size_t i = 0; i < job.path.size(); ++i) {
      toolpath::PathSample s;
      s.line = static_cast<int>(i) + 1;
      s.tip_m = job.path[i].position_m;
      s.axis = Eigen::Vector3d::UnitZ();
      s.feed_direction = job.path[i].feed_direction;
      s.spindle_rad_s = job.process->spindle_rad_s;
      s.feed_per_tooth_m = job.process->feed_per_tooth_m;
      s.feed_m_s = 0.01;
      s.analysed = true;
      s.axial_depth_m = job.process->axial_depth_m;
      s.entry_rad = 0.0;
      s.exit_rad = std::acos(1.0 - job.process->radial_depth_m / radius);
      s.engaged_rad = s.exit_rad;
      s.arcs = 1;
      samples.push_back(s);
    }
    std::vector<RobotSample> out(samples.size());
    along.evaluate(samples, out);
    const RobotPathSummary summary = along.finish();
    double worst = 0.0;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      ASSERT_TRUE(out[i].has_offset) << i;
      const double expected = reference.points[i].d_m;
      worst = std::max(worst, std::abs(out[i].steady_offset_m - expected) / expected);
      EXPECT_NEAR(out[i].steady_offset_m, expected, 1e-7 * expected)
          << "pose " << p[0] << ", " << p[1] << ", " << p[2] << " point " << i + 1;
    }
    EXPECT_EQ(summary.offset_samples, samples.size());
    EXPECT_NEAR(summary.mean_offset_m, reference.dm_m, 1e-7 * reference.dm_m);
    std::cout << fmt::format(
        "004 pose [{}, {}, {}]: optimize dm {:.6f} mm, program {:.6f} mm, largest point "
        "difference {:.1e} relative\n",
        p[0], p[1], p[2], reference.dm_m * 1e3, summary.mean_offset_m * 1e3, worst);
  }
}

TEST(RobotAlongPath, PosturesReachTheTipWithTheRedundancyAngle) {
  Fixture f("robot_path: {redundancy: 20 deg}\n");
  RobotAlongPath along = f.along();
  const double entry = kPi - std::acos(1.0 - 2.5 / 5.0);
  std::vector<toolpath::PathSample> samples = {side_cut_sample(10e-3, entry, kPi),
                                               side_cut_sample(50e-3, entry, kPi)};
  std::vector<RobotSample> out(2);
  along.evaluate(samples, out);
  for (std::size_t i = 0; i < 2; ++i) {
    ASSERT_TRUE(out[i].reachable);
    const Eigen::Isometry3d pose = robot::tool_pose(*f.setup.model, out[i].q_rad);
    const Eigen::Vector3d expected = f.setup.settings.workpiece_to_cell * samples[i].tip_m;
    EXPECT_LT((pose.translation() - expected).norm(), 1e-8);
    EXPECT_LT((pose.linear() -
               robot::tool_orientation_about_axis(Eigen::Vector3d::UnitZ(), 20.0 * kPi / 180.0))
                  .norm(),
              1e-7);
    EXPECT_GT(out[i].singularity, 0.0);
    EXPECT_GT(out[i].joint_margin_rad, 0.0);
  }
}

// A program that fixes the tool's rotation about its axis (a KRL frame,
// PathSample::oriented) sets ψ at each sample: the robot's tool x lands on
// the program's x (in the cell), whatever robot_path.redundancy says.
TEST(RobotAlongPath, OrientedSamplesTakeTheProgramsRedundancyAngle) {
  Fixture f("robot_path: {redundancy: 20 deg}\n");
  RobotAlongPath along = f.along();
  const double entry = kPi - std::acos(1.0 - 2.5 / 5.0);
  std::vector<toolpath::PathSample> samples;
  for (const double psi_deg : {-30.0, 0.0, 40.0}) {
    toolpath::PathSample s = side_cut_sample((10.0 + psi_deg) * 1e-3 + 40e-3, entry, kPi);
    s.oriented = true;
    s.tool_x = Eigen::Vector3d(std::cos(psi_deg * kPi / 180.0), std::sin(psi_deg * kPi / 180.0), 0);
    samples.push_back(s);
  }
  samples.push_back(side_cut_sample(60e-3, entry, kPi));  // not oriented: the job's 20°
  std::vector<RobotSample> out(samples.size());
  along.evaluate(samples, out);
  const Eigen::Matrix3d to_cell = f.setup.settings.workpiece_to_cell.linear();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    ASSERT_TRUE(out[i].reachable) << i;
    const Eigen::Matrix3d tool = robot::tool_pose(*f.setup.model, out[i].q_rad).linear();
    const Eigen::Vector3d expected_x =
        samples[i].oriented
            ? Eigen::Vector3d(to_cell * samples[i].tool_x)
            : robot::tool_orientation_about_axis(to_cell * samples[i].axis, 20.0 * kPi / 180.0)
                  .col(0);
    EXPECT_LT((tool.col(0) - expected_x).norm(), 1e-7) << i;
    EXPECT_LT((tool.col(2) - to_cell * samples[i].axis).norm(), 1e-7) << i;
  }
  // The cell x is the workpiece x here (θp = 0), so ψ is the program's angle.
  EXPECT_NEAR(out[0].redundancy_rad, -30.0 * kPi / 180.0, 1e-12);
  EXPECT_NEAR(out[1].redundancy_rad, 0.0, 1e-12);
  EXPECT_NEAR(out[2].redundancy_rad, 40.0 * kPi / 180.0, 1e-12);
  EXPECT_NEAR(out[3].redundancy_rad, 20.0 * kPi / 180.0, 1e-12);
  const RobotPathSummary summary = along.finish();
  EXPECT_EQ(summary.oriented_samples, 3u);
  EXPECT_NEAR(summary.min_redundancy_rad, -30.0 * kPi / 180.0, 1e-12);
  EXPECT_NEAR(summary.max_redundancy_rad, 40.0 * kPi / 180.0, 1e-12);
}

TEST(RobotAlongPath, UnreachableSamplesAreReportedByLineNotSkipped) {
  Fixture f;
  RobotAlongPath along = f.along();
  const double entry = kPi - std::acos(1.0 - 2.5 / 5.0);
  // 3 m further than the part: beyond a 2.9 m robot's reach.
  std::vector<toolpath::PathSample> samples = {side_cut_sample(10e-3, entry, kPi, 5),
                                               side_cut_sample(3.0, entry, kPi, 7),
                                               side_cut_sample(3.1, entry, kPi, 8)};
  std::vector<RobotSample> out(3);
  along.evaluate(samples, out);
  EXPECT_TRUE(out[0].reachable);
  EXPECT_FALSE(out[1].reachable);
  EXPECT_FALSE(out[1].stability);
  const RobotPathSummary summary = along.finish();
  EXPECT_EQ(summary.unreachable, 2u);
  EXPECT_EQ(summary.first_unreachable_line, 7);
  EXPECT_EQ(summary.unreachable_lines, (std::vector<int>{7, 8}));
}

TEST(RobotAlongPath, SetupNamesWhatIsMissing) {
  // robot_path without a workpiece pose.
  const std::string no_pose = R"(
tool: {type: flat, diameter: 10 mm, teeth: 3, helix: 30 deg, overhang: 40 mm}
cutting: {law: linear, Ktc: 796 N/mm^2, Krc: 169 N/mm^2}
robot:
  dh:
    - {a: 0 mm, alpha: 0 deg, d: 0 mm, theta: 0 deg}
  joint_stiffness: [1e6]
  posture: [0]
robot_path: {redundancy: 0 deg}
)";
  try {
    (void)analysis::robot_path_setup(job::parse_job(no_pose, kSource / "tests" / "job.yaml"), 1);
    FAIL() << "expected an InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("workpiece.pose"), std::string::npos) << error.what();
  }
  // Without a robot the program runs as before.
  const job::Job plain = job::parse_job(
      "tool: {type: flat, diameter: 10 mm, teeth: 3, overhang: 40 mm}\n"
      "cutting: {law: linear, Ktc: 796 N/mm^2, Krc: 169 N/mm^2}\n",
      kSource / "tests" / "job.yaml");
  EXPECT_FALSE(analysis::robot_path_setup(plain, 1).has_value());
}

TEST(ProgramOptimization, ChosenSpeedRaisesTheSmallestMarginAndPutsNoSafeSampleAtRisk) {
  // A full slot 3 mm deep at 8000 rpm across the part: the robot's modes
  // make parts of it chatter. One region (one S word), 41 candidate speeds.
  Fixture f("robot_path: {risk_margin: 1.2}\n");
  RobotAlongPath along = f.along();
  std::vector<toolpath::PathSample> samples;
  for (int i = 0; i < 30; ++i)
    samples.push_back(side_cut_sample((5.0 + 2.0 * i) * 1e-3, 0.0, kPi));
  std::vector<RobotSample> out(samples.size());
  along.evaluate(samples, out);
  std::vector<RecordedSample> recorded;
  for (std::size_t i = 0; i < samples.size(); ++i)
    recorded.push_back({samples[i], out[i].q_rad, out[i].margin});
  toolpath::Program program;
  toolpath::Move move;
  move.spindle_rad_s = samples[0].spindle_rad_s;
  move.line = 1;
  program.moves.push_back(move);
  const std::vector<SpindleRegion> regions = spindle_regions(program);
  ASSERT_EQ(regions.size(), 1u);
  std::vector<double> candidates;
  for (int k = 0; k <= 40; ++k)
    candidates.push_back((6000.0 + 100.0 * k) * 2.0 * kPi / 60.0);
  const auto choices = choose_spindle_speeds(along, regions, recorded, candidates, 0.02, 2);
  ASSERT_EQ(choices.size(), 1u);
  const SpindleChoice& c = choices[0];
  EXPECT_EQ(c.samples, samples.size());
  EXPECT_GE(c.min_margin_after, c.min_margin_before);
  EXPECT_LE(c.at_risk_after, c.at_risk_before);
  if (!c.changed())
    GTEST_SKIP() << "no better speed in 6000-10000 rpm; margin " << c.min_margin_before;
  EXPECT_NE(std::find(candidates.begin(), candidates.end(), c.chosen_rad_s), candidates.end());
  // The claim, checked sample by sample with the direct limit at the new speed.
  double smallest = 1e300;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    toolpath::PathSample moved = samples[i];
    moved.spindle_rad_s = c.chosen_rad_s;
    const double margin = along.direct_limit(moved, out[i].q_rad).depth_limit_m / 3e-3;
    smallest = std::min(smallest, margin);
    if (out[i].margin > 1.2) {
      EXPECT_GT(margin, 1.2) << "sample " << i << " was safe and is now at risk";
    }
  }
  EXPECT_NEAR(smallest, c.min_margin_after, 1e-9 * smallest);
  EXPECT_GT(c.min_margin_after, c.min_margin_before * 1.02);
}

TEST(ProgramOptimization, RedundancyAngleOfASpindleAlongJointSixChangesNothing) {
  // The examples' spindle lies along joint 6: ψ turns joint 6 and the
  // round tool only, so the margins cannot change and ψ is kept.
  Fixture f;
  RobotAlongPath along = f.along();
  std::vector<toolpath::PathSample> samples;
  for (int i = 0; i < 8; ++i)
    samples.push_back(side_cut_sample((5.0 + 7.0 * i) * 1e-3, 0.0, kPi));
  std::vector<RobotSample> out(samples.size());
  along.evaluate(samples, out);
  std::vector<RecordedSample> recorded;
  for (std::size_t i = 0; i < samples.size(); ++i)
    recorded.push_back({samples[i], out[i].q_rad, out[i].margin});
  const std::vector<double> psi = {-kPi / 2, -kPi / 4, kPi / 4, kPi / 2};
  const RedundancyChoice c = choose_redundancy_angle(along, recorded, psi, 0.02, 2);
  ASSERT_EQ(c.candidates.size(), psi.size());
  for (const auto& candidate : c.candidates) {
    EXPECT_EQ(candidate.unreachable, 0u);
    EXPECT_NEAR(candidate.min_margin, c.min_margin_before, 1e-6 * c.min_margin_before);
  }
  EXPECT_FALSE(c.changed());
}

TEST(ProgramOptimization, RedundancyAngleOfAnOffsetSpindleIsChosenOnItsMargins) {
  // A spindle tilted 60° on the flange (an angle head): ψ now moves the
  // wrist and the arm. Every candidate's claim is checked
  // against the direct limit at the posture it reports.
  Fixture f("", {{"robot.tool", "{xyz: [0, 0, 350], rpy: [180, 60, 0]}"}});
  RobotAlongPath along = f.along();
  std::vector<toolpath::PathSample> samples;
  for (int i = 0; i < 8; ++i)
    samples.push_back(side_cut_sample((5.0 + 7.0 * i) * 1e-3, 0.0, kPi));
  std::vector<RobotSample> out(samples.size());
  along.evaluate(samples, out);
  std::vector<RecordedSample> recorded;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    ASSERT_TRUE(out[i].reachable) << i;
    recorded.push_back({samples[i], out[i].q_rad, out[i].margin});
  }
  const std::vector<RecordedSample> original = recorded;
  std::vector<double> psi;
  for (int k = -6; k <= 6; ++k)
    psi.push_back(k * kPi / 12.0);
  const RedundancyChoice c = choose_redundancy_angle(along, recorded, psi, 0.02, 2);
  double spread_low = 1e300, spread_high = 0.0;
  for (const auto& candidate : c.candidates) {
    if (candidate.unreachable > 0)
      continue;
    spread_low = std::min(spread_low, candidate.min_margin);
    spread_high = std::max(spread_high, candidate.min_margin);
  }
  EXPECT_GT(spread_high, spread_low * 1.01) << "ψ should matter with an offset spindle";
  EXPECT_GE(c.min_margin_after, c.min_margin_before);
  // With a 60° angle head the programmed ψ = 0 is not the best (measured:
  // this is what the search is for); the chosen one must hold its claims.
  ASSERT_TRUE(c.changed()) << "min margin " << c.min_margin_before << " at every ψ";
  // The returned postures are the chosen ψ's: the tool turned about its axis.
  for (std::size_t i = 0; i < recorded.size(); ++i) {
    expect_at_angle(f, along, recorded[i], c.chosen_rad, c.min_margin_after);
    if (original[i].margin > 1.0) {
      EXPECT_GT(recorded[i].margin, 1.0) << "sample " << i;
    }
  }
}

// The schedule ψ(s): on the 60° angle head, two program lines at right
// angles (line 10 along +x, a link of two moves out of the cut and back
// taking 2 s, line 11 along +y). Line 10 is best near ψ = −90°, line 11 near
// 0°, a single angle at −45°. With a free joint-speed bound the schedule turns
// on the link and beats every single angle; with a bound no turn can meet it
// is the best single angle; every turn stays within its bound; the samples
// it returns are at their line's angle with the margins the direct limits
// give there.
TEST(ProgramOptimization, RedundancyScheduleBeatsOneAngleAndRespectsTheJointSpeed) {
  Fixture f("", {{"robot.tool", "{xyz: [0, 0, 350], rpy: [180, 60, 0]}"}});
  toolpath::Program program;
  const Eigen::Vector3d corner(60e-3, 20e-3, 17e-3), above = corner + Eigen::Vector3d(0, 0, 10e-3);
  const std::tuple<Eigen::Vector3d, Eigen::Vector3d, int> moves[] = {
      {Eigen::Vector3d(5e-3, 20e-3, 17e-3), corner, 10},
      {corner, above, 20},
      {above, corner, 21},
      {corner, Eigen::Vector3d(60e-3, 35e-3, 17e-3), 11}};
  for (const auto& [from, to, number] : moves) {
    toolpath::Move move;
    move.kind = toolpath::MotionKind::linear;
    move.start_m = from;
    move.end_m = to;
    move.feed_m_s = 0.01;
    move.line = number;
    program.moves.push_back(move);
  }
  std::vector<toolpath::PathSample> samples;
  for (int i = 0; i < 8; ++i) {
    toolpath::PathSample s = side_cut_sample((5.0 + 55.0 * i / 7.0) * 1e-3, 0.0, kPi, 10);
    s.move = 0;
    s.move_fraction = i / 7.0;
    s.t_s = 5.5 * i / 7.0;
    samples.push_back(s);
  }
  for (int i = 0; i < 8; ++i) {
    toolpath::PathSample s = side_cut_sample(60e-3, 0.0, kPi, 11);
    s.tip_m.y() = (20.0 + 15.0 * i / 7.0) * 1e-3;
    s.feed_direction = Eigen::Vector3d::UnitY();
    s.move = 3;
    s.move_fraction = i / 7.0;
    s.t_s = 7.5 + 1.5 * i / 7.0;
    samples.push_back(s);
  }
  RobotAlongPath along = f.along();
  std::vector<RobotSample> out(samples.size());
  along.evaluate(samples, out);
  std::vector<RecordedSample> recorded;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    ASSERT_TRUE(out[i].reachable) << i;
    recorded.push_back({samples[i], out[i].q_rad, out[i].margin});
  }
  std::vector<double> psi;
  for (int k = -6; k <= 6; ++k)
    psi.push_back(k * kPi / 12.0);
  std::vector<RecordedSample> one_angle = recorded;
  const RedundancyChoice constant = choose_redundancy_angle(along, one_angle, psi, 0.02, 2);

  const double free_bound = 1000.0 * kPi / 180.0;
  std::vector<RecordedSample> free_turns = recorded;
  const RedundancySchedule free =
      schedule_redundancy(along, program, free_turns, psi, free_bound, 0.02, 2);
  ASSERT_EQ(free.lines.size(), 2u);
  EXPECT_GT(free.min_margin_after, constant.min_margin_after * 1.1);
  EXPECT_EQ(free.turns, 1u);
  EXPECT_TRUE(free.lines[1].turn_before);
  EXPECT_NE(free.lines[0].to_rad, free.lines[1].to_rad);
  for (std::size_t i = 0; i < free_turns.size(); ++i) {
    const RedundancySchedule::Line& line = free.lines[free_turns[i].sample.move == 0 ? 0 : 1];
    expect_at_angle(f, along, free_turns[i], line.to_rad, free.min_margin_after);
  }
  for (const auto& line : free.lines)
    EXPECT_LE(line.turn_joint_speed_rad_s, free_bound);
  std::cout << fmt::format(
      "schedule: line 10 at {:.0f} deg, line 11 at {:.0f} deg (turned on the link at {:.1f} "
      "deg/s), min margin {:.3f} (one angle {:.0f} deg: {:.3f}, programmed {:.3f})\n",
      free.lines[0].to_rad * 180 / kPi, free.lines[1].to_rad * 180 / kPi,
      free.lines[1].turn_joint_speed_rad_s * 180 / kPi, free.min_margin_after,
      constant.chosen_rad * 180 / kPi, constant.min_margin_after, free.min_margin_before);
  // The schedule as the re-run takes it: ψ at each move's start and end,
  // the turn spread over the link's two moves.
  const auto by_move = free.by_move(4);
  EXPECT_EQ(by_move[0].first, free.lines[0].from_rad);
  EXPECT_EQ(by_move[0].second, free.lines[0].to_rad);
  EXPECT_EQ(by_move[1].first, free.lines[0].to_rad);
  EXPECT_NEAR(by_move[1].second, 0.5 * (free.lines[0].to_rad + free.lines[1].from_rad), 1e-12);
  EXPECT_EQ(by_move[2].second, free.lines[1].from_rad);
  EXPECT_EQ(by_move[3].first, free.lines[1].to_rad);

  // A bound no turn can meet: the best single angle for both lines.
  std::vector<RecordedSample> no_turns = recorded;
  const RedundancySchedule tight =
      schedule_redundancy(along, program, no_turns, psi, 1e-9, 0.02, 2);
  EXPECT_EQ(tight.turns, 0u);
  EXPECT_EQ(tight.lines[0].to_rad, tight.lines[1].to_rad);
  EXPECT_EQ(tight.lines[1].from_rad, tight.lines[1].to_rad);
  EXPECT_NEAR(tight.min_margin_after, constant.min_margin_after, 1e-9 * constant.min_margin_after);
  // 10 deg/s: whatever it chooses, its turns within it.
  std::vector<RecordedSample> slow_turns = recorded;
  const RedundancySchedule slow =
      schedule_redundancy(along, program, slow_turns, psi, 10.0 * kPi / 180.0, 0.02, 2);
  for (const auto& line : slow.lines)
    EXPECT_LE(line.turn_joint_speed_rad_s, 10.0 * kPi / 180.0);
}

TEST(RobotAlongPath, BandProcessMapsArcsToTheStraightCut) {
  const double r = 5e-3;
  const auto down = band_process(kPi - std::acos(1.0 - 2.0 / 5.0), kPi, r, 100.0, 1e-4);
  ASSERT_TRUE(down);
  EXPECT_NEAR(down->radial_depth_m, 2e-3, 1e-12);
  EXPECT_EQ(down->direction, cutting::MillingDirection::down);
  const auto up = band_process(0.0, std::acos(1.0 - 1.0 / 5.0), r, 100.0, 1e-4);
  ASSERT_TRUE(up);
  EXPECT_NEAR(up->radial_depth_m, 1e-3, 1e-12);
  EXPECT_EQ(up->direction, cutting::MillingDirection::up);
  const auto slot = band_process(0.0, kPi, r, 100.0, 1e-4);
  ASSERT_TRUE(slot);
  EXPECT_NEAR(slot->radial_depth_m, 10e-3, 1e-15);
  EXPECT_FALSE(band_process(0.5, 2.0, r, 100.0, 1e-4).has_value());
}

}  // namespace
}  // namespace test_robot_along_path_cpp
}  // namespace robomill::robot_path

namespace robomill::robot_path {
namespace test_robot_along_path_cpp {
namespace {

// The compensation's polyline (deflection_compensation.hpp): points are
// added only where the samples' corrections leave the straight interpolation
// (a kink; the start, which stays where the line before ended), and at a
// square corner the shared point takes both walls' corrections, each line
// taking the other wall's out over its first or last step.
TEST(DeflectionCompensation, PolylineFollowsTheSamplesAndCornersTakeBothWalls) {
  toolpath::Program program;
  auto line = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, int number) {
    toolpath::Move move;
    move.kind = toolpath::MotionKind::linear;
    move.start_m = a;
    move.end_m = b;
    move.feed_m_s = 0.01;
    move.line = number;
    program.moves.push_back(move);
  };
  line({0, 0, 0}, {0.01, 0, 0}, 1);        // along +x: wall at −y
  line({0.01, 0, 0}, {0.01, 0.01, 0}, 2);  // along +y: wall at +x
  CompensationSettings settings;
  settings.tolerance_m = 0.5e-6;
  PathCorrections corrections(program.moves.size(), settings);
  auto add = [&](std::size_t move, const Eigen::Vector3d& wall, double error) {
    toolpath::PathSample s;
    s.move = move;
    s.analysed = true;
    RobotSample r;
    r.reachable = true;
    r.wall = true;
    r.wall_direction = wall;
    r.form_error_m = error;
    corrections.add(s, r);
  };
  // Line 1: 11 samples, the error rises 10 → 20 µm to the middle, then
  // stays (a kink at u = 0.5). Line 2: a constant 30 µm.
  for (int k = 0; k <= 10; ++k)
    add(0, -Eigen::Vector3d::UnitY(), (10.0 + 2.0 * std::min(k, 5)) * 1e-6);
  for (int k = 0; k <= 10; ++k)
    add(1, Eigen::Vector3d::UnitX(), 30e-6);
  const std::vector<LineCorrection> lines = corrections.corrections(program);
  ASSERT_EQ(lines.size(), 2u);
  // Line 1 starts where the program did (no offset), so the first point
  // kept is the second sample's 12 µm; then the kink at u = 0.5. Its end
  // takes both walls (30 µm along +x for line 2's wall), so the x offset
  // ramps in over the last step only: a point at u = 0.9 holds it at 0
  // before.
  ASSERT_EQ(lines[0].points.size(), 3u);
  const double u[] = {0.1, 0.5, 0.9}, y_um[] = {-12.0, -20.0, -20.0};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(lines[0].points[i].u, u[i], 1e-12);
    EXPECT_LT((lines[0].points[i].offset_m - Eigen::Vector3d(0, y_um[i] * 1e-6, 0)).norm(), 1e-12);
  }
  EXPECT_LT((lines[0].offset_m - Eigen::Vector3d(30e-6, -20e-6, 0)).norm(), 1e-12);
  // Line 2 starts at that corner: its first step takes the −20 µm of line
  // 1's wall out (a point at u = 0.1), then its constant 30 µm.
  ASSERT_EQ(lines[1].points.size(), 1u);
  EXPECT_NEAR(lines[1].points[0].u, 0.1, 1e-12);
  EXPECT_LT((lines[1].points[0].offset_m - Eigen::Vector3d(30e-6, 0, 0)).norm(), 1e-12);
  EXPECT_LT((lines[1].offset_m - Eigen::Vector3d(30e-6, 0, 0)).norm(), 1e-12);
  // The written path's ends: line 1's points and end, line 2's point and end.
  const std::vector<Eigen::Vector3d> ends = corrected_ends(program, lines);
  ASSERT_EQ(ends.size(), 6u);
  EXPECT_LT((ends[1] - Eigen::Vector3d(0.005, -20e-6, 0)).norm(), 1e-12);
  EXPECT_LT((ends[3] - Eigen::Vector3d(0.01 + 30e-6, -20e-6, 0)).norm(), 1e-12);
  EXPECT_LT((ends[4] - Eigen::Vector3d(0.01 + 30e-6, 0.001, 0)).norm(), 1e-12);
  EXPECT_LT((ends[5] - Eigen::Vector3d(0.01 + 30e-6, 0.01, 0)).norm(), 1e-12);
}

// What the compensation leaves as programmed is said, line by line: a line
// of several moves (an arc in pieces, a loop), the line before such an arc
// (its centre is programmed from its start); a line whose error stays under
// min_offset is not listed. An arc alone on its line and the line before it
// are compensated.
TEST(DeflectionCompensation, LinesLeftAsProgrammedAreNamedWithTheReason) {
  toolpath::Program program;
  auto move = [&](toolpath::MotionKind kind, int number) {
    toolpath::Move m;
    m.kind = kind;
    m.start_m = Eigen::Vector3d(0.01 * static_cast<double>(program.moves.size()), 0.02, 0);
    m.end_m = m.start_m + Eigen::Vector3d(0.01, 0, 0);
    if (kind ==
        toolpath::MotionKind::arc) {  // a quarter circle from the start about a centre below it
      m.centre_m = m.start_m - Eigen::Vector3d(0, 0.01, 0);
      m.sweep_rad = -std::numbers::pi / 2.0;
      m.end_m = m.centre_m + Eigen::Vector3d(0.01, 0, 0);
    }
    m.feed_m_s = 0.01;
    m.line = number;
    program.moves.push_back(m);
  };
  move(toolpath::MotionKind::linear, 1);  // compensated
  move(toolpath::MotionKind::linear, 2);  // before an arc alone on its line: ends on the moved arc
  move(toolpath::MotionKind::arc, 3);     // compensated
  move(toolpath::MotionKind::linear, 4);  // two moves on line 4
  move(toolpath::MotionKind::linear, 4);
  move(toolpath::MotionKind::linear, 5);  // under min_offset
  move(toolpath::MotionKind::linear, 6);  // before an arc in two pieces on line 7
  move(toolpath::MotionKind::arc, 7);
  move(toolpath::MotionKind::arc, 7);
  PathCorrections corrections(program.moves.size(), CompensationSettings{});
  for (std::size_t m = 0; m < program.moves.size(); ++m)
    for (int k = 0; k <= 4; ++k) {
      toolpath::PathSample s;
      s.move = m;
      s.analysed = true;
      RobotSample r;
      r.reachable = r.wall = true;
      r.wall_direction = -Eigen::Vector3d::UnitY();
      r.form_error_m = m == 5 ? 0.5e-6 : 20e-6;
      corrections.add(s, r);
    }
  const std::vector<LineCorrection> written = corrections.corrections(program);
  ASSERT_EQ(written.size(), 3u);
  EXPECT_EQ(written[0].line, 1);
  EXPECT_EQ(written[1].line, 2);
  EXPECT_EQ(written[2].line, 3);
  EXPECT_TRUE(written[2].arc.has_value());
  const std::vector<PathCorrections::Kept> kept = corrections.kept(program);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_EQ(kept[0].line, 4);
  EXPECT_NE(kept[0].reason.find("several moves"), std::string::npos);
  EXPECT_EQ(kept[1].line, 6);
  EXPECT_NE(kept[1].reason.find("before an arc that stays"), std::string::npos);
  EXPECT_EQ(kept[2].line, 7);
  EXPECT_NE(kept[2].reason.find("several moves"), std::string::npos);
  // A line the writer could not edit (keep) stays, and so does the line
  // before an arc kept that way.
  const std::vector<LineCorrection> without_arc = corrections.corrections(program, {3});
  ASSERT_EQ(without_arc.size(), 1u);
  EXPECT_EQ(without_arc[0].line, 1);
}

// An arc's compensation (deflection_compensation.hpp): the circle's centre
// and radius fitted to the samples' corrections. A quarter circle of
// R = 10 mm (CCW from (10, 0) to (0, 10) mm about the origin) after a line
// up the wall x = 10 mm:
//  - the same 20 µm error all round, towards the wall (outwards): the radius
//    grows by 20 µm, the centre stays, the line before ends 20 µm out along
//    x, the arc's end moves 20 µm along y, and the fit follows the samples
//    exactly;
//  - an error that keeps its direction in the cell (15 µm along +x, the
//    robot yielding one way): the centre moves 15 µm, the radius stays (to
//    the 1e-3 ridge that prefers the radius where the two look alike);
//  - after a rapid (its end cannot move), the arc starts where it was
//    programmed: the circle through that start fitted, the radius following,
//    and the fit's residual says what it could not follow.
TEST(DeflectionCompensation, ArcsGetTheirCentreAndRadiusMoved) {
  auto program_with = [](toolpath::MotionKind before) {
    toolpath::Program program;
    toolpath::Move line;
    line.kind = before;
    line.start_m = Eigen::Vector3d(0.01, -0.01, 0);
    line.end_m = Eigen::Vector3d(0.01, 0, 0);
    line.feed_m_s = before == toolpath::MotionKind::rapid ? 0.0 : 0.01;
    line.line = 1;
    program.moves.push_back(line);
    toolpath::Move arc;
    arc.kind = toolpath::MotionKind::arc;
    arc.start_m = line.end_m;
    arc.end_m = Eigen::Vector3d(0, 0.01, 0);
    arc.centre_m = Eigen::Vector3d::Zero();
    arc.sweep_rad = std::numbers::pi / 2.0;
    arc.feed_m_s = 0.01;
    arc.line = 2;
    program.moves.push_back(arc);
    return program;
  };
  auto collect = [](const toolpath::Program& program, auto correction_at) {
    PathCorrections corrections(program.moves.size(), CompensationSettings{});
    for (std::size_t m = 0; m < program.moves.size(); ++m)
      for (int k = 0; k <= 20; ++k) {
        const double u = k / 20.0;
        toolpath::PathSample s;
        s.move = m;
        s.analysed = true;
        s.kind = program.moves[m].kind;
        RobotSample r;
        r.reachable = true;
        const Eigen::Vector3d c = correction_at(program.moves[m], u);
        r.wall = c.norm() > 0.0;
        r.wall_direction = r.wall ? Eigen::Vector3d(c.normalized()) : Eigen::Vector3d::UnitX();
        r.form_error_m = c.norm();
        corrections.add(s, r);
      }
    return corrections.corrections(program);
  };
  auto radial = [](const toolpath::Move& move, double u) -> Eigen::Vector3d {
    if (move.kind != toolpath::MotionKind::arc)
      return Eigen::Vector3d::UnitX();  // the wall x = 10 mm
    return (position_at(move, u) - move.centre_m).normalized();
  };
  {  // the same error all round
    const toolpath::Program program = program_with(toolpath::MotionKind::linear);
    const std::vector<LineCorrection> lines =
        collect(program, [&](const toolpath::Move& move, double u) {
          return Eigen::Vector3d(20e-6 * radial(move, u));
        });
    ASSERT_EQ(lines.size(), 2u);
    EXPECT_LT((lines[0].offset_m - Eigen::Vector3d(20e-6, 0, 0)).norm(), 1e-12);
    ASSERT_TRUE(lines[1].arc.has_value());
    EXPECT_NEAR(lines[1].arc->radius_change_m, 20e-6, 1e-12);
    EXPECT_LT(lines[1].arc->centre_offset_m.norm(), 1e-12);
    EXPECT_LT(lines[1].arc->fit_residual_m, 1e-12);
    EXPECT_LT((lines[1].offset_m - Eigen::Vector3d(0, 20e-6, 0)).norm(), 1e-12);
    const std::vector<Eigen::Vector3d> ends = corrected_ends(program, lines);
    // The line starts where the program did: a point after its first step.
    ASSERT_EQ(ends.size(), 3u);
    EXPECT_LT((ends[2] - Eigen::Vector3d(0, 0.01 + 20e-6, 0)).norm(), 1e-12);
  }
  {  // one direction in the cell. Over a quarter turn Δc and δ r̂ are far
     // from independent, so the ridge's pull towards the radius shows: 52 nm
     // of the 15 µm when this was written; 1 % (150 nm) bounds it.
    const toolpath::Program program = program_with(toolpath::MotionKind::linear);
    const std::vector<LineCorrection> lines = collect(
        program, [](const toolpath::Move&, double) { return Eigen::Vector3d(15e-6, 0, 0); });
    ASSERT_EQ(lines.size(), 2u);
    ASSERT_TRUE(lines[1].arc.has_value());
    EXPECT_LT((lines[1].arc->centre_offset_m - Eigen::Vector3d(15e-6, 0, 0)).norm(), 150e-9);
    EXPECT_NEAR(lines[1].arc->radius_change_m, 0.0, 150e-9);
    EXPECT_LT(lines[1].arc->fit_residual_m, 150e-9);
    EXPECT_LT((lines[1].offset_m - Eigen::Vector3d(15e-6, 0, 0)).norm(), 150e-9);
    // The line before ends where the moved circle starts.
    const Eigen::Vector3d start = program.moves[1].start_m + lines[0].offset_m;
    const Eigen::Vector3d centre = lines[1].arc->centre_offset_m;
    EXPECT_NEAR((start - centre).norm(), 0.01 + lines[1].arc->radius_change_m, 1e-15);
  }
  {  // after a rapid: the programmed start kept
    const toolpath::Program program = program_with(toolpath::MotionKind::rapid);
    const std::vector<LineCorrection> lines =
        collect(program, [&](const toolpath::Move& move, double u) {
          return move.kind == toolpath::MotionKind::arc ? Eigen::Vector3d(20e-6 * radial(move, u))
                                                        : Eigen::Vector3d(Eigen::Vector3d::Zero());
        });
    ASSERT_EQ(lines.size(), 1u);
    ASSERT_TRUE(lines[0].arc.has_value());
    const ArcCorrection& arc = *lines[0].arc;
    // On the moved circle: the programmed start, and the end moved.
    EXPECT_NEAR((program.moves[1].start_m - arc.centre_offset_m).norm(), 0.01 + arc.radius_change_m,
                1e-15);
    EXPECT_NEAR((program.moves[1].end_m + lines[0].offset_m - arc.centre_offset_m).norm(),
                0.01 + arc.radius_change_m, 1e-15);
    // The circle through the fixed start leans towards the far end: the
    // centre moves away from the start, the radius grows less than 20 µm,
    // and the 20 µm the start cannot take stay in the residual.
    EXPECT_GT(arc.radius_change_m, 0.0);
    EXPECT_LT(arc.radius_change_m, 20e-6);
    EXPECT_LT(arc.centre_offset_m.x(), 0.0);
    EXPECT_GE(arc.fit_residual_m, 10e-6);
    EXPECT_LE(arc.fit_residual_m, 20e-6 + 1e-12);
  }
}

}  // namespace
}  // namespace test_robot_along_path_cpp
}  // namespace robomill::robot_path
