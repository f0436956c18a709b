// robomill forces JOB: the rigid-tool milling force history (DESIGN.md §3).

#include <fmt/format.h>

#include <chrono>
#include <iostream>
#include <numbers>

#include "robomill/commands/commands.hpp"
#include "robomill/cutting/milling_forces.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/summary.hpp"

namespace robomill::commands {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

io::CsvTable force_table(const cutting::ForceSeries& series) {
  io::CsvTable table({"angle_deg", "t_s", "fx_N", "fy_N", "fz_N", "torque_Nm"});
  for (std::size_t i = 0; i < series.size(); ++i) {
    const Eigen::Vector3d& f = series.force_n[i];
    table.add_row({series.rotation_rad[i] * kDegPerRad, series.time_s[i], f.x(), f.y(), f.z(),
                   series.torque_nm[i]});
  }
  return table;
}

nlohmann::json law_summary(const job::Job& job, const cutting::MillingForceModel& model) {
  nlohmann::json law = {{"law", std::string(cutting::law_name(*job.cutting))}};
  if (model.law().is_linear()) {
    // For the size-dependent law these are the coefficients at this process's
    // mean chip thickness (004 Eq A2-A3).
    const cutting::LinearLaw& k = model.law().linear();
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
  job::require(job, {job::Section::tool, job::Section::cutting, job::Section::process});

  const auto start = std::chrono::steady_clock::now();
  const tool::Tool cutter(*job.tool);
  const int elements = job.forces.axial_elements > 0
                           ? job.forces.axial_elements
                           : cutting::default_axial_elements(cutter, job.process->axial_depth_m);
  const cutting::MillingForceModel model(cutter, *job.cutting, *job.process, elements);
  const cutting::ForceSampling sampling{job.forces.revolutions, job.forces.steps_per_tooth};
  const cutting::ForceSeries series = cutting::sample_forces(model, sampling, threads);
  const cutting::ForceStatistics stats = cutting::summarize(series, job.process->spindle_rad_s);
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const cutting::MillingProcess& process = *job.process;
  const double tooth_period_s = model.tooth_period_s();
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
       {{"entry", model.nominal_engagement().entry_rad * kDegPerRad},
        {"exit", model.nominal_engagement().exit_rad * kDegPerRad}}},
      {"helix_lag_deg", cutter.lag_angle_rad(process.axial_depth_m) * kDegPerRad},
      {"mean_chip_thickness_mm", model.mean_chip_m() * 1e3},
      {"cutting", law_summary(job, model)},
      {"direction", std::string(cutting::to_string(process.direction))},
      {"axial_elements", elements},
      {"samples", series.size()},
      {"revolutions", sampling.revolutions},
      {"steps_per_tooth", sampling.steps_per_tooth},
      {"elapsed_s", elapsed_s},
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
