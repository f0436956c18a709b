#include "robomill/analysis/frf_synthesis.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "robomill/core/error.hpp"
#include "robomill/dynamics/frf_noise.hpp"
#include "robomill/job/units.hpp"

namespace robomill::analysis {
namespace {

/// A frequency option: "10 Hz", "6 kHz" or a bare number in Hz.
double frequency_option(const std::string& option, const std::string& text) {
  job::Quantity q;
  try {
    q = job::parse_quantity(text);
  } catch (const std::invalid_argument& e) {
    throw InputError(option, 0, e.what());
  }
  if (!(q.dimension == job::dimensions::frequency || q.dimension == job::dimensions::none))
    throw InputError(option, 0, "'" + text + "' is not a frequency (Hz, kHz)");
  if (!std::isfinite(q.value_si) || q.value_si < 0.0)
    throw InputError(option, 0, "'" + text + "' must be a finite frequency ≥ 0");
  return q.value_si;
}

dynamics::FrfKind kind_option(const std::string& text) {
  if (text == "receptance")
    return dynamics::FrfKind::receptance;
  if (text == "mobility")
    return dynamics::FrfKind::mobility;
  if (text == "accelerance")
    return dynamics::FrfKind::accelerance;
  throw InputError("--kind", 0, "'" + text + "': expected receptance, mobility or accelerance");
}

struct FrequencyGrid {
  double from_hz = 0.0;              ///< FrfSynthesis::from_hz
  std::vector<double> frequency_hz;  ///< FrfSynthesis::frequencies_hz
};

FrequencyGrid frequency_grid(const dynamics::ModalModel& modes,
                             const FrfSynthesisSettings& settings) {
  // Default grid: linear from 0 to 1.5 × the highest mode, with 10 points in
  // the half-power band 2ζfn of the sharpest mode, so every peak is resolved;
  // or log-spaced, which resolves every peak alike with far fewer points when
  // the modes span decades (a robot's 20 Hz and its tool's 5 kHz).
  double sharpest_band_hz = INFINITY;
  for (const dynamics::Mode& mode : modes.modes())
    sharpest_band_hz =
        std::min(sharpest_band_hz, 2.0 * mode.damping_ratio * mode.natural_frequency_hz);
  const bool log_spacing = settings.spacing == "log";
  if (!log_spacing && settings.spacing != "linear")
    throw InputError("--spacing", 0, "'" + settings.spacing + "': expected linear or log");
  const double default_from_hz =
      log_spacing ? 0.5 * modes.modes().front().natural_frequency_hz : 0.0;
  const double from_hz =
      settings.from.empty() ? default_from_hz : frequency_option("--from", settings.from);
  const double to_hz = settings.to.empty() ? 1.5 * modes.highest_frequency_hz()
                                           : frequency_option("--to", settings.to);
  if (!(to_hz > from_hz))
    throw InputError("--to", 0, fmt::format("must exceed --from ({:g} Hz)", from_hz));
  std::vector<double> grid;
  if (log_spacing) {
    if (!(from_hz > 0.0))
      throw InputError("--from", 0, "a log-spaced grid needs --from > 0 Hz");
    if (settings.points < 2 || settings.points > 2000000)
      throw InputError("--points", 0, "must lie in 2 … 2 000 000");
    grid.resize(static_cast<std::size_t>(settings.points));
    for (std::size_t i = 0; i < grid.size(); ++i)
      grid[i] = from_hz * std::pow(to_hz / from_hz,
                                   static_cast<double>(i) / static_cast<double>(grid.size() - 1));
    grid.back() = to_hz;
  } else {
    const double step_hz =
        settings.step.empty() ? sharpest_band_hz / 10.0 : frequency_option("--step", settings.step);
    if (!(step_hz > 0.0))
      throw InputError("--step", 0, "must be positive");
    const double points = std::floor((to_hz - from_hz) / step_hz + 1e-9) + 1.0;
    if (points > 2e6)
      throw InputError("--step", 0,
                       fmt::format("gives {:.0f} frequencies; at most 2 000 000", points));
    grid.resize(static_cast<std::size_t>(points));
    for (std::size_t i = 0; i < grid.size(); ++i)
      grid[i] = from_hz + static_cast<double>(i) * step_hz;
  }
  return {from_hz, std::move(grid)};
}

}  // namespace

FrfSynthesis frf_synthesis(const job::Job& job, const FrfSynthesisSettings& settings) {
  job::require(job, {job::Section::modes});
  const dynamics::ModalModel modes = job::modal_model(job);

  FrfSynthesis result;
  result.modes = modes.size();
  FrequencyGrid grid = frequency_grid(modes, settings);
  result.from_hz = grid.from_hz;
  result.frequencies_hz = std::move(grid.frequency_hz);
  if (!(settings.noise_relative >= 0.0 && settings.noise_relative <= 1.0))
    throw InputError("--noise", 0, "relative noise must lie in [0, 1] (0.02 is 2 %)");
  result.kind = kind_option(settings.kind);

  // A driving-point FRF for every direction some mode moves, and a cross FRF
  // for every pair of directions some mode moves together.
  const Eigen::Matrix<double, 3, Eigen::Dynamic> shapes = modes.shape_matrix();
  std::vector<std::pair<int, int>> pairs;
  for (int r = 0; r < 3; ++r) {
    if (shapes.row(r).cwiseAbs().maxCoeff() > 0.0)
      pairs.emplace_back(r, r);
  }
  for (int r = 0; r < 3; ++r) {
    for (int s = r + 1; s < 3; ++s) {
      if (shapes.row(r).cwiseProduct(shapes.row(s)).cwiseAbs().maxCoeff() > 0.0)
        pairs.emplace_back(r, s);
    }
  }
  for (const auto& [response, reference] : pairs) {
    dynamics::Frf frf =
        dynamics::synthesize(modes, response, reference, result.frequencies_hz, result.kind);
    // Each FRF its own seed, so adding one leaves the others' data unchanged.
    if (settings.noise_relative > 0.0)
      dynamics::add_relative_noise(
          frf, settings.noise_relative,
          settings.seed + static_cast<std::uint32_t>(3 * response + reference));
    result.frfs.push_back(std::move(frf));
  }
  return result;
}

}  // namespace robomill::analysis
