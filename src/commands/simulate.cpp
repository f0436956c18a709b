// robomill simulate JOB: the nonlinear, regenerative time-domain simulation
// of 002 §3 (docs/simulation.md). The structure (modal model, 002's 1/2-DOF
// fixations, the reduced 6-D robot model, or rigid) is driven by the cutting
// forces of the teeth, whose chips come from the swept-surface memory; the
// response gives the static deviation, overshoot, settling time, first
// frequency and the chatter verdict. The run is analysis::time_simulation's;
// this file writes it as timeseries.csv, spectrum.csv and summary.json.

#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "robomill/analysis/time_simulation.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/summary.hpp"

namespace robomill::commands {
namespace {

nlohmann::json per_axis(const simulation::ResponseMetrics& m, double scale,
                        double simulation::DirectionResponse::*member, bool zero_is_null) {
  nlohmann::json out;
  for (int a = 0; a < 3; ++a) {
    const double v = m.direction[a].*member;
    if (zero_is_null && v == 0.0)
      out[std::string(1, "xyz"[a])] = nullptr;
    else
      out[std::string(1, "xyz"[a])] = v * scale;
  }
  return out;
}

}  // namespace

CommandResult compute_simulate(const job::Job& job) {
  const analysis::TimeSimulation simulated = analysis::time_simulation(job);
  const job::SimulationSettings& s = *job.simulation;
  const simulation::LinearStructure& structure = simulated.structure;
  const int steps_per_tooth = simulated.steps_per_tooth;
  const simulation::SimulationResult& result = simulated.result;
  const simulation::ResponseOptions& response = simulated.response_options;
  const simulation::ResponseMetrics& metrics = simulated.metrics;
  const double elapsed_s = simulated.elapsed_s;

  io::CsvTable series({"t_s", "fx_N", "fy_N", "fz_N", "x_mm", "y_mm", "z_mm", "teeth_cutting"});
  for (std::size_t i = 0; i < result.size(); ++i) {
    const Eigen::Vector3d& f = result.force_n[i];
    const Eigen::Vector3d u = result.displacement_m[i] * 1e3;
    series.add_row({result.time_s[i], f.x(), f.y(), f.z(), u.x(), u.y(), u.z(),
                    static_cast<double>(result.teeth_cutting[i])});
  }
  // Spectrum of the steady window (amplitudes, Hann window).
  const auto& force = simulated.force_spectra_n;
  const auto& displacement = simulated.displacement_spectra_mm;
  io::CsvTable spectrum({"frequency_hz", "fx_N", "fy_N", "fz_N", "x_mm", "y_mm", "z_mm"});
  for (std::size_t k = 0; k < force[0].frequency_hz.size(); ++k) {
    spectrum.add_row({force[0].frequency_hz[k], force[0].amplitude[k], force[1].amplitude[k],
                      force[2].amplitude[k], displacement[0].amplitude[k],
                      displacement[1].amplitude[k], displacement[2].amplitude[k]});
  }

  const auto& x = metrics.direction[0];
  const Eigen::VectorXd& frequencies = simulated.natural_frequencies_hz;
  const int max_teeth = simulated.max_teeth_cutting;
  nlohmann::json summary = {
      {"command", "simulate"},
      {"job", job.source.string()},
      {"model", s.model_name},
      {"structure", structure.description},
      {"natural_frequencies_hz",
       std::vector<double>(frequencies.data(), frequencies.data() + frequencies.size())},
      {"duration_s", result.time_s.back()},
      {"step_s", result.step_s},
      {"steps_per_tooth", steps_per_tooth},
      {"steps", static_cast<long long>(std::llround(result.time_s.back() / result.step_s))},
      {"axial_elements", simulated.axial_elements},
      {"steady_window_s", result.time_s.back() - metrics.steady_from_s},
      {"static_deviation_mm",
       per_axis(metrics, 1e3, &simulation::DirectionResponse::static_deviation_m, false)},
      {"overshoot_pct", x.overshoot_pct},
      {"settling_time_s", x.settling_time_s},
      {"first_frequency_hz",
       per_axis(metrics, 1.0, &simulation::DirectionResponse::first_frequency_hz, true)},
      {"peak_to_peak_mm",
       per_axis(metrics, 1e3, &simulation::DirectionResponse::peak_to_peak_m, false)},
      {"overshoot_pct_xyz",
       per_axis(metrics, 1.0, &simulation::DirectionResponse::overshoot_pct, false)},
      {"settling_time_s_xyz",
       per_axis(metrics, 1.0, &simulation::DirectionResponse::settling_time_s, false)},
      {"chatter", metrics.chatter.chatter},
      {"chatter_freq_hz", metrics.chatter.chatter ? nlohmann::json(metrics.chatter.frequency_hz)
                                                  : nlohmann::json(nullptr)},
      // The verdict weighs nonharmonic_rms_mm against floor_mm and needs
      // persistence >= min_persistence (docs/simulation.md, "The chatter
      // verdict"); the energy fraction and the spread are evidence only.
      {"chatter_evidence",
       {{"nonharmonic_energy_fraction", metrics.chatter.nonharmonic_fraction},
        {"once_per_period_spread", metrics.chatter.sample_spread},
        {"largest_nonharmonic_hz", metrics.chatter.frequency_hz},
        {"nonharmonic_rms_mm", metrics.chatter.nonharmonic_rms_m * 1e3},
        {"forced_rms_mm", metrics.chatter.forced_rms_m * 1e3},
        {"floor_mm", metrics.chatter.floor_m * 1e3},
        {"floor_basis", simulation::chatter_floor_name(metrics.chatter.floor)},
        {"feed_per_tooth_mm", job.process->feed_per_tooth_m * 1e3},
        {"floor_feed_fraction", response.chatter.floor_feed_fraction},
        {"persistence", metrics.chatter.persistence},
        {"min_persistence", response.chatter.min_persistence}}},
      {"mean_force_N", io::xyz(metrics.mean_force_n)},
      {"peak_force_N", io::xyz(metrics.peak_force_n)},
      {"first_contact_s", result.first_contact_s},
      {"full_engagement_s", result.full_engagement_s},
      {"max_teeth_cutting", max_teeth},
      {"element_evaluations", result.element_evaluations},
      {"elapsed_s", elapsed_s}};

  CommandResult output;
  output.tables.emplace_back("timeseries", std::move(series));
  output.tables.emplace_back("spectrum", std::move(spectrum));
  output.summary = std::move(summary);
  output.message = fmt::format(
      "simulate: {} s of cutting on {} ({} steps of {:.3g} s) in {:.2f} s\n"
      "  static deviation x {:.4f} mm, y {:.4f} mm; overshoot (x) {:.1f} %, settling (x) "
      "{:.3f} s\n"
      "  first frequency x {:.3g} Hz, y {:.3g} Hz; {}\n",
      result.time_s.back(), structure.description, result.size() - 1, result.step_s, elapsed_s,
      metrics.direction[0].static_deviation_m * 1e3, metrics.direction[1].static_deviation_m * 1e3,
      x.overshoot_pct, x.settling_time_s, metrics.direction[0].first_frequency_hz,
      metrics.direction[1].first_frequency_hz,
      metrics.chatter.chatter ? fmt::format("CHATTER at {:.1f} Hz", metrics.chatter.frequency_hz)
                              : std::string("stable"));
  return output;
}

}  // namespace robomill::commands
