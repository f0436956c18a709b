// robomill optimize JOB: where to put the workpiece (004 §3.3, Eq 8-9). The
// job's path is placed on the table at a pose p = (xp, yp, θp), the robot's
// posture found at every point, the steady-state tool offset computed from the
// periodic milling force (Eq 1-2 in the frequency domain) and averaged (Eq 6);
// NLopt searches the job's bounds for the smallest d_m. Also evaluates the
// job's listed poses (004 Table 2) and, with optimize.landscape, a grid of
// (xp, yp) for each θp (004 Figure 7d).

#include <fmt/format.h>

#include <chrono>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "robomill/commands/commands.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/summary.hpp"
#include "robomill/planning/pose_optimization.hpp"
#include "robomill/stability/lobes.hpp"

namespace robomill::commands {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

nlohmann::json pose_json(const planning::WorkpiecePose& pose) {
  return {{"x_mm", pose.x_m * 1e3},
          {"y_mm", pose.y_m * 1e3},
          {"theta_deg", pose.theta_rad * kDegPerRad}};
}

std::string pose_text(const planning::WorkpiecePose& pose) {
  return fmt::format("[{:.1f} mm, {:.1f} mm, {:.2f} deg]", pose.x_m * 1e3, pose.y_m * 1e3,
                     pose.theta_rad * kDegPerRad);
}

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

void add_path_rows(io::CsvTable& table, int pose_index, const robot::RobotModel& robot,
                   const planning::PathPerformance& path, planning::OffsetMeasure measure) {
  for (std::size_t i = 0; i < path.points.size(); ++i) {
    const planning::PointPerformance& p = path.points[i];
    std::vector<double> row = {static_cast<double>(pose_index), static_cast<double>(i + 1),
                               p.placed.position_m.x() * 1e3,   p.placed.position_m.y() * 1e3,
                               p.placed.position_m.z() * 1e3,   p.reachable ? 1.0 : 0.0,
                               p.offset.measure(measure) * 1e3, p.offset.peak_m * 1e3,
                               p.offset.vibration_m * 1e3,      p.offset.rms_m * 1e3,
                               p.offset.mean_m * 1e3,           p.offset.startup_m * 1e3};
    for (int j = 0; j < robot.dof(); ++j)
      row.push_back(p.q[j] * kDegPerRad);
    for (int j = 0; j < robot.dof(); ++j)
      row.push_back(p.reachable ? p.natural_frequencies_hz[j] : 0.0);
    table.add_row(row);
  }
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
  throw InputError("optimize.bounds", 0,
                   fmt::format("no pose within the bounds reaches every path point ({} poses "
                               "tried); at the centre {}: {}",
                               evaluations, pose_text(centre), unreachable_text(robot, at_centre)));
}

// summary.json's time_domain_check: the harmonic offset of the best pose's
// first point against a time-domain integration.
nlohmann::json time_domain_check(const robot::RobotModel& robot,
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
  const double harmonic = p.offset.measure(settings.measure);
  const double integrated = time_domain.measure(settings.measure);
  return {{"point", 1},
          {"harmonic_mm", harmonic * 1e3},
          {"time_domain_mm", integrated * 1e3},
          {"relative_difference", (harmonic - integrated) / integrated},
          {"periods", periods}};
}

// evaluations.csv: every pose the search evaluated.
io::CsvTable evaluations_table(const planning::PoseOptimizationResult& result) {
  io::CsvTable evaluations(
      {"evaluation", "phase", "x_mm", "y_mm", "theta_deg", "reachable", "dm_mm", "objective_mm"});
  for (std::size_t i = 0; i < result.evaluations.size(); ++i) {
    const planning::PoseEvaluation& e = result.evaluations[i];
    evaluations.add_row({static_cast<double>(i + 1), static_cast<double>(e.phase), e.pose.x_m * 1e3,
                         e.pose.y_m * 1e3, e.pose.theta_rad * kDegPerRad, e.reachable ? 1.0 : 0.0,
                         e.dm_m * 1e3, e.objective_m * 1e3});
  }
  return evaluations;
}

// path.csv's columns (add_path_rows' cells).
std::vector<std::string> path_columns(int dof) {
  std::vector<std::string> columns = {"pose",         "point",     "x_mm",    "y_mm",
                                      "z_mm",         "reachable", "d_mm",    "peak_mm",
                                      "vibration_mm", "rms_mm",    "mean_mm", "startup_mm"};
  for (int j = 0; j < dof; ++j)
    columns.push_back(fmt::format("q{}_deg", j + 1));
  for (int j = 0; j < dof; ++j)
    columns.push_back(fmt::format("fn{}_hz", j + 1));
  return columns;
}

// landscape.csv: the grid of poses over the bounds.
io::CsvTable landscape_csv(const std::vector<planning::PathPerformance>& landscape) {
  io::CsvTable landscape_table({"x_mm", "y_mm", "theta_deg", "reachable", "dm_mm", "max_mm"});
  for (const planning::PathPerformance& cell : landscape) {
    landscape_table.add_row({cell.pose.x_m * 1e3, cell.pose.y_m * 1e3,
                             cell.pose.theta_rad * kDegPerRad, cell.reachable() ? 1.0 : 0.0,
                             cell.dm_m * 1e3, cell.max_m * 1e3});
  }
  return landscape_table;
}

}  // namespace

