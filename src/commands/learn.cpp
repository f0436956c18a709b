// robomill learn JOB: the job's uncertain inputs updated from its test cuts,
// and the next test to run (issue 35, docs/learning.md). The numbers are
// analysis::learn's; this file writes them as posterior.csv, summary.json,
// lobes_quantiles.csv and chatter_probability.csv (the posterior's, as
// `stability` writes a band), lobes_quantiles_prior.csv and experiments.csv.

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <numbers>

#include "band_outputs.hpp"
#include "robomill/analysis/learning.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/io/csv.hpp"

namespace robomill::commands {
namespace {

nlohmann::json summary_json(const analysis::VariableSummary& s) {
  return {{"mean", s.mean}, {"sd", s.sd}, {"q05", s.q05}, {"q50", s.q50}, {"q95", s.q95}};
}

/// A number, or null where there is none (never NaN in summary.json).
nlohmann::json number_or_null(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

/// Joint angles in degrees.
std::vector<double> degrees(const std::vector<double>& radians) {
  std::vector<double> out;
  for (const double r : radians)
    out.push_back(std::round(r * 180.0 / std::numbers::pi * 1e9) / 1e9);  // 1e-9°: no 22.549999…
  return out;
}

nlohmann::json next_test_json(const analysis::NextTest& t, const analysis::LearningResult& r) {
  if (!t.found)
    return {{"found", false}, {"strategy", t.strategy}, {"reason", t.reason}};
  nlohmann::json next = {{"found", true},
                         {"strategy", t.strategy},
                         {"reason", t.reason},
                         {"spindle_rpm", t.spindle_rad_s * kRpmPerRadS},
                         {"ap_mm", t.depth_m * 1e3},
                         {"p_chatter", t.p_chatter},
                         {"information_bits", t.information_bits},
                         {"mrr_cm3_min", t.removal_rate_m3_s * 1e6 * 60.0}};
  if (!r.places_rad.empty() && !r.places_rad.front().empty()) {
    next["place"] = t.place;
    next["posture_deg"] = degrees(r.places_rad[static_cast<std::size_t>(t.place)]);
  }
  return next;
}

/// A robot's places: per place and speed the prior's and the posterior's
/// quantile lobes (places.csv).
io::CsvTable places_table(const analysis::LearningResult& r) {
  io::CsvTable table({"place", "spindle_rpm", "prior_q05_mm", "prior_q50_mm", "prior_q95_mm",
                      "posterior_q05_mm", "posterior_q50_mm", "posterior_q95_mm", "nominal_mm"});
  const auto add = [&](int place, const analysis::StabilityBand& prior,
                       const analysis::StabilityBand& posterior) {
    for (std::size_t s = 0; s < prior.speeds_rad_s.size(); ++s)
      table.add_row({static_cast<double>(place), prior.speeds_rad_s[s] * kRpmPerRadS,
                     prior.q05_m[s].value * 1e3, prior.q50_m[s].value * 1e3,
                     prior.q95_m[s].value * 1e3, posterior.q05_m[s].value * 1e3,
                     posterior.q50_m[s].value * 1e3, posterior.q95_m[s].value * 1e3,
                     prior.nominal_limit_m[s] * 1e3});
  };
  add(0, r.prior_band, r.posterior_band);
  for (std::size_t p = 0; p < r.more_places.size(); ++p)
    add(static_cast<int>(p) + 1, r.more_places[p].prior, r.more_places[p].posterior);
  return table;
}

io::CsvTable posterior_table(const analysis::LearningResult& r) {
  io::CsvTable table(r.names);
  for (Eigen::Index i = 0; i < r.posterior_values.rows(); ++i) {
    std::vector<double> row;
    for (Eigen::Index j = 0; j < r.posterior_values.cols(); ++j)
      row.push_back(r.posterior_values(i, j));
    table.add_row(row);
  }
  return table;
}

io::CsvTable experiments_table(const analysis::LearningResult& r) {
  io::CsvTable table({"experiment", "line", "spindle_rpm", "depth_mm", "chatter", "chatter_freq_hz",
                      "predicted_chatter_freq_hz", "p_chatter_prior", "p_chatter_posterior",
                      "from_recording", "place", "power_w", "predicted_power_w"});
  for (const analysis::LearnedExperiment& e : r.experiments) {
    table.add_row({static_cast<double>(e.index), static_cast<double>(e.line),
                   e.spindle_rad_s * kRpmPerRadS, e.depth_m * 1e3, e.chatter ? 1.0 : 0.0,
                   e.chatter_frequency_hz, e.predicted_chatter_frequency_hz, e.p_chatter_prior,
                   e.p_chatter_posterior, e.from_recording ? 1.0 : 0.0,
                   static_cast<double>(e.place), e.power_w, e.predicted_power_w});
  }
  return table;
}

io::CsvTable hammer_table(const analysis::LearningResult& r) {
  io::CsvTable table({"experiment", "line", "place", "axis", "fn_hz", "zeta", "k_n_per_m",
                      "prior_fn_hz", "prior_k_n_per_m", "posterior_fn_hz", "posterior_k_n_per_m"});
  for (const analysis::LearnedHammerMode& m : r.hammer_modes)
    table.add_row({static_cast<double>(m.index), static_cast<double>(m.line),
                   static_cast<double>(m.place), static_cast<double>(m.axis), m.fn_hz, m.zeta,
                   m.k_n_per_m, m.prior_fn_hz, m.prior_k_n_per_m, m.posterior_fn_hz,
                   m.posterior_k_n_per_m});
  return table;
}

/// Every place's posterior P(chatter) map (chatter_probability.csv's
/// columns after a place column): a robot's lobes change with the posture.
io::CsvTable places_probability_table(const analysis::LearningResult& r) {
  std::vector<const analysis::StabilityBand*> bands = {&r.posterior_band};
  for (const analysis::PlaceBands& p : r.more_places)
    bands.push_back(&p.posterior);
  std::vector<std::string> columns = {"place"};
  const io::CsvTable first = band_probability_table(*bands.front());
  columns.insert(columns.end(), first.columns().begin(), first.columns().end());
  io::CsvTable table(columns);
  for (std::size_t p = 0; p < bands.size(); ++p) {
    const io::CsvTable one = band_probability_table(*bands[p]);
    for (std::size_t row = 0; row < one.rows(); ++row) {
      std::vector<double> values = {static_cast<double>(p)};
      for (std::size_t c = 0; c < one.columns().size(); ++c)
        values.push_back(one.at(row, c));
      table.add_row(values);
    }
  }
  return table;
}

nlohmann::json diagnostics_json(const learning::SmcPosterior& s) {
  nlohmann::json temperatures = nlohmann::json::array();
  for (const learning::SmcStage& stage : s.stages)
    temperatures.push_back(stage.temperature);
  return {{"sampler", "tempered sequential Monte Carlo, random-walk Metropolis moves"},
          {"samples", s.particles.rows()},
          {"stages", s.stages.size()},
          {"temperatures", temperatures},
          {"min_ess_fraction", s.min_ess_fraction},
          {"acceptance", s.acceptance},
          {"log_evidence", s.log_evidence},
          {"likelihood_evaluations", s.likelihood_evaluations}};
}

}  // namespace

CommandResult compute_learn(const job::Job& job, int threads) {
  const analysis::LearningResult r = analysis::learn(job, threads);
  CommandResult result;
  nlohmann::json variables = nlohmann::json::object();
  for (std::size_t j = 0; j < r.names.size(); ++j) {
    nlohmann::json correlations = nlohmann::json::object();
    for (std::size_t k = 0; k < r.names.size(); ++k) {
      if (k != j)
        correlations[r.names[k]] =
            r.posterior_correlation(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(k));
    }
    variables[r.names[j]] = {{"unit", r.units[j]},
                             {"prior", summary_json(r.prior[j])},
                             {"posterior", summary_json(r.posterior[j])},
                             {"posterior_correlation", correlations}};
  }
  nlohmann::json used = nlohmann::json::array();
  for (const analysis::LearnedExperiment& e : r.experiments) {
    used.push_back(
        {{"experiment", e.index},
         {"line", e.line},
         {"spindle_rpm", e.spindle_rad_s * kRpmPerRadS},
         {"depth_mm", e.depth_m * 1e3},
         {"chatter", e.chatter},
         {"chatter_freq_hz",
          number_or_null(e.chatter_frequency_hz > 0.0 ? e.chatter_frequency_hz : NAN)},
         {"predicted_chatter_freq_hz",
          number_or_null(e.predicted_chatter_frequency_hz > 0.0 ? e.predicted_chatter_frequency_hz
                                                                : NAN)},
         {"p_chatter_prior", e.p_chatter_prior},
         {"p_chatter_posterior", e.p_chatter_posterior},
         {"source", e.from_recording ? "recording" : "written"},
         {"place", e.place}});
  }
  nlohmann::json hammer = nlohmann::json::array();
  for (const analysis::LearnedHammerMode& m : r.hammer_modes)
    hammer.push_back(
        {{"experiment", m.index},
         {"line", m.line},
         {"place", m.place},
         {"axis", std::string(1, static_cast<char>('x' + m.axis))},
         {"fn_hz", m.fn_hz},
         {"zeta", m.zeta},
         {"k_n_per_m", m.k_n_per_m},
         {"predicted_prior", {{"fn_hz", m.prior_fn_hz}, {"k_n_per_m", m.prior_k_n_per_m}}},
         {"predicted_posterior",
          {{"fn_hz", m.posterior_fn_hz}, {"k_n_per_m", m.posterior_k_n_per_m}}}});
  nlohmann::json skipped = nlohmann::json::array();
  for (const analysis::SkippedExperiment& e : r.skipped)
    skipped.push_back({{"experiment", e.index}, {"line", e.line}, {"reason", e.reason}});
  result.summary = {
      {"command", "learn"},
      {"job", job.source.string()},
      {"variables", variables},
      {"next_test", next_test_json(r.next, r)},
      {"experiments_used", used},
      {"experiments_skipped", skipped},
      {"hammer_modes", hammer},
      {"warnings", r.warnings},
      {"boundary_spread_mm",
       {{"prior", r.prior_spread_m * 1e3},
        {"posterior", r.posterior_spread_m * 1e3},
        {"posterior_without_last_test", number_or_null(r.spread_before_last_m * 1e3)}}},
      {"diagnostics", diagnostics_json(r.sampler)},
      {"elapsed_s", r.elapsed_s}};
  result.tables.emplace_back("posterior", posterior_table(r));
  result.tables.emplace_back("lobes_quantiles", band_quantiles_table(r.posterior_band));
  result.tables.emplace_back("chatter_probability", band_probability_table(r.posterior_band));
  result.tables.emplace_back("lobes_quantiles_prior", band_quantiles_table(r.prior_band));
  result.tables.emplace_back("experiments", experiments_table(r));
  if (!r.hammer_modes.empty())
    result.tables.emplace_back("hammer_modes", hammer_table(r));
  if (!r.places_rad.empty() && !r.places_rad.front().empty()) {
    nlohmann::json places = nlohmann::json::array();
    for (std::size_t p = 0; p < r.places_rad.size(); ++p)
      places.push_back({{"place", p}, {"posture_deg", degrees(r.places_rad[p])}});
    result.summary["places"] = places;
    result.tables.emplace_back("places", places_table(r));
    result.tables.emplace_back("chatter_probability_places", places_probability_table(r));
  }

  for (const std::string& w : r.warnings)
    result.message += "  warning: " + w + "\n";
  for (const analysis::SkippedExperiment& e : r.skipped)
    result.message +=
        fmt::format("  note: experiments[{}] (line {}) skipped: {}\n", e.index, e.line, e.reason);
  result.message += fmt::format(
      "  {} cuts, {} hammer-test modes, {} samples ({} stages, acceptance {:.2f}, log evidence "
      "{:.3f}) in "
      "{:.2f} s; boundary spread {:.3f} → {:.3f} mm\n",
      r.experiments.size(), r.hammer_modes.size(), r.posterior_values.rows(),
      r.sampler.stages.size(), r.sampler.acceptance, r.sampler.log_evidence, r.elapsed_s,
      r.prior_spread_m * 1e3, r.posterior_spread_m * 1e3);
  if (r.next.found) {
    std::string where;
    if (!r.places_rad.empty() && !r.places_rad.front().empty()) {
      const std::vector<double> posture =
          degrees(r.places_rad[static_cast<std::size_t>(r.next.place)]);
      where = fmt::format(" at posture [{:.6g}] deg (place {})", fmt::join(posture, ", "),
                          r.next.place);
    }
    result.message += fmt::format(
        "next test: {:.0f} rpm, ap {:.3f} mm{} (P(chatter) {:.2f}, {:.3f} bits, {:.2f} "
        "cm³/min; {})\n",
        r.next.spindle_rad_s * kRpmPerRadS, r.next.depth_m * 1e3, where, r.next.p_chatter,
        r.next.information_bits, r.next.removal_rate_m3_s * 1e6 * 60.0, r.next.strategy);
  } else
    result.message += "next test: none (" + r.next.reason + ")\n";
  return result;
}

}  // namespace robomill::commands
