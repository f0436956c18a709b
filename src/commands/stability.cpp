// robomill stability JOB: the stability lobe diagram (DESIGN.md §3) by the
// zero-order approximation or the semi-/full-discretization methods. The
// diagram is analysis::stability_diagram's; this file writes it as sld.csv
// (sld_envelope.csv, map.csv) and summary.json. With an `uncertainty:`
// section also analysis::stability_band's quantile lobes and chatter
// probability (lobes_quantiles.csv, chatter_probability.csv and
// summary.json's "uncertainty", issue 33).

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>

#include "band_outputs.hpp"
#include "robomill/analysis/stability_band.hpp"
#include "robomill/analysis/stability_diagram.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/summary.hpp"

namespace robomill::commands {
namespace {

using Settings = job::StabilitySettings;
using analysis::StabilityLimit;

const char* method_name(Settings::Method method) {
  switch (method) {
    case Settings::Method::zoa:
      return "zoa";
    case Settings::Method::sdm:
      return "sdm";
    case Settings::Method::fdm:
      return "fdm";
    case Settings::Method::fdm2:
      return "fdm2";
  }
  return "?";
}

io::CsvTable limit_table(const std::vector<StabilityLimit>& limits, bool with_mode) {
  std::vector<std::string> columns = {"spindle_rpm", "depth_limit_mm", "chatter_freq_hz",
                                      "bifurcation"};
  if (with_mode)
    columns.push_back("mode");
  io::CsvTable table(columns);
  for (const StabilityLimit& l : limits) {
    std::vector<io::CsvTable::Cell> row = {l.spindle_rad_s * kRpmPerRadS, l.depth_limit_m * 1e3,
                                           l.chatter_frequency_hz,
                                           std::string(analysis::to_string(l.bifurcation))};
    if (with_mode)
      row.emplace_back(static_cast<double>(l.mode + 1));
    table.add_cells(row);
  }
  return table;
}

nlohmann::json experiments_json(const analysis::ExperimentComparison& comparison) {
  nlohmann::json tests = nlohmann::json::array();
  for (const analysis::ExperimentCheck& check : comparison.tests) {
    const job::Experiment& e = check.experiment;
    nlohmann::json entry = {{"spindle_rpm", e.spindle_rad_s * kRpmPerRadS},
                            {"depth_mm", e.axial_depth_m * 1e3},
                            {"observed_chatter", e.chatter}};
    if (check.limit_m) {
      entry["limit_mm"] = *check.limit_m * 1e3;
      entry["predicted_chatter"] = check.predicted_chatter;
      entry["agrees"] = check.agrees;
      if (check.chatter_frequency_hz)
        entry["chatter_freq_hz"] = *check.chatter_frequency_hz;
      if (check.governing_mode >= 0 && check.governing_mode_fn_hz) {
        entry["governing_mode"] = check.governing_mode + 1;
        entry["governing_mode_fn_hz"] = *check.governing_mode_fn_hz;
      }
    } else {
      entry["note"] = "spindle speed outside the computed range";
    }
    tests.push_back(entry);
  }
  return {{"tests", tests},
          {"agree", comparison.agree},
          {"compared", comparison.compared},
          {"total", comparison.tests.size()}};
}

nlohmann::json diagram_summary(const std::vector<StabilityLimit>& limits) {
  const analysis::DiagramFigures figures = analysis::diagram_figures(limits);
  return {{"min_limit_mm", figures.min_limit_m * 1e3},
          {"min_limit_spindle_rpm", figures.min_limit_spindle_rad_s * kRpmPerRadS},
          {"max_limit_mm", figures.max_limit_m * 1e3},
          {"speeds_stable_to_depth_max", figures.speeds_stable_to_depth_max},
          {"speeds_period_doubling", figures.speeds_period_doubling}};
}

/// 000 Figures 12-13: how far the deformed engagement moved the cut, and
/// each variant's figures and its expansion over the traditional diagram.
nlohmann::json deformation_summary(const analysis::StabilityDiagram& diagram) {
  const analysis::DeformedEngagementFigures& d = *diagram.deformation;
  nlohmann::json deformation = {
      {"robot_included", d.robot_included},
      {"mode_shapes_along_tool", d.mode_shapes_along_tool},
      {"table_depths", d.table_depths},
      {"nominal_entry_deg", d.nominal_entry_rad * 180.0 / std::numbers::pi},
      {"entry_at_depth_max_deg",
       {{"tip", d.entry_at_depth_max_tip_rad * 180.0 / std::numbers::pi},
        {"top", d.entry_at_depth_max_top_rad * 180.0 / std::numbers::pi}}}};
  nlohmann::json list = nlohmann::json::object();
  for (const analysis::DeformationVariant& v : diagram.variants) {
    nlohmann::json entry = diagram_summary(v.limits);
    entry["max_expansion_pct"] = 100.0 * v.max_expansion;
    entry["max_expansion_spindle_rpm"] = v.max_expansion_spindle_rad_s * kRpmPerRadS;
    entry["experiments"] = experiments_json(v.experiments);
    list[v.name] = entry;
  }
  deformation["variants"] = list;
  return deformation;
}

/// The band of the uncertain inputs (issue 33): lobes_quantiles.csv (one
/// row per speed), chatter_probability.csv (speed-major: every depth of one
/// speed, then the next speed, as map.csv) and summary.json's
/// "uncertainty".
void add_stability_band(CommandResult& result, const analysis::StabilityBand& band) {
  nlohmann::json pockets = nlohmann::json::array();
  for (const analysis::RobustPocket& p : band.robust_pockets) {
    pockets.push_back({{"spindle_rpm", p.spindle_rad_s * kRpmPerRadS},
                       {"depth_limit_q05_mm", p.depth_limit_q05_m * 1e3}});
  }
  result.summary["uncertainty"] = {
      {"draws", band.draw_count},
      {"source", band.draws.source},
      {"variables", band.draws.names},
      {"depth_limit_q05_min_mm", band.q05_min_m * 1e3},
      {"depth_limit_q05_min_spindle_rpm", band.q05_min_spindle_rad_s * kRpmPerRadS},
      {"depth_limit_q95_max_mm", band.q95_max_m * 1e3},
      {"depth_limit_q95_max_spindle_rpm", band.q95_max_spindle_rad_s * kRpmPerRadS},
      {"robust_pockets", pockets},
      {"elapsed_s", band.elapsed_s}};
  result.tables.emplace_back("lobes_quantiles", band_quantiles_table(band));
  result.tables.emplace_back("chatter_probability", band_probability_table(band));
  result.message += fmt::format(
      "  uncertainty: {} draws ({}) in {:.3f} s; 5 % lobe from {:.3f} mm (at {:.0f} "
      "rpm), 95 % lobe up to {:.3f} mm\n",
      band.draw_count, band.draws.source, band.elapsed_s, band.q05_min_m * 1e3,
      band.q05_min_spindle_rad_s * kRpmPerRadS, band.q95_max_m * 1e3);
  if (!band.robust_pockets.empty()) {
    const analysis::RobustPocket& best = band.robust_pockets.front();
    result.message +=
        fmt::format("  robust pocket: {:.0f} rpm, 95 % of the draws stable to {:.3f} mm\n",
                    best.spindle_rad_s * kRpmPerRadS, best.depth_limit_q05_m * 1e3);
  }
}

}  // namespace

io::CsvTable band_quantiles_table(const analysis::StabilityBand& band) {
  io::CsvTable lobes({"spindle_rpm", "depth_limit_q05_mm", "depth_limit_q50_mm",
                      "depth_limit_q95_mm", "depth_limit_nominal_mm"});
  for (std::size_t s = 0; s < band.speeds_rad_s.size(); ++s) {
    lobes.add_row({band.speeds_rad_s[s] * kRpmPerRadS, band.q05_m[s].value * 1e3,
                   band.q50_m[s].value * 1e3, band.q95_m[s].value * 1e3,
                   band.nominal_limit_m[s] * 1e3});
  }
  return lobes;
}

io::CsvTable band_probability_table(const analysis::StabilityBand& band) {
  io::CsvTable probability({"spindle_rpm", "depth_mm", "p_chatter", "p_chatter_se"});
  for (std::size_t s = 0; s < band.speeds_rad_s.size(); ++s) {
    for (std::size_t d = 0; d < band.depths_m.size(); ++d) {
      const auto row = static_cast<Eigen::Index>(d);
      const auto column = static_cast<Eigen::Index>(s);
      probability.add_row({band.speeds_rad_s[s] * kRpmPerRadS, band.depths_m[d] * 1e3,
                           band.p_chatter(row, column), band.p_chatter_se(row, column)});
    }
  }
  return probability;
}

CommandResult compute_stability(const job::Job& job, int threads) {
  const analysis::StabilityDiagram diagram = analysis::stability_diagram(job, threads);
  CommandResult result = stability_result(job, diagram);
  if (job.uncertainty)
    add_stability_band(result, analysis::stability_band(job, diagram, threads));
  return result;
}

CommandResult stability_result(const job::Job& job, const analysis::StabilityDiagram& diagram) {
  const Settings& settings = *job.stability;
  const bool want_coupled = settings.modes != Settings::Modes::envelope;
  const bool want_envelope = settings.modes != Settings::Modes::coupled;
  const std::vector<StabilityLimit>& primary = diagram.primary();
  const std::optional<dynamics::ModalModel>& modes = diagram.modes;

  nlohmann::json summary = {
      {"command", "stability"},
      {"job", job.source.string()},
      {"method", method_name(settings.method)},
      {"elapsed_s", diagram.elapsed_s},
      {"speeds",
       {{"from_rpm", settings.speed_from_rad_s * kRpmPerRadS},
        {"to_rpm", settings.speed_to_rad_s * kRpmPerRadS},
        {"count", settings.speed_count}}},
      {"depth_max_mm", settings.depth_max_m * 1e3},
      {"depth_tolerance", settings.depth_tolerance},
      {"continuation", settings.continuation},
      {"modes", settings.modes == Settings::Modes::coupled    ? "coupled"
                : settings.modes == Settings::Modes::envelope ? "envelope"
                                                              : "both"},
      {"dynamics", job::dynamics_source_name(job.dynamics_source)},
      {"mode_count", modes ? modes->size() : 0},
      {"process_damping", settings.process_damping == Settings::Damping::none ? "none"
                          : settings.process_damping == Settings::Damping::energy_balance
                              ? "energy_balance"
                              : "linear_equivalent"},
      {"experiments", experiments_json(diagram.experiments)},
  };
  std::string convergence_warning;
  if (settings.method != Settings::Method::zoa) {
    summary["discretization"] = settings.discretization;
    if (const auto& check = diagram.discretization) {
      summary["steps_per_period_of_highest_mode"] = check->steps_per_period;
      if (!check->converged()) {
        convergence_warning = fmt::format(
            "{} steps per tooth period give {:.1f} steps per period of the {:.4g} Hz mode at "
            "{:.0f} rpm: the lowest speeds may not be converged; discretization: {:.0f} gives 8",
            check->discretization, check->steps_per_period, check->highest_mode_hz,
            check->lowest_spindle_rad_s * kRpmPerRadS, check->discretization_for_convergence);
        summary["discretization_warning"] = convergence_warning;
      }
    }
  }
  if (job.posture_library) {
    // 001 Eq 16-18: where the table was interpolated and with what weights.
    const job::PostureLibrary& library = *job.posture_library;
    nlohmann::json query = nlohmann::json::array(), weights = nlohmann::json::array();
    for (Eigen::Index i = 0; i < library.query_rad.size(); ++i)
      query.push_back(library.query_rad[i] * 180.0 / std::numbers::pi);
    for (Eigen::Index i = 0; i < library.weights.size(); ++i)
      weights.push_back(library.weights[i]);
    summary["posture_interpolation"] = {{"at_deg", query},
                                        {"from", library.query_source},
                                        {"postures", library.postures_rad.size()},
                                        {"weights", weights},
                                        {"exact_posture", library.exact_index + 1}};
  }
  summary.update(diagram_summary(primary));
  if (want_coupled && want_envelope) {
    summary["envelope"] = diagram_summary(diagram.envelope);
    summary["envelope"]["experiments"] = experiments_json(*diagram.envelope_experiments);
  }
  if (diagram.deformation)
    summary["deformation"] = deformation_summary(diagram);
  if (const auto& map = diagram.map) {
    summary["map"] = {{"speeds", map->spindle_rad_s.size()},
                      {"depths", map->depth_m.size()},
                      {"grid_points_per_s", static_cast<double>(map->spectral_radius.size()) /
                                                std::max(diagram.elapsed_s, 1e-9)}};
  }
  if (!job.name.empty())
    summary["name"] = job.name;

  CommandResult result;
  result.summary = std::move(summary);
  const std::vector<analysis::DeformationVariant>& variants = diagram.variants;
  if (variants.empty()) {
    result.tables.emplace_back("sld", limit_table(primary, !want_coupled));
  } else {
    // One limit and chatter-frequency column per variant next to the
    // traditional diagram's (DESIGN.md's columns).
    std::vector<std::string> columns = {"spindle_rpm", "depth_limit_mm", "chatter_freq_hz",
                                        "bifurcation"};
    for (std::size_t v = 1; v < variants.size(); ++v) {
      columns.push_back(fmt::format("depth_limit_{}_mm", variants[v].name));
      columns.push_back(fmt::format("chatter_freq_{}_hz", variants[v].name));
    }
    io::CsvTable table(columns);
    for (std::size_t i = 0; i < primary.size(); ++i) {
      const StabilityLimit& l = primary[i];
      std::vector<io::CsvTable::Cell> row = {l.spindle_rad_s * kRpmPerRadS, l.depth_limit_m * 1e3,
                                             l.chatter_frequency_hz,
                                             std::string(analysis::to_string(l.bifurcation))};
      for (std::size_t v = 1; v < variants.size(); ++v) {
        row.emplace_back(variants[v].limits[i].depth_limit_m * 1e3);
        row.emplace_back(variants[v].limits[i].chatter_frequency_hz);
      }
      table.add_cells(row);
    }
    result.tables.emplace_back("sld", std::move(table));
  }
  if (want_coupled && want_envelope)
    result.tables.emplace_back("sld_envelope", limit_table(diagram.envelope, true));
  if (const auto& map = diagram.map) {
    io::CsvTable table({"spindle_rpm", "depth_mm", "spectral_radius"});
    for (std::size_t i = 0; i < map->spindle_rad_s.size(); ++i) {
      for (std::size_t j = 0; j < map->depth_m.size(); ++j) {
        table.add_row(
            {map->spindle_rad_s[i] * kRpmPerRadS, map->depth_m[j] * 1e3,
             map->spectral_radius(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j))});
      }
    }
    result.tables.emplace_back("map", std::move(table));
  }

  const analysis::DiagramFigures figures = analysis::diagram_figures(primary);
  result.message = fmt::format(
      "stability ({}): {} speeds in {:.3f} s; limit {:.3f} mm (at {:.0f} rpm) … {:.3f} mm\n",
      method_name(settings.method), diagram.speeds_rad_s.size(), diagram.elapsed_s,
      figures.min_limit_m * 1e3, figures.min_limit_spindle_rad_s * kRpmPerRadS,
      figures.max_limit_m * 1e3);
  if (!convergence_warning.empty())
    result.message += "  warning: " + convergence_warning + "\n";
  if (!job.experiments.empty()) {
    result.message += fmt::format("  experiments: {} of {} agree with the prediction\n",
                                  diagram.experiments.agree, diagram.experiments.compared);
  }
  return result;
}

}  // namespace robomill::commands
