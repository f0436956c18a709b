#include "robomill/analysis/stability_band.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <limits>
#include <optional>
#include <stdexcept>

#include "robomill/core/error.hpp"
#include "robomill/core/parallel.hpp"
#include "robomill/stability/lobes.hpp"
#include "robomill/stability/zero_order.hpp"
#include "robomill/tool/tool.hpp"

namespace robomill::analysis {
namespace {

using BandSettings = job::StabilitySettings;

/// A draw needs only the diagram the band is read from (primary()): the
/// same diagram by the same method, without what the nominal run adds
/// around it. A map's spectral radii are not propagated (mode: boundary);
/// `modes: both` keeps the coupled diagram, its primary; with 000's
/// deformation variants (time-domain methods on modes only) the primary is
/// the traditional one, which is the multipoint diagram without process
/// damping. The tests are compared once, on the nominal diagram.
void keep_only_primary(job::Job& draw_job) {
  BandSettings& s = *draw_job.stability;
  s.mode = BandSettings::Mode::boundary;
  if (s.modes == BandSettings::Modes::both)
    s.modes = BandSettings::Modes::coupled;
  const bool floquet_on_modes = s.method != BandSettings::Method::zoa &&
                                draw_job.dynamics_source != job::Job::DynamicsSource::frf;
  if (s.deformation && floquet_on_modes) {
    s.deformation = false;
    s.process_damping = BandSettings::Damping::none;
  }
  draw_job.experiments.clear();
}

/// The A0 basis every draw shares (issue 33 deliverable 5: what does not
/// change between draws is computed once), for the zero-order diagram on
/// modes when the draws keep the nominal cut; otherwise none, and each draw
/// averages W itself.
std::optional<stability::MeanCuttingStiffnessBasis> shared_cut_basis(const job::Job& job) {
  if (job.stability->method != BandSettings::Method::zoa ||
      job.dynamics_source == job::Job::DynamicsSource::frf || !draws_keep_the_cut(job))
    return std::nullopt;
  return stability::mean_cutting_stiffness_basis(tool::Tool(*job.tool), *job.cutting, *job.process);
}

/// The primary diagram of draw i.
std::vector<StabilityLimit> draw_primary(const job::Job& job, const JobDraws& draws, std::size_t i,
                                         const stability::MeanCuttingStiffnessBasis* cut_basis) {
  job::Job draw_job = job_of_draw(job, draws, i);
  keep_only_primary(draw_job);
  return stability_diagram(draw_job, 1, cut_basis).primary();
}

/// Every draw's primary diagram, on up to `threads` threads (for_each_draw
/// names a failing draw).
std::vector<std::vector<StabilityLimit>> all_draw_limits(const job::Job& job, const JobDraws& draws,
                                                         int threads) {
  const std::optional<stability::MeanCuttingStiffnessBasis> cut_basis = shared_cut_basis(job);
  std::vector<std::vector<StabilityLimit>> rows(static_cast<std::size_t>(draws.values.rows()));
  for_each_draw(draws, threads, [&](std::size_t i) {
    rows[i] = draw_primary(job, draws, i, cut_basis ? &*cut_basis : nullptr);
  });
  return rows;
}

/// The quantiles and the probability column of speed s (writes only that
/// speed's entries).
void band_summarize_speed(StabilityBand& band, std::size_t s) {
  const auto column = static_cast<Eigen::Index>(s);
  const auto n = static_cast<std::size_t>(band.draw_count);
  std::vector<double> limits(n), for_fraction(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto row = static_cast<Eigen::Index>(i);
    limits[i] = band.limits_m(row, column);
    // Not limited up to depth_max: stable at every depth of the map.
    for_fraction[i] =
        band.limited(row, column) ? limits[i] : std::numeric_limits<double>::infinity();
  }
  constexpr std::array<double, 3> probabilities = {kBandLowerProbability, kBandMedianProbability,
                                                   kBandUpperProbability};
  const std::vector<uncertainty::Estimate> q =
      uncertainty::empirical_quantiles(limits, probabilities);
  band.q05_m[s] = q[0];
  band.q50_m[s] = q[1];
  band.q95_m[s] = q[2];
  for (std::size_t d = 0; d < band.depths_m.size(); ++d) {
    const uncertainty::Estimate p = uncertainty::fraction_below(for_fraction, band.depths_m[d]);
    band.p_chatter(static_cast<Eigen::Index>(d), column) = p.value;
    band.p_chatter_se(static_cast<Eigen::Index>(d), column) = p.standard_error;
  }
}

/// The lowest 5 % and the highest 95 % quantile over the speeds.
void band_find_extremes(StabilityBand& band) {
  band.q05_min_m = std::numeric_limits<double>::infinity();
  band.q95_max_m = -std::numeric_limits<double>::infinity();
  for (std::size_t s = 0; s < band.speeds_rad_s.size(); ++s) {
    if (band.q05_m[s].value < band.q05_min_m) {
      band.q05_min_m = band.q05_m[s].value;
      band.q05_min_spindle_rad_s = band.speeds_rad_s[s];
    }
    if (band.q95_m[s].value > band.q95_max_m) {
      band.q95_max_m = band.q95_m[s].value;
      band.q95_max_spindle_rad_s = band.speeds_rad_s[s];
    }
  }
}

}  // namespace

std::vector<RobustPocket> robust_pockets(const std::vector<double>& speeds_rad_s,
                                         const std::vector<uncertainty::Estimate>& lobe_m,
                                         int max_count) {
  if (speeds_rad_s.size() != lobe_m.size())
    throw std::invalid_argument("robust_pockets: speeds and lobe differ in size");
  std::vector<RobustPocket> pockets;
  const std::size_t n = lobe_m.size();
  // Runs of equal values (a flat top, e.g. draws stable to depth_max): a run
  // above both neighbours (a range end counts as below) is one maximum.
  for (std::size_t begin = 0; begin < n;) {
    const double value = lobe_m[begin].value;
    std::size_t end = begin + 1;
    while (end < n && lobe_m[end].value == value)
      ++end;
    const bool above_left = begin == 0 || lobe_m[begin - 1].value < value;
    const bool above_right = end == n || lobe_m[end].value < value;
    if (above_left && above_right) {
      const std::size_t middle = begin + (end - 1 - begin) / 2;
      pockets.push_back({speeds_rad_s[middle], value, lobe_m[middle].standard_error});
    }
    begin = end;
  }
  // Deepest first; stable, so equal depths keep the lower speed first.
  std::stable_sort(pockets.begin(), pockets.end(),
                   [](const RobustPocket& a, const RobustPocket& b) {
                     return a.depth_limit_q05_m > b.depth_limit_q05_m;
                   });
  if (pockets.size() > static_cast<std::size_t>(std::max(max_count, 0)))
    pockets.resize(static_cast<std::size_t>(std::max(max_count, 0)));
  return pockets;
}

void summarize_band(StabilityBand& band, const job::StabilitySettings& settings, int threads) {
  const std::size_t speeds = band.speeds_rad_s.size();
  if (band.limits_m.cols() != static_cast<Eigen::Index>(speeds) ||
      band.limited.cols() != band.limits_m.cols() || band.limited.rows() != band.limits_m.rows() ||
      band.limits_m.rows() < 1)
    throw std::invalid_argument("summarize_band: limits and speeds differ in size");
  band.draw_count = static_cast<int>(band.limits_m.rows());
  // The map's depths, as stability_diagram's spectral-radius map has them.
  band.depths_m = stability::linear_range(settings.depth_max_m / settings.depth_count,
                                          settings.depth_max_m, settings.depth_count);
  const auto depth_count = static_cast<Eigen::Index>(band.depths_m.size());
  band.p_chatter.resize(depth_count, static_cast<Eigen::Index>(speeds));
  band.p_chatter_se.resize(depth_count, static_cast<Eigen::Index>(speeds));
  band.q05_m.resize(speeds);
  band.q50_m.resize(speeds);
  band.q95_m.resize(speeds);
  core::parallel_for(speeds, threads, [&band](std::size_t s) { band_summarize_speed(band, s); });
  band_find_extremes(band);
  band.robust_pockets = robust_pockets(band.speeds_rad_s, band.q05_m);
}

StabilityBand stability_band(const job::Job& job, const StabilityDiagram& nominal, int threads) {
  if (!job.uncertainty)
    throw InputError("uncertainty", 0, "the band needs an uncertainty: section");
  const std::vector<StabilityLimit>& primary = nominal.primary();
  if (primary.empty()) {
    throw InputError("stability", 0,
                     "the nominal diagram has no limits to propagate the uncertainty through");
  }
  const auto start = std::chrono::steady_clock::now();
  StabilityBand band;
  band.draws = draw_job_inputs(job);
  band.draw_count = static_cast<int>(band.draws.values.rows());
  if (band.draw_count < 1)
    throw InputError("uncertainty.samples", 0, "no draws to compute the band from");
  for (const StabilityLimit& l : primary) {
    band.speeds_rad_s.push_back(l.spindle_rad_s);
    band.nominal_limit_m.push_back(l.depth_limit_m);
  }
  const std::size_t speeds = primary.size();
  const auto speed_count = static_cast<Eigen::Index>(speeds);

  const std::vector<std::vector<StabilityLimit>> rows = all_draw_limits(job, band.draws, threads);
  band.limits_m.resize(band.draw_count, speed_count);
  band.limited.resize(band.draw_count, speed_count);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].size() != speeds) {
      throw InputError("uncertainty", 0,
                       fmt::format("draw {} gives {} spindle speeds, the nominal diagram {}: a "
                                   "variable must not change stability.speeds",
                                   i + 1, rows[i].size(), speeds));
    }
    for (std::size_t s = 0; s < speeds; ++s) {
      const auto row = static_cast<Eigen::Index>(i);
      const auto column = static_cast<Eigen::Index>(s);
      band.limits_m(row, column) = rows[i][s].depth_limit_m;
      band.limited(row, column) = rows[i][s].limited;
    }
  }

  summarize_band(band, *job.stability, threads);
  band.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return band;
}

}  // namespace robomill::analysis
