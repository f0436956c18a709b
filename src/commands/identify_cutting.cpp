// robomill identify-cutting DATA.csv: the six linear cutting coefficients from
// mean forces measured at several feeds per tooth (000 §6.2, 001 §3.2). The
// engagement and the fit are analysis::identify_cutting_coefficients's; this
// file reads the typed options (over the job's setup) and DATA.csv, and writes
// fit.csv, cutting.yaml and summary.json.

#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <optional>

#include "robomill/analysis/cutting_coefficient_identification.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/summary.hpp"
#include "robomill/job/units.hpp"

namespace robomill::commands {
namespace {

/// A length typed on the command line: "2", "2 mm", "0.002 m" (bare = mm).
std::optional<double> length_option(const std::string& text, const std::string& option) {
  if (text.empty())
    return std::nullopt;
  job::Quantity quantity;
  try {
    quantity = job::parse_quantity(text);
  } catch (const std::invalid_argument& error) {
    throw InputError(option, 0, error.what());
  }
  double meters = quantity.value_si;
  if (quantity.dimension == job::dimensions::none) {
    meters *= 1e-3;
  } else if (!(quantity.dimension == job::dimensions::length)) {
    throw InputError(option, 0, "expected a length such as '2 mm', got '" + text + "'");
  }
  if (!(meters > 0.0) || !std::isfinite(meters)) {
    throw InputError(option, 0, "must be a positive length, got '" + text + "'");
  }
  return meters;
}

/// The job's setup (--job), with the typed options over it.
analysis::CuttingTestSetup setup_from(const IdentifyCuttingInputs& options) {
  analysis::CuttingTestSetup setup;
  if (!options.job_file.empty())
    setup = analysis::cutting_test_setup(job::load_job(options.job_file));
  if (!options.teeth.empty()) {
    try {
      std::size_t used = 0;
      setup.teeth = std::stoi(options.teeth, &used);
      if (used != options.teeth.size())
        throw std::invalid_argument("trailing characters");
    } catch (const std::exception&) {
      throw InputError("--teeth", 0, "expected a positive integer, got '" + options.teeth + "'");
    }
  }
  if (setup.teeth < 1) {
    throw InputError("--teeth", 0, "the number of teeth is required (--teeth or --job) and ≥ 1");
  }
  if (auto v = length_option(options.axial_depth, "--ap"))
    setup.axial_depth_m = v;
  if (auto v = length_option(options.radial_depth, "--ae"))
    setup.radial_depth_m = v;
  if (auto v = length_option(options.diameter, "--diameter"))
    setup.diameter_m = v;
  if (!options.direction.empty()) {
    setup.direction =
        options.direction == "up" ? cutting::MillingDirection::up : cutting::MillingDirection::down;
  }
  return setup;
}

}  // namespace

CommandResult compute_identify_cutting(const IdentifyCuttingInputs& options) {
  const analysis::CuttingTestSetup setup = setup_from(options);
  const io::CsvTable data = io::read_csv(options.data_file);
  const std::string source = options.data_file.string();
  for (const char* column : {"feed_per_tooth_mm", "fx_N", "fy_N", "fz_N"}) {
    if (data.find(column) < 0) {
      throw InputError(source, 1,
                       std::string("missing column '") + column +
                           "'; expected feed_per_tooth_mm,fx_N,fy_N,fz_N[,ap_mm][,ae_mm]");
    }
  }
  const int feed_col = data.find("feed_per_tooth_mm");
  const int ap_col = data.find("ap_mm");
  const int ae_col = data.find("ae_mm");
  const double sign = options.measured_on == "workpiece" ? -1.0 : 1.0;

  std::vector<analysis::MeasuredCuttingTest> measured;
  for (std::size_t r = 0; r < data.rows(); ++r) {
    analysis::MeasuredCuttingTest test;
    test.row = static_cast<int>(r + 1);
    test.feed_per_tooth_m = data.at(r, static_cast<std::size_t>(feed_col)) * 1e-3;
    test.mean_force_n =
        sign * Eigen::Vector3d(data.at(r, static_cast<std::size_t>(data.find("fx_N"))),
                               data.at(r, static_cast<std::size_t>(data.find("fy_N"))),
                               data.at(r, static_cast<std::size_t>(data.find("fz_N"))));
    if (ap_col >= 0)
      test.axial_depth_m = data.at(r, static_cast<std::size_t>(ap_col)) * 1e-3;
    if (ae_col >= 0)
      test.radial_depth_m = data.at(r, static_cast<std::size_t>(ae_col)) * 1e-3;
    measured.push_back(test);
  }

  const analysis::CuttingCoefficientIdentification identification =
      analysis::identify_cutting_coefficients(setup, measured, source);
  const std::vector<cutting::MeanForceMeasurement>& tests = identification.tests;
  const cutting::CoefficientFit& fit = identification.fit;
  const cutting::LinearLaw& k = fit.coefficients;

  io::CsvTable table(
      {"feed_per_tooth_mm", "fx_N", "fy_N", "fz_N", "fx_fit_N", "fy_fit_N", "fz_fit_N"});
  for (std::size_t i = 0; i < tests.size(); ++i) {
    const Eigen::Vector3d& m = tests[i].mean_force_n;
    const Eigen::Vector3d& f = fit.fitted_n[i];
    table.add_row({tests[i].feed_per_tooth_m * 1e3, m.x(), m.y(), m.z(), f.x(), f.y(), f.z()});
  }
  const auto& se = fit.standard_error;
  nlohmann::json summary = {
      {"command", "identify-cutting"},
      {"data", source},
      {"coefficients",
       {{"Ktc_N_per_mm2", k.Ktc_pa * 1e-6},
        {"Krc_N_per_mm2", k.Krc_pa * 1e-6},
        {"Kac_N_per_mm2", k.Kac_pa * 1e-6},
        {"Kte_N_per_mm", k.Kte_n_per_m * 1e-3},
        {"Kre_N_per_mm", k.Kre_n_per_m * 1e-3},
        {"Kae_N_per_mm", k.Kae_n_per_m * 1e-3}}},
      {"standard_error",
       {{"Ktc_N_per_mm2", se[0] * 1e-6},
        {"Krc_N_per_mm2", se[1] * 1e-6},
        {"Kac_N_per_mm2", se[2] * 1e-6},
        {"Kte_N_per_mm", se[3] * 1e-3},
        {"Kre_N_per_mm", se[4] * 1e-3},
        {"Kae_N_per_mm", se[5] * 1e-3}}},
      {"rms_residual_N", fit.rms_residual_n},
      {"r_squared", fit.r_squared},
      {"tests", tests.size()},
      {"teeth", setup.teeth},
      {"measured_on", options.measured_on},
  };
  // A ready-to-paste `cutting:` section for a job file.
  const std::string snippet = fmt::format(
      "# identified by robomill identify-cutting from {} ({} tests, RMS residual {:.3g} N)\n"
      "cutting:\n  law: linear\n  Ktc: {:.6g} N/mm^2\n  Krc: {:.6g} N/mm^2\n  Kac: {:.6g} N/mm^2\n"
      "  Kte: {:.6g} N/mm\n  Kre: {:.6g} N/mm\n  Kae: {:.6g} N/mm\n",
      source, tests.size(), fit.rms_residual_n, k.Ktc_pa * 1e-6, k.Krc_pa * 1e-6, k.Kac_pa * 1e-6,
      k.Kte_n_per_m * 1e-3, k.Kre_n_per_m * 1e-3, k.Kae_n_per_m * 1e-3);

  CommandResult result;
  result.tables.emplace_back("fit", std::move(table));
  result.texts.emplace_back("cutting.yaml", snippet);
  result.summary = std::move(summary);
  result.message = fmt::format(
      "identify-cutting: {} tests, RMS residual {:.3g} N, R² {:.6f}\n"
      "  Ktc {:9.2f} ± {:.2f} N/mm²   Kte {:8.3f} ± {:.3f} N/mm\n"
      "  Krc {:9.2f} ± {:.2f} N/mm²   Kre {:8.3f} ± {:.3f} N/mm\n"
      "  Kac {:9.2f} ± {:.2f} N/mm²   Kae {:8.3f} ± {:.3f} N/mm\n",
      tests.size(), fit.rms_residual_n, fit.r_squared, k.Ktc_pa * 1e-6, se[0] * 1e-6,
      k.Kte_n_per_m * 1e-3, se[3] * 1e-3, k.Krc_pa * 1e-6, se[1] * 1e-6, k.Kre_n_per_m * 1e-3,
      se[4] * 1e-3, k.Kac_pa * 1e-6, se[2] * 1e-6, k.Kae_n_per_m * 1e-3, se[5] * 1e-3);
  return result;
}

}  // namespace robomill::commands
