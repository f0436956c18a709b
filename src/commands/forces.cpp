// robomill forces JOB: the rigid-tool milling force history (DESIGN.md §3).
// The history is analysis::milling_force_history's; this file writes it as
// forces.csv and summary.json.

#include <fmt/format.h>

#include <iostream>

#include "robomill/analysis/milling_force_history.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/summary.hpp"

namespace robomill::commands {
namespace {

io::CsvTable force_table(const cutting::ForceSeries& series) {
  io::CsvTable table({"angle_deg", "t_s", "fx_N", "fy_N", "fz_N", "torque_Nm"});
  for (std::size_t i = 0; i < series.size(); ++i) {
    const Eigen::Vector3d& f = series.force_n[i];
    table.add_row({series.rotation_rad[i] * kDegPerRad, series.time_s[i], f.x(), f.y(), f.z(),
                   series.torque_nm[i]});
  }
  return table;
}

nlohmann::json law_summary(const job::Job& job, const analysis::MillingForceHistory& history) {
  nlohmann::json law = {{"law", std::string(cutting::law_name(*job.cutting))}};
  if (history.linear_law) {
    // For the size-dependent law these are the coefficients at this process's
    // mean chip thickness (004 Eq A2-A3).
    const cutting::LinearLaw& k = *history.linear_law;
    law["Ktc_N_per_mm2"] = k.Ktc_pa * 1e-6;
    law["Krc_N_per_mm2"] = k.Krc_pa * 1e-6;
    law["Kac_N_per_mm2"] = k.Kac_pa * 1e-6;
    law["Kte_N_per_mm"] = k.Kte_n_per_m * 1e-3;
    law["Kre_N_per_mm"] = k.Kre_n_per_m * 1e-3;
    law["Kae_N_per_mm"] = k.Kae_n_per_m * 1e-3;
  }
  return law;
}

}  // namespace

CommandResult compute_forces(const job::Job& job, int threads) {
  const analysis::MillingForceHistory history = analysis::milling_force_history(job, threads);
  const cutting::ForceSeries& series = history.series;
  const cutting::ForceStatistics& stats = history.statistics;
  const cutting::ForceSampling& sampling = history.sampling;

  const cutting::MillingProcess& process = *job.process;
  const double tooth_period_s = history.tooth_period_s;
  nlohmann::json summary = {
      {"command", "forces"},
      {"job", job.source.string()},
      {"mean_N", io::xyz(stats.mean_n)},
      {"peak_N", io::xyz(stats.peak_n)},
      {"min_N", io::xyz(stats.min_n)},
      {"max_N", io::xyz(stats.max_n)},
      {"peak_to_peak_N", io::xyz(stats.peak_to_peak_n)},
      {"mean_torque_Nm", stats.mean_torque_nm},
      {"peak_torque_Nm", stats.peak_torque_nm},
      {"mean_power_W", stats.mean_power_w},
      {"tooth_period_s", tooth_period_s},
      {"tooth_passing_hz", 1.0 / tooth_period_s},
      {"engagement_deg",
       {{"entry", history.nominal_engagement.entry_rad * kDegPerRad},
        {"exit", history.nominal_engagement.exit_rad * kDegPerRad}}},
      {"helix_lag_deg", history.helix_lag_rad * kDegPerRad},
      {"mean_chip_thickness_mm", history.mean_chip_m * 1e3},
      {"cutting", law_summary(job, history)},
      {"direction", std::string(cutting::to_string(process.direction))},
      {"axial_elements", history.axial_elements},
      {"samples", series.size()},
      {"revolutions", sampling.revolutions},
      {"steps_per_tooth", sampling.steps_per_tooth},
      {"elapsed_s", history.elapsed_s},
      {"frame", "forces on the tool, tool frame: x feed, z tool axis towards the spindle"},
  };
  if (!job.name.empty())
    summary["name"] = job.name;

  CommandResult result;
  result.tables.emplace_back("forces", force_table(series));
  result.summary = std::move(summary);
  result.message = fmt::format(
      "forces: {} samples over {} revolution(s), tooth period {:.6g} s ({:.4g} Hz)\n"
      "  mean  Fx {:10.2f} N  Fy {:10.2f} N  Fz {:10.2f} N  torque {:.3f} N·m\n"
      "  peak  Fx {:10.2f} N  Fy {:10.2f} N  Fz {:10.2f} N  torque {:.3f} N·m\n",
      series.size(), sampling.revolutions, tooth_period_s, 1.0 / tooth_period_s, stats.mean_n.x(),
      stats.mean_n.y(), stats.mean_n.z(), stats.mean_torque_nm, stats.peak_n.x(), stats.peak_n.y(),
      stats.peak_n.z(), stats.peak_torque_nm);
  return result;
}

}  // namespace robomill::commands
