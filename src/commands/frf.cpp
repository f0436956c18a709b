// robomill frf JOB: the tool-tip FRFs of the job's modal table (001 Eq 19-22),
// optionally with measurement-like noise, written as UFF58 (what hammer-test
// software exchanges) or CSV. Users check a modal table against their
// measurement with it; the project makes its example measurements with it.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>

#include "robomill/commands/commands.hpp"
#include "robomill/core/error.hpp"
#include "robomill/dynamics/frf.hpp"
#include "robomill/dynamics/frf_noise.hpp"
#include "robomill/io/frf_csv.hpp"
#include "robomill/io/summary.hpp"
#include "robomill/io/uff58.hpp"
#include "robomill/job/units.hpp"

namespace robomill::commands {
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

}  // namespace

CommandResult compute_frf(const job::Job& job, const FrfSettings& options) {
  job::require(job, {job::Section::modes});
  const dynamics::ModalModel modes = job::modal_model(job);

  // Default grid: linear from 0 to 1.5 × the highest mode, with 10 points in
  // the half-power band 2ζfn of the sharpest mode, so every peak is resolved;
  // or log-spaced, which resolves every peak alike with far fewer points when
  // the modes span decades (a robot's 20 Hz and its tool's 5 kHz).
  double sharpest_band_hz = INFINITY;
  for (const dynamics::Mode& mode : modes.modes())
    sharpest_band_hz =
        std::min(sharpest_band_hz, 2.0 * mode.damping_ratio * mode.natural_frequency_hz);
  const bool log_spacing = options.spacing == "log";
  if (!log_spacing && options.spacing != "linear")
    throw InputError("--spacing", 0, "'" + options.spacing + "': expected linear or log");
  const double default_from_hz =
      log_spacing ? 0.5 * modes.modes().front().natural_frequency_hz : 0.0;
  const double from_hz =
      options.from.empty() ? default_from_hz : frequency_option("--from", options.from);
  const double to_hz = options.to.empty() ? 1.5 * modes.highest_frequency_hz()
                                          : frequency_option("--to", options.to);
  if (!(to_hz > from_hz))
    throw InputError("--to", 0, fmt::format("must exceed --from ({:g} Hz)", from_hz));
  std::vector<double> grid;
  if (log_spacing) {
    if (!(from_hz > 0.0))
      throw InputError("--from", 0, "a log-spaced grid needs --from > 0 Hz");
    if (options.points < 2 || options.points > 2000000)
      throw InputError("--points", 0, "must lie in 2 … 2 000 000");
    grid.resize(static_cast<std::size_t>(options.points));
    for (std::size_t i = 0; i < grid.size(); ++i)
      grid[i] = from_hz * std::pow(to_hz / from_hz,
                                   static_cast<double>(i) / static_cast<double>(grid.size() - 1));
    grid.back() = to_hz;
  } else {
    const double step_hz =
        options.step.empty() ? sharpest_band_hz / 10.0 : frequency_option("--step", options.step);
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
  if (!(options.noise >= 0.0 && options.noise <= 1.0))
    throw InputError("--noise", 0, "relative noise must lie in [0, 1] (0.02 is 2 %)");
  const dynamics::FrfKind kind = kind_option(options.kind);

  // A driving-point FRF for every direction some mode moves, and a cross FRF
  // for every pair of directions some mode moves together.
  std::vector<io::UffFrf> frfs;
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
    io::UffFrf entry;
    entry.frf = dynamics::synthesize(modes, response, reference, grid, kind);
    // Each FRF its own seed, so adding one leaves the others' data unchanged.
    if (options.noise > 0.0)
      dynamics::add_relative_noise(
          entry.frf, options.noise,
          options.seed + static_cast<std::uint32_t>(3 * response + reference));
    const std::string direction{"xyz"[response], "xyz"[reference]};
    entry.frf.label = fmt::format("H{} {} of {}", direction, dynamics::kind_name(kind),
                                  job.name.empty() ? job.source.filename().string() : job.name);
    entry.id_lines[0] = fmt::format("robomill frf: {} modes, noise {:g} %, seed {}", modes.size(),
                                    100.0 * options.noise, options.seed);
    frfs.push_back(std::move(entry));
  }

  CommandResult result;
  std::vector<std::string> files;
  if (options.format == "csv") {
    for (const io::UffFrf& entry : frfs) {
      const std::string name = fmt::format("frf_{}{}.csv", "xyz"[entry.frf.response_axis],
                                           "xyz"[entry.frf.reference_axis]);
      result.texts.emplace_back(name, io::format_frf_csv(entry.frf));
      files.push_back(name);
    }
  } else {
    const bool binary = options.format == "uff58b";
    if (!binary && options.format != "uff58")
      throw InputError("--format", 0,
                       "'" + options.format + "': expected uff58, uff58b (binary) or csv");
    result.texts.emplace_back("frf.uff", io::format_uff58(frfs, binary ? io::UffEncoding::binary
                                                                       : io::UffEncoding::ascii));
    files.push_back("frf.uff");
  }
  nlohmann::json summary = {{"command", "frf"},
                            {"job", job.source.string()},
                            {"kind", dynamics::kind_name(kind)},
                            {"from_hz", from_hz},
                            {"to_hz", grid.back()},
                            {"spacing", options.spacing},
                            {"points", grid.size()},
                            {"noise_relative", options.noise},
                            {"seed", options.seed},
                            {"frfs", frfs.size()},
                            {"files", files}};
  result.summary = std::move(summary);
  result.message =
      fmt::format("frf: {} FRF(s), {} points {:g}-{:g} Hz, noise {:g} %\n", frfs.size(),
                  grid.size(), from_hz, grid.back(), 100.0 * options.noise);
  return result;
}

}  // namespace robomill::commands
