// robomill advise JOB: cutting-parameter advice (issue 9 item 4). The spindle
// speed and axial depth that maximize the material removal rate inside the
// stability diagram (with the job's safety factor) and under the job's
// tool-offset limit, at the job's posture or at every point of its path; and,
// with advise.redundancy, the rotation of a 6-joint robot about the tool axis
// that maximizes the minimum stable depth along the path.
//
// The computation is analysis::cutting_parameter_advice's; this file writes it
// as advice.json, advice_map.csv, redundancy.csv and summary.json. With an
// uncertainty: section, analysis::robust_cutting_advice adds the advice that
// keeps P(chatter) ≤ advise.max_chatter_probability (advice_map_robust.csv,
// "uncertainty" in summary.json and advice.json).

#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "robomill/analysis/cutting_parameter_advice.hpp"
#include "robomill/analysis/robust_advice.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/summary.hpp"

namespace robomill::commands {
namespace {

constexpr double kCm3PerMinPerM3PerS = 1e6 * 60.0;

nlohmann::json speed_json(const planning::SpeedAdvice& a, const job::Job& job) {
  const int teeth = job.tool->teeth;
  nlohmann::json j = {
      {"spindle_rpm", a.spindle_rad_s * kRpmPerRadS},
      {"depth_mm", a.depth_m * 1e3},
      {"limit_depth_mm", a.limit_depth_m * 1e3},
      {"limited", a.limited},
      {"stable_depth_mm", a.stable_depth_m * 1e3},
      {"expected_offset_mm", a.offset_m * 1e3},
      {"offset_limited", a.offset_limited},
      {"mrr_cm3_per_min", a.mrr_m3_per_s * kCm3PerMinPerM3PerS},
      {"feed_speed_mm_per_min",
       job.process->feed_per_tooth_m * teeth * a.spindle_rad_s / (2.0 * std::numbers::pi) * 6e4},
      {"governing_station", a.station + 1},
      {"stage", a.stage == 0 ? "scan" : "refine"}};
  if (a.limited)
    j["chatter_freq_hz"] = a.chatter_frequency_hz;
  if (a.depth_m > 0.0)
    j["margin_to_chatter"] = a.limit_depth_m / a.depth_m;
  return j;
}

// advice.json's limits: the job's search settings.
nlohmann::json limits_json(const job::AdviseSettings& settings) {
  return {{"speed_from_rpm", settings.limits.speed_min_rad_s * kRpmPerRadS},
          {"speed_to_rpm", settings.limits.speed_max_rad_s * kRpmPerRadS},
          {"speeds", settings.limits.speed_count},
          {"refine", settings.limits.refine_count},
          {"depth_max_mm", settings.limit.depth_max_m * 1e3},
          {"depth_step_mm", settings.limits.depth_step_m * 1e3},
          {"margin", settings.limits.stability_margin},
          {"max_offset_mm", settings.limits.max_offset_m
                                ? nlohmann::json(*settings.limits.max_offset_m * 1e3)
                                : nlohmann::json(nullptr)},
          {"measure", std::string(planning::to_string(settings.limits.measure))}};
}

// advice.json's floquet_check: the time-domain check of the advice.
nlohmann::json floquet_check_json(const planning::CuttingAdvice& advice,
                                  const job::AdviseSettings& settings) {
  nlohmann::json check = {{"done", advice.check.done}};
  if (advice.check.done) {
    check["method"] = advice.check.method;
    check["steps"] = advice.check.steps;
    check["spectral_radius"] = advice.check.spectral_radius;
    check["stable"] = advice.check.spectral_radius < 1.0;
    if (advice.check.next_done) {
      check["next_depth_mm"] = advice.best.depth_m * 1e3 + settings.limits.depth_step_m * 1e3;
      check["next_spectral_radius"] = advice.check.next_spectral_radius;
    }
    check["stepped_down"] = advice.stepped_down;
  }
  return check;
}

// advice_map.csv: every speed scanned or refined, in speed order.
io::CsvTable advice_map_table(const planning::CuttingAdvice& advice) {
  io::CsvTable map({"spindle_rpm", "stage", "limit_depth_mm", "limited", "station",
                    "chatter_freq_hz", "stable_depth_mm", "depth_mm", "offset_mm", "offset_limited",
                    "mrr_cm3_per_min"});
  std::vector<planning::SpeedAdvice> rows = advice.scan;
  std::stable_sort(rows.begin(), rows.end(),
                   [](const auto& a, const auto& b) { return a.spindle_rad_s < b.spindle_rad_s; });
  for (const auto& a : rows)
    map.add_row({a.spindle_rad_s * kRpmPerRadS, double(a.stage), a.limit_depth_m * 1e3,
                 a.limited ? 1.0 : 0.0, double(a.station + 1), a.chatter_frequency_hz,
                 a.stable_depth_m * 1e3, a.depth_m * 1e3, a.offset_m * 1e3,
                 a.offset_limited ? 1.0 : 0.0, a.mrr_m3_per_s * kCm3PerMinPerM3PerS});
  return map;
}

// redundancy.csv: every path point at every candidate angle.
io::CsvTable redundancy_csv(const planning::RedundancyStudy& study, int dof) {
  std::vector<std::string> columns = {"point",        "angle_deg",      "reachable",
                                      "min_limit_mm", "at_spindle_rpm", "lowest_fn_hz"};
  for (int j = 0; j < dof; ++j)
    columns.push_back(fmt::format("q{}_deg", j + 1));
  io::CsvTable table(columns);
  for (std::size_t i = 0; i < study.points.size(); ++i) {
    const planning::PointRedundancy& p = study.points[i];
    for (const planning::RedundancySample& s : p.samples) {
      std::vector<double> row = {
          double(i + 1),       s.angle_rad * kDegPerRad,         s.reachable ? 1.0 : 0.0,
          s.min_limit_m * 1e3, s.at_spindle_rad_s * kRpmPerRadS, s.lowest_fn_hz};
      for (int j = 0; j < dof; ++j)
        row.push_back(s.q[j] * kDegPerRad);
      table.add_row(row);
    }
  }
  return table;
}

// advice.json's redundancy.per_point entry of path point `i` (0-based).
nlohmann::json point_redundancy_json(const planning::PointRedundancy& p, std::size_t i) {
  nlohmann::json entry = {{"point", i + 1}};
  if (p.best >= 0) {
    const planning::RedundancySample& b = p.samples[std::size_t(p.best)];
    entry["best_angle_deg"] = b.angle_rad * kDegPerRad;
    entry["min_limit_mm"] = b.min_limit_m * 1e3;
    double worst = b.min_limit_m;
    for (const auto& s : p.samples)
      if (s.reachable)
        worst = std::min(worst, s.min_limit_m);
    entry["worst_angle_min_limit_mm"] = worst * 1e3;
  } else {
    entry["best_angle_deg"] = nullptr;
  }
  return entry;
}

// advice.json's redundancy: the study per point and the best constant angle.
nlohmann::json redundancy_study_json(const job::AdviseSettings& settings,
                                     const planning::RedundancyStudy& study) {
  nlohmann::json per_point = nlohmann::json::array();
  for (std::size_t i = 0; i < study.points.size(); ++i)
    per_point.push_back(point_redundancy_json(study.points[i], i));
  nlohmann::json redundancy = {{"angles", settings.redundancy->angles_rad.size()},
                               {"points", study.points.size()},
                               {"at", settings.redundancy->at_spindle ? "spindle" : "range"},
                               {"per_point", per_point},
                               {"elapsed_s", study.elapsed_s}};
  if (study.best_constant >= 0) {
    const double angle = settings.redundancy->angles_rad[std::size_t(study.best_constant)];
    redundancy["best_constant_angle_deg"] = angle * kDegPerRad;
    redundancy["constant_min_limit_mm"] = study.constant_min_limit_m * 1e3;
    redundancy["constant_weakest_point"] = study.constant_weakest_point + 1;
  } else {
    redundancy["best_constant_angle_deg"] = nullptr;
    redundancy["note"] = "no candidate angle reaches every point within the joint limits";
  }
  return redundancy;
}

// The message: the advice (or why there is none) and the constant
// redundancy angle.
std::string advise_message(const job::AdviseSettings& settings,
                           const planning::CuttingAdvice& advice, std::size_t stations,
                           const std::optional<planning::RedundancyStudy>& study) {
  std::string message;
  if (advice.feasible) {
    message = fmt::format(
        "advise ({}, {} station(s)): {:.0f} rpm, ap = {:.3f} mm → MRR {:.2f} cm³/min; limit "
        "{:.3f} mm (margin to chatter {:.2f}), expected offset {:.4f} mm{}\n",
        planning::to_string(settings.limit.method), stations,
        advice.best.spindle_rad_s * kRpmPerRadS, advice.best.depth_m * 1e3,
        advice.best.mrr_m3_per_s * kCm3PerMinPerM3PerS, advice.best.limit_depth_m * 1e3,
        advice.margin_to_chatter, advice.best.offset_m * 1e3,
        advice.best.offset_limited ? " (offset-limited)" : "");
  } else {
    message = "advise: no speed in the range admits one depth step within the limits\n";
  }
  if (study && study->best_constant >= 0)
    message +=
        fmt::format("  redundancy: constant angle {:g} deg, minimum stable depth {:.3f} mm\n",
                    settings.redundancy->angles_rad[std::size_t(study->best_constant)] * kDegPerRad,
                    study->constant_min_limit_m * 1e3);
  return message;
}

// One point of the robust advice (summary.json's uncertainty.advice, the
// peaks): the speed, the depth under the robust limit, what it removes.
nlohmann::json robust_speed_json(const planning::SpeedAdvice& a) {
  return {{"spindle_rpm", a.spindle_rad_s * kRpmPerRadS},
          {"depth_mm", a.depth_m * 1e3},
          {"robust_limit_depth_mm", a.limit_depth_m * 1e3},
          {"expected_offset_mm", a.offset_m * 1e3},
          {"offset_limited", a.offset_limited},
          {"mrr_cm3_per_min", a.mrr_m3_per_s * kCm3PerMinPerM3PerS},
          {"stage", a.stage == 0 ? "scan" : "refine"}};
}

/// The robust advice of an uncertain job (issue 33): advice_map_robust.csv
/// (every speed scanned or refined, in speed order: the robust limit, the
/// advised depth there, its offset and MRR), summary.json's and
/// advice.json's "uncertainty", one more line of the message.
void add_robust_advice(CommandResult& result, const analysis::RobustCuttingAdvice& robust,
                       const planning::CuttingAdvice& nominal) {
  const planning::CuttingAdvice& advice = robust.advice;
  io::CsvTable map({"spindle_rpm", "stage", "robust_limit_depth_mm", "limited", "depth_mm",
                    "offset_mm", "offset_limited", "mrr_cm3_per_min"});
  std::vector<planning::SpeedAdvice> rows = advice.scan;
  std::stable_sort(rows.begin(), rows.end(),
                   [](const auto& a, const auto& b) { return a.spindle_rad_s < b.spindle_rad_s; });
  for (const auto& a : rows)
    map.add_row({a.spindle_rad_s * kRpmPerRadS, double(a.stage), a.limit_depth_m * 1e3,
                 a.limited ? 1.0 : 0.0, a.depth_m * 1e3, a.offset_m * 1e3,
                 a.offset_limited ? 1.0 : 0.0, a.mrr_m3_per_s * kCm3PerMinPerM3PerS});
  nlohmann::json peaks = nlohmann::json::array();
  for (const auto& p : advice.peaks)
    peaks.push_back(robust_speed_json(p));
  nlohmann::json block = {{"draws", robust.draw_count},
                          {"source", robust.draws.source},
                          {"variables", robust.draws.names},
                          {"max_chatter_probability", robust.max_chatter_probability},
                          {"feasible", advice.feasible},
                          {"advice", robust_speed_json(advice.best)},
                          {"p_chatter", robust.p_chatter.value},
                          {"p_chatter_se", robust.p_chatter.standard_error},
                          {"elapsed_s", robust.elapsed_s}};
  if (nominal.feasible) {
    block["nominal_p_chatter"] = robust.nominal_p_chatter.value;
    block["nominal_p_chatter_se"] = robust.nominal_p_chatter.standard_error;
  }
  if (advice.check.done) {
    block["nominal_structure_spectral_radius"] = advice.check.spectral_radius;
    block["check_method"] = advice.check.method;
  }
  result.documents.front().second["uncertainty"] = block;
  result.documents.front().second["uncertainty"]["peaks"] = peaks;
  result.summary["uncertainty"] = block;
  result.tables.emplace_back("advice_map_robust", std::move(map));
  if (advice.feasible) {
    result.message += fmt::format(
        "  robust ({} draws, P(chatter) ≤ {:g} %): {:.0f} rpm, ap = {:.3f} mm → MRR {:.2f} "
        "cm³/min, P(chatter) {:.1f} % ± {:.1f}",
        robust.draw_count, robust.max_chatter_probability * 100.0,
        advice.best.spindle_rad_s * kRpmPerRadS, advice.best.depth_m * 1e3,
        advice.best.mrr_m3_per_s * kCm3PerMinPerM3PerS, robust.p_chatter.value * 100.0,
        robust.p_chatter.standard_error * 100.0);
  } else {
    result.message += fmt::format(
        "  robust ({} draws, P(chatter) ≤ {:g} %): no speed in the range admits one depth step",
        robust.draw_count, robust.max_chatter_probability * 100.0);
  }
  if (nominal.feasible)
    result.message += fmt::format("; the nominal advice chatters in {:.1f} % ± {:.1f} of the draws",
                                  robust.nominal_p_chatter.value * 100.0,
                                  robust.nominal_p_chatter.standard_error * 100.0);
  result.message += "\n";
}

}  // namespace

CommandResult compute_advise(const job::Job& job, int threads) {
  const analysis::CuttingParameterAdvice run = analysis::cutting_parameter_advice(job, threads);
  const job::AdviseSettings& settings = *job.advise;
  const planning::CuttingAdvice& advice = run.advice;
  const std::vector<dynamics::ModalModel>& stations = run.stations;
  const std::optional<planning::RedundancyStudy>& study = run.redundancy;
  const std::optional<robot::RobotModel>& robot = run.robot;
  const double elapsed_s = run.elapsed_s;

  // advice.json: everything; summary.json: the key figures.
  nlohmann::json peaks = nlohmann::json::array();
  for (const auto& p : advice.peaks)
    peaks.push_back(speed_json(p, job));
  const nlohmann::json limits = limits_json(settings);
  const nlohmann::json check = floquet_check_json(advice, settings);
  nlohmann::json document = {
      {"command", "advise"},
      {"job", job.source.string()},
      {"method", std::string(planning::to_string(settings.limit.method))},
      {"along", settings.along_path ? "path" : "posture"},
      {"dynamics", settings.along_path ? "robot" : job::dynamics_source_name(job.dynamics_source)},
      {"stations", stations.size()},
      {"limits", limits},
      {"feasible", advice.feasible},
      {"advice", speed_json(advice.best, job)},
      {"floquet_check", check},
      {"peaks", peaks},
      {"process",
       {{"ae_mm", job.process->radial_depth_m * 1e3},
        {"feed_per_tooth_mm", job.process->feed_per_tooth_m * 1e3},
        {"teeth", job.tool->teeth},
        {"direction", std::string(cutting::to_string(job.process->direction))}}},
      {"advice_s", advice.elapsed_s},
      {"elapsed_s", elapsed_s}};
  if (settings.along_path)
    document["redundancy_angle_deg"] = settings.redundancy_angle_rad * kDegPerRad;
  nlohmann::json summary = {{"command", "advise"},
                            {"job", job.source.string()},
                            {"feasible", advice.feasible},
                            {"spindle_rpm", advice.best.spindle_rad_s * kRpmPerRadS},
                            {"depth_mm", advice.best.depth_m * 1e3},
                            {"mrr_cm3_per_min", advice.best.mrr_m3_per_s * kCm3PerMinPerM3PerS},
                            {"limit_depth_mm", advice.best.limit_depth_m * 1e3},
                            {"expected_offset_mm", advice.best.offset_m * 1e3},
                            {"offset_limited", advice.best.offset_limited},
                            {"stations", stations.size()},
                            {"method", std::string(planning::to_string(settings.limit.method))},
                            {"elapsed_s", elapsed_s}};
  if (advice.feasible)
    summary["margin_to_chatter"] = advice.margin_to_chatter;
  if (advice.check.done)
    summary["spectral_radius"] = advice.check.spectral_radius;

  io::CsvTable map = advice_map_table(advice);

  std::optional<io::CsvTable> redundancy_table;
  if (study) {
    redundancy_table.emplace(redundancy_csv(*study, robot->dof()));
    document["redundancy"] = redundancy_study_json(settings, *study);
    if (study->best_constant >= 0) {
      const double angle = settings.redundancy->angles_rad[std::size_t(study->best_constant)];
      summary["redundancy_angle_deg"] = angle * kDegPerRad;
      summary["redundancy_min_limit_mm"] = study->constant_min_limit_m * 1e3;
    }
  }

  CommandResult result;
  result.tables.emplace_back("advice_map", std::move(map));
  if (redundancy_table)
    result.tables.emplace_back("redundancy", std::move(*redundancy_table));
  result.documents.emplace_back("advice", std::move(document));
  result.summary = std::move(summary);

  result.message = advise_message(settings, advice, stations.size(), study);
  if (job.uncertainty)
    add_robust_advice(result, analysis::robust_cutting_advice(job, advice, threads), advice);
  return result;
}

}  // namespace robomill::commands