CommandResult compute_optimize(const job::Job& job, int threads) {
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
  planning::PlacementProblem problem;
  problem.cell = job.workpiece->cell;
  problem.path = job.path;
  problem.force = planning::force_harmonics(force, settings.samples, settings.harmonics);
  problem.measure = settings.measure;
  problem.seed_posture_rad = job.robot->posture_rad.empty()
                                 ? Eigen::VectorXd(Eigen::VectorXd::Zero(robot.dof()))
                                 : Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(
                                       job.robot->posture_rad.data(), robot.dof()));

  // The job's own poses first (004 Table 2): each must be reachable.
  std::vector<std::pair<std::string, planning::PathPerformance>> listed;
  if (job.workpiece->pose)
    listed.emplace_back("workpiece.pose", planning::evaluate_path(
                                              robot, problem, *job.workpiece->pose, threads, true));
  for (std::size_t i = 0; i < settings.poses.size(); ++i) {
    listed.emplace_back(fmt::format("optimize.poses[{}]", i),
                        planning::evaluate_path(robot, problem, settings.poses[i], threads, true));
  }
  for (const auto& [field, path] : listed) {
    if (!path.reachable())
      throw InputError(
          field, 0,
          fmt::format("pose {}: {}", pose_text(path.pose), unreachable_text(robot, path)));
  }

  planning::PoseOptimizationOptions search = settings.options;
  search.threads = threads;
  const planning::PoseOptimizationResult result =
      planning::optimize_workpiece_pose(robot, problem, settings.bounds, search);
  if (!result.found)
    throw_no_reachable_pose(robot, problem, settings, result.evaluations.size(), threads);
  const planning::PathPerformance best =
      planning::evaluate_path(robot, problem, result.best, threads);

  nlohmann::json check;
  if (settings.check_time_domain)
    check = time_domain_check(robot, problem, force, settings, best);

  // Landscape (004 Figure 7d): grid over the bounds for each θp of the job.
  std::vector<planning::PathPerformance> landscape;
  if (settings.landscape_counts[0] > 0) {
    landscape = planning::pose_landscape(
        robot, problem,
        stability::linear_range(settings.bounds.lower.x_m, settings.bounds.upper.x_m,
                                settings.landscape_counts[0]),
        stability::linear_range(settings.bounds.lower.y_m, settings.bounds.upper.y_m,
                                settings.landscape_counts[1]),
        settings.landscape_theta_rad, threads);
  }
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  io::CsvTable evaluations = evaluations_table(result);
  io::CsvTable path_table(path_columns(robot.dof()));
  add_path_rows(path_table, 0, robot, best, settings.measure);
  nlohmann::json poses = nlohmann::json::array();
  for (std::size_t i = 0; i < listed.size(); ++i) {
    const planning::PathPerformance& path = listed[i].second;
    add_path_rows(path_table, static_cast<int>(i + 1), robot, path, settings.measure);
    nlohmann::json entry = pose_json(path.pose);
    entry["field"] = listed[i].first;
    entry["dm_mm"] = path.dm_m * 1e3;
    entry["max_mm"] = path.max_m * 1e3;
    poses.push_back(entry);
  }
  io::CsvTable landscape_table = landscape_csv(landscape);

  nlohmann::json summary = {{"command", "optimize"},
                            {"job", job.source.string()},
                            {"best", pose_json(result.best)},
                            {"objective", result.dm_m * 1e3},
                            {"objective_name", "dm_mm"},
                            {"measure", std::string(planning::to_string(settings.measure))},
                            {"dm_mm", result.dm_m * 1e3},
                            {"max_offset_mm", best.max_m * 1e3},
                            {"evaluations", result.evaluations.size()},
                            {"global_evaluations", result.global_evaluations},
                            {"global_status", result.global_status},
                            {"local_status", result.local_status},
                            {"optimization_s", result.elapsed_s},
                            {"elapsed_s", elapsed_s},
                            {"path_points", problem.path.size()},
                            {"force_mean_N", io::xyz(problem.force.coefficients[0].real())},
                            {"poses", poses}};
  if (!check.is_null())
    summary["time_domain_check"] = check;
  if (!landscape.empty()) {
    int reachable = 0;
    for (const auto& cell : landscape)
      reachable += cell.reachable() ? 1 : 0;
    summary["landscape"] = {{"cells", landscape.size()}, {"reachable", reachable}};
  }

  CommandResult output;
  output.tables.emplace_back("evaluations", std::move(evaluations));
  output.tables.emplace_back("path", std::move(path_table));
  if (!landscape.empty())
    output.tables.emplace_back("landscape", std::move(landscape_table));
  output.summary = std::move(summary);
  output.message = fmt::format(
      "optimize: best pose {} with dm = {:.4f} mm ({}), {} evaluations in "
      "{:.2f} s\n",
      pose_text(result.best), result.dm_m * 1e3, planning::to_string(settings.measure),
      result.evaluations.size(), result.elapsed_s);
  for (const auto& [field, path] : listed)
    output.message +=
        fmt::format("  {} {}: dm = {:.4f} mm\n", field, pose_text(path.pose), path.dm_m * 1e3);
  return output;
}

}  // namespace robomill::commands
