// robomill optimize JOB: where to put the workpiece (004 §3.3, Eq 8-9). The
// job's path is placed on the table at a pose p = (xp, yp, θp), the robot's
// posture found at every point, the steady-state tool offset computed from the
// periodic milling force (Eq 1-2 in the frequency domain) and averaged (Eq 6);
// NLopt searches the job's bounds for the smallest d_m. Also evaluates the
// job's listed poses (004 Table 2) and, with optimize.landscape, a grid of
// (xp, yp) for each θp (004 Figure 7d). The search is
// analysis::workpiece_pose_optimization's; this file writes it as
// evaluations.csv, path.csv, landscape.csv and summary.json.

#include <fmt/format.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "robomill/analysis/workpiece_pose_optimization.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/summary.hpp"

namespace robomill::commands {
namespace {

nlohmann::json pose_json(const planning::WorkpiecePose& pose) {
  return {{"x_mm", pose.x_m * 1e3},
          {"y_mm", pose.y_m * 1e3},
          {"theta_deg", pose.theta_rad * kDegPerRad}};
}

// path.csv: every point at the best pose (pose 0), then at each listed pose.
io::CsvTable path_table(const analysis::WorkpiecePoseOptimization& run) {
  std::vector<std::string> columns = {"pose",         "point",     "x_mm",    "y_mm",
                                      "z_mm",         "reachable", "d_mm",    "peak_mm",
                                      "vibration_mm", "rms_mm",    "mean_mm", "startup_mm"};
  for (int j = 0; j < run.joints; ++j)
    columns.push_back(fmt::format("q{}_deg", j + 1));
  for (int j = 0; j < run.joints; ++j)
    columns.push_back(fmt::format("fn{}_hz", j + 1));
  io::CsvTable table(columns);
  for (const analysis::PathPointFigures& p : run.point_figures) {
    std::vector<double> row = {static_cast<double>(p.pose),
                               static_cast<double>(p.point),
                               p.position_m.x() * 1e3,
                               p.position_m.y() * 1e3,
                               p.position_m.z() * 1e3,
                               p.reachable ? 1.0 : 0.0,
                               p.offset_m * 1e3,
                               p.offset.peak_m * 1e3,
                               p.offset.vibration_m * 1e3,
                               p.offset.rms_m * 1e3,
                               p.offset.mean_m * 1e3,
                               p.offset.startup_m * 1e3};
    for (const double q : p.posture_rad)
      row.push_back(q * kDegPerRad);
    for (const double fn : p.natural_frequencies_hz)
      row.push_back(fn);
    table.add_row(row);
  }
  return table;
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

// summary.json's time_domain_check.
nlohmann::json time_domain_check_json(const analysis::TimeDomainCheck& check) {
  return {{"point", 1},
          {"harmonic_mm", check.harmonic_m * 1e3},
          {"time_domain_mm", check.time_domain_m * 1e3},
          {"relative_difference", check.relative_difference},
          {"periods", check.periods}};
}

}  // namespace

CommandResult compute_optimize(const job::Job& job, int threads) {
  const analysis::WorkpiecePoseOptimization run =
      analysis::workpiece_pose_optimization(job, threads);
  const planning::PoseOptimizationResult& result = run.search;

  nlohmann::json poses = nlohmann::json::array();
  for (const analysis::ListedPose& listed : run.listed) {
    nlohmann::json entry = pose_json(listed.path.pose);
    entry["field"] = listed.field;
    entry["dm_mm"] = listed.path.dm_m * 1e3;
    entry["max_mm"] = listed.path.max_m * 1e3;
    poses.push_back(entry);
  }

  nlohmann::json summary = {{"command", "optimize"},
                            {"job", job.source.string()},
                            {"best", pose_json(result.best)},
                            {"objective", result.dm_m * 1e3},
                            {"objective_name", "dm_mm"},
                            {"measure", std::string(planning::to_string(run.measure))},
                            {"dm_mm", result.dm_m * 1e3},
                            {"max_offset_mm", run.best.max_m * 1e3},
                            {"evaluations", result.evaluations.size()},
                            {"global_evaluations", result.global_evaluations},
                            {"global_status", result.global_status},
                            {"local_status", result.local_status},
                            {"optimization_s", result.elapsed_s},
                            {"elapsed_s", run.elapsed_s},
                            {"path_points", run.path_points},
                            {"force_mean_N", io::xyz(run.force_mean_n)},
                            {"poses", poses}};
  if (run.time_domain_check)
    summary["time_domain_check"] = time_domain_check_json(*run.time_domain_check);
  if (!run.landscape.empty())
    summary["landscape"] = {{"cells", run.landscape.size()},
                            {"reachable", run.landscape_reachable}};

  CommandResult output;
  output.tables.emplace_back("evaluations", evaluations_table(result));
  output.tables.emplace_back("path", path_table(run));
  if (!run.landscape.empty())
    output.tables.emplace_back("landscape", landscape_csv(run.landscape));
  output.summary = std::move(summary);
  output.message = fmt::format(
      "optimize: best pose {} with dm = {:.4f} mm ({}), {} evaluations in "
      "{:.2f} s\n",
      analysis::pose_in_words(result.best), result.dm_m * 1e3, planning::to_string(run.measure),
      result.evaluations.size(), result.elapsed_s);
  for (const analysis::ListedPose& listed : run.listed)
    output.message +=
        fmt::format("  {} {}: dm = {:.4f} mm\n", listed.field,
                    analysis::pose_in_words(listed.path.pose), listed.path.dm_m * 1e3);
  return output;
}

}  // namespace robomill::commands
