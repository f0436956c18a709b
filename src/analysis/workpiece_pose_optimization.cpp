#include "robomill/analysis/workpiece_pose_optimization.hpp"

#include <fmt/format.h>

#include <chrono>

#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"
#include "robomill/cutting/milling_forces.hpp"
#include "robomill/planning/force_harmonics.hpp"
#include "robomill/stability/lobes.hpp"

namespace robomill::analysis {
namespace {

/// The first unreachable point of a path, in words: which point, where, and
/// which joint would have to pass its range (or that it is out of reach).
std::string unreachable_text(const robot::RobotModel& robot,
                             const planning::PathPerformance& path) {
  for (std::size_t i = 0; i < path.points.size(); ++i) {
    const planning::PointPerformance& p = path.points[i];
    if (p.reachable)
      continue;
    const Eigen::Vector3d x = p.placed.position_m * 1e3;
    std::string text = fmt::format(
        "{} of {} path points unreachable; point {} at [{:.1f}, {:.1f}, "
        "{:.1f}] mm (cell frame) ",
        path.unreachable, path.points.size(), i + 1, x.x(), x.y(), x.z());
    if (p.why && p.why->joint >= 0) {
      const auto& joint = robot.joints()[std::size_t(p.why->joint)];
      text += fmt::format("needs joint {} at {:.1f} deg, outside its range [{:.1f}, {:.1f}] deg",
                          p.why->joint + 1, p.why->needed_angle_rad * kDegPerRad,
                          joint.lower_rad * kDegPerRad, joint.upper_rad * kDegPerRad);
    } else {
      text += fmt::format("is outside the robot's workspace (IK leaves {:.1f} mm)",
                          p.ik_residual_m * 1e3);
    }
    return text;
  }
  return "all points reachable";
}

/// The placement problem of the job: cell, path, the cut's force harmonics,
/// the job's measure and the posture the inverse kinematics starts from.
planning::PlacementProblem placement_problem(const job::Job& job, const robot::RobotModel& robot,
                                             const cutting::MillingForceModel& force) {
  const job::OptimizeSettings& settings = *job.optimize;
  planning::PlacementProblem problem;
  problem.cell = job.workpiece->cell;
  problem.path = job.path;
  problem.force = planning::force_harmonics(force, settings.samples, settings.harmonics);
  problem.measure = settings.measure;
  problem.seed_posture_rad = job.robot->posture_rad.empty()
                                 ? Eigen::VectorXd(Eigen::VectorXd::Zero(robot.dof()))
                                 : Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(
                                       job.robot->posture_rad.data(), robot.dof()));
  return problem;
}

/// The job's own poses (004 Table 2), each of which must be reachable.
std::vector<ListedPose> listed_poses(const job::Job& job, const robot::RobotModel& robot,
                                     const planning::PlacementProblem& problem, int threads) {
  const job::OptimizeSettings& settings = *job.optimize;
  std::vector<ListedPose> listed;
  if (job.workpiece->pose)
    listed.push_back({"workpiece.pose", planning::evaluate_path(
                                            robot, problem, *job.workpiece->pose, threads, true)});
  for (std::size_t i = 0; i < settings.poses.size(); ++i) {
    listed.push_back({fmt::format("optimize.poses[{}]", i),
                      planning::evaluate_path(robot, problem, settings.poses[i], threads, true)});
  }
  for (const ListedPose& pose : listed) {
    if (!pose.path.reachable())
      throw InputError(pose.field, 0,
                       fmt::format("pose {}: {}", pose_in_words(pose.path.pose),
                                   unreachable_text(robot, pose.path)));
  }
  return listed;
}

// No pose within the bounds reaches every path point: says so, with why the
// centre of the bounds does not.
[[noreturn]] void throw_no_reachable_pose(const robot::RobotModel& robot,
                                          const planning::PlacementProblem& problem,
                                          const job::OptimizeSettings& settings,
                                          std::size_t evaluations, int threads) {
  planning::WorkpiecePose centre;
  centre.x_m = 0.5 * (settings.bounds.lower.x_m + settings.bounds.upper.x_m);
  centre.y_m = 0.5 * (settings.bounds.lower.y_m + settings.bounds.upper.y_m);
  centre.theta_rad = 0.5 * (settings.bounds.lower.theta_rad + settings.bounds.upper.theta_rad);
  const planning::PathPerformance at_centre =
      planning::evaluate_path(robot, problem, centre, threads, true);
  throw InputError(
      "optimize.bounds", 0,
      fmt::format("no pose within the bounds reaches every path point ({} poses "
                  "tried); at the centre {}: {}",
                  evaluations, pose_in_words(centre), unreachable_text(robot, at_centre)));
}

// The harmonic offset of the best pose's first point against a time-domain
// integration.
TimeDomainCheck time_domain_check(const robot::RobotModel& robot,
                                  const planning::PlacementProblem& problem,
                                  const cutting::MillingForceModel& force,
                                  const job::OptimizeSettings& settings,
                                  const planning::PathPerformance& best) {
  const planning::PointPerformance& p = best.points.front();
  const planning::PostureDynamics dynamics = planning::posture_dynamics(robot, p.q);
  int periods = 0;
  const planning::OffsetResponse time_domain = planning::steady_state_offset_time_domain(
      dynamics, p.placed.tool_to_cell, force, problem.force.period_s, 4 * settings.samples, 2000,
      1e-7, &periods, settings.measure == planning::OffsetMeasure::startup);
  TimeDomainCheck check;
  check.harmonic_m = p.offset.measure(settings.measure);
  check.time_domain_m = time_domain.measure(settings.measure);
  check.relative_difference = (check.harmonic_m - check.time_domain_m) / check.time_domain_m;
  check.periods = periods;
  return check;
}

/// Every point of `path` at the pose numbered `pose_index`.
void add_point_figures(std::vector<PathPointFigures>& figures, int pose_index,
                       const robot::RobotModel& robot, const planning::PathPerformance& path,
                       planning::OffsetMeasure measure) {
  for (std::size_t i = 0; i < path.points.size(); ++i) {
    const planning::PointPerformance& p = path.points[i];
    PathPointFigures point;
    point.pose = pose_index;
    point.point = static_cast<int>(i + 1);
    point.position_m = p.placed.position_m;
    point.reachable = p.reachable;
    point.offset_m = p.offset.measure(measure);
    point.offset = p.offset;
    for (int j = 0; j < robot.dof(); ++j)
      point.posture_rad.push_back(p.q[j]);
    for (int j = 0; j < robot.dof(); ++j)
      point.natural_frequencies_hz.push_back(p.reachable ? p.natural_frequencies_hz[j] : 0.0);
    figures.push_back(std::move(point));
  }
}

}  // namespace

