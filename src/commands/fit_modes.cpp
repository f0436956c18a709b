// robomill fit-modes JOB: modal parameters from the job's measured FRFs
// (dynamics.frf), band by band (dynamics.fit), for the stability and
// simulation engines or for a modal table to paste into a job. The fit is
// analysis::measured_frf_fit's; this file writes it as modes.csv,
// frf_fit.csv, stabilization.csv, modes.yaml and summary.json.

#include <fmt/format.h>

#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "robomill/analysis/measured_frf_fit.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/summary.hpp"

namespace robomill::commands {
namespace {

std::string direction_name(const dynamics::Frf& frf) {
  return std::string(1, "xyz"[frf.response_axis]) + std::string(1, "xyz"[frf.reference_axis]);
}

nlohmann::json mode_json(const dynamics::FittedMode& m) {
  return {{"fn_hz", m.natural_frequency_hz},
          {"zeta", m.damping_ratio},
          {"k_N_per_m", m.stiffness_n_per_m},
          {"m_kg", m.mass_kg},
          {"band_hz", {m.band_low_hz, m.band_high_hz}},
          {"fit_error", m.fit_error},
          {"assurance", m.assurance},
          {"contribution", m.contribution},
          {"stable_orders", m.stable_orders}};
}

}  // namespace

CommandResult compute_fit_modes(const job::Job& job) {
  const analysis::MeasuredFrfFit run = analysis::measured_frf_fit(job);
  const analysis::StructureFit& structure = run.structure;

  // DESIGN.md's public columns first: direction,fn_hz,zeta,k_N_per_m.
  io::CsvTable modes_table({"direction", "fn_hz", "zeta", "k_N_per_m", "m_kg", "frf", "mode",
                            "band_low_hz", "band_high_hz", "fit_error", "assurance",
                            "contribution"});
  io::CsvTable fit_table(
      {"frf", "freq_hz", "measured_re", "measured_im", "fitted_re", "fitted_im"});
  io::CsvTable stabilization_table(
      {"frf", "band", "order", "freq_hz", "zeta", "stable_frequency", "stable_damping"});
  std::string snippet =
      "# Modes fitted by robomill fit-modes to " + job.source.filename().string() +
      "'s measured FRFs;\n# paste under dynamics: (or set dynamics.use: fit to refit each run).\n"
      "modes:\n";
  nlohmann::json fits = nlohmann::json::array();
  nlohmann::json all_modes = nlohmann::json::array();
  for (std::size_t f = 0; f < structure.fits.size(); ++f) {
    const dynamics::Frf& frf = structure.measured[f];
    const dynamics::ModalFit& fit = structure.fits[f];
    const std::string name = direction_name(frf);
    nlohmann::json modes = nlohmann::json::array(), rejected = nlohmann::json::array();
    for (std::size_t i = 0; i < fit.modes.size(); ++i) {
      const dynamics::FittedMode& m = fit.modes[i];
      modes_table.add_cells({std::string(1, "xyz"[frf.response_axis]), m.natural_frequency_hz,
                             m.damping_ratio, m.stiffness_n_per_m, m.mass_kg, name,
                             static_cast<double>(i + 1), m.band_low_hz, m.band_high_hz, m.fit_error,
                             m.assurance, m.contribution});
      all_modes.push_back({{"direction", std::string(1, "xyz"[frf.response_axis])},
                           {"fn_hz", m.natural_frequency_hz},
                           {"zeta", m.damping_ratio},
                           {"k_N_per_m", m.stiffness_n_per_m},
                           {"fit_error", m.fit_error}});
      modes.push_back(mode_json(m));
      if (m.stiffness_n_per_m > 0.0) {
        snippet +=
            fmt::format("  - {{direction: {}, fn: {:.6g} Hz, zeta: {:.4g} %, k: {:.6g} N/m}}\n",
                        "xyz"[frf.response_axis], m.natural_frequency_hz, 100.0 * m.damping_ratio,
                        m.stiffness_n_per_m);
      }
    }
    for (const dynamics::FittedMode& m : fit.rejected)
      rejected.push_back(mode_json(m));
    // The fit drops a 0 Hz point; the grids then align from the top.
    const dynamics::Frf& fitted = fit.fitted.front();
    const std::size_t offset = run.first_fitted_point[f];
    for (std::size_t i = 0; i < fitted.frequency_hz.size(); ++i) {
      const std::complex<double> h = frf.value[i + offset], h_fit = fitted.value[i];
      fit_table.add_cells(
          {name, fitted.frequency_hz[i], h.real(), h.imag(), h_fit.real(), h_fit.imag()});
    }
    for (const dynamics::StabilizationPoint& p : fit.stabilization) {
      stabilization_table.add_cells({name, static_cast<double>(p.band),
                                     static_cast<double>(p.order), p.frequency_hz, p.damping_ratio,
                                     p.stable_frequency ? 1.0 : 0.0, p.stable_damping ? 1.0 : 0.0});
    }
    nlohmann::json bands = nlohmann::json::array();
    for (const dynamics::FitBand& b : fit.bands_used)
      bands.push_back({{"from_hz", b.low_hz}, {"to_hz", b.high_hz}, {"max_order", b.max_order}});
    fits.push_back({{"frf", name},
                    {"kind", dynamics::kind_name(frf.kind)},
                    {"points", frf.frequency_hz.size()},
                    {"overall_error", fit.overall_error},
                    {"bands", bands},
                    {"modes", modes},
                    {"rejected", rejected}});
  }

  nlohmann::json summary = {{"command", "fit-modes"},
                            {"job", job.source.string()},
                            {"elapsed_s", run.elapsed_s},
                            {"frfs_read", run.frfs_read},
                            {"frfs_fitted", structure.fits.size()},
                            {"modes", all_modes},
                            {"fit_error", run.worst_fit_error},
                            {"fits", fits}};
  CommandResult result;
  result.tables.emplace_back("modes", std::move(modes_table));
  result.tables.emplace_back("frf_fit", std::move(fit_table));
  result.tables.emplace_back("stabilization", std::move(stabilization_table));
  result.texts.emplace_back("modes.yaml", std::move(snippet));
  result.summary = std::move(summary);

  std::string& message = result.message;
  message = fmt::format("fit-modes: {} FRF(s) fitted in {:.2f} s, {} modes\n",
                        structure.fits.size(), run.elapsed_s, structure.modes.size());
  for (std::size_t f = 0; f < structure.fits.size(); ++f) {
    message += fmt::format("  H{}: error {:.2g} %\n", direction_name(structure.measured[f]),
                           100.0 * structure.fits[f].overall_error);
    for (const dynamics::FittedMode& m : structure.fits[f].modes) {
      message += fmt::format("    {:10.4f} Hz  zeta {:6.3f} %  k {:10.4g} N/m  error {:.2g} %\n",
                             m.natural_frequency_hz, 100.0 * m.damping_ratio, m.stiffness_n_per_m,
                             100.0 * m.fit_error);
    }
  }
  return result;
}

}  // namespace robomill::commands