std::string pose_in_words(const planning::WorkpiecePose& pose) {
  return fmt::format("[{:.1f} mm, {:.1f} mm, {:.2f} deg]", pose.x_m * 1e3, pose.y_m * 1e3,
                     pose.theta_rad * kDegPerRad);
}

WorkpiecePoseOptimization workpiece_pose_optimization(const job::Job& job, int threads) {
  if (!job.optimize)
    throw InputError("optimize", 0, "required: the optimize: section (bounds of the pose search)");
  const job::OptimizeSettings& settings = *job.optimize;
  const auto start = std::chrono::steady_clock::now();

  const robot::RobotModel robot(job.robot->description);
  const tool::Tool cutter(*job.tool);
  const cutting::MillingForceModel force(
      cutter, *job.cutting, *job.process,
      job.forces.axial_elements > 0
          ? job.forces.axial_elements
          : cutting::default_axial_elements(cutter, job.process->axial_depth_m));
  const planning::PlacementProblem problem = placement_problem(job, robot, force);

  WorkpiecePoseOptimization run;
  run.listed = listed_poses(job, robot, problem, threads);

  planning::PoseOptimizationOptions search = settings.options;
  search.threads = threads;
  run.search = planning::optimize_workpiece_pose(robot, problem, settings.bounds, search);
  if (!run.search.found)
    throw_no_reachable_pose(robot, problem, settings, run.search.evaluations.size(), threads);
  run.best = planning::evaluate_path(robot, problem, run.search.best, threads);

  if (settings.check_time_domain)
    run.time_domain_check = time_domain_check(robot, problem, force, settings, run.best);

  // Landscape (004 Figure 7d): grid over the bounds for each θp of the job.
  if (settings.landscape_counts[0] > 0) {
    run.landscape = planning::pose_landscape(
        robot, problem,
        stability::linear_range(settings.bounds.lower.x_m, settings.bounds.upper.x_m,
                                settings.landscape_counts[0]),
        stability::linear_range(settings.bounds.lower.y_m, settings.bounds.upper.y_m,
                                settings.landscape_counts[1]),
        settings.landscape_theta_rad, threads);
  }
  run.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  add_point_figures(run.point_figures, 0, robot, run.best, settings.measure);
  for (std::size_t i = 0; i < run.listed.size(); ++i)
    add_point_figures(run.point_figures, static_cast<int>(i + 1), robot, run.listed[i].path,
                      settings.measure);
  for (const planning::PathPerformance& cell : run.landscape)
    run.landscape_reachable += cell.reachable() ? 1 : 0;
  run.joints = robot.dof();
  run.measure = settings.measure;
  run.path_points = problem.path.size();
  run.force_mean_n = problem.force.coefficients[0].real();
  return run;
}

}  // namespace robomill::analysis
