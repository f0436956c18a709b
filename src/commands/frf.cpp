// robomill frf JOB: the tool-tip FRFs of the job's modal table (001 Eq 19-22),
// optionally with measurement-like noise, written as UFF58 (what hammer-test
// software exchanges) or CSV. Users check a modal table against their
// measurement with it; the project makes its example measurements with it.
// The grid and the FRFs are analysis::frf_synthesis's; this file writes them.

#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "robomill/analysis/frf_synthesis.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/frf_csv.hpp"
#include "robomill/io/summary.hpp"
#include "robomill/io/uff58.hpp"

namespace robomill::commands {

CommandResult compute_frf(const job::Job& job, const FrfSettings& options) {
  analysis::FrfSynthesis synthesis = analysis::frf_synthesis(job, options);
  const dynamics::FrfKind kind = synthesis.kind;
  const std::vector<double>& grid = synthesis.frequencies_hz;
  const double from_hz = synthesis.from_hz;

  std::vector<io::UffFrf> frfs;
  for (dynamics::Frf& frf : synthesis.frfs) {
    io::UffFrf entry;
    entry.frf = std::move(frf);
    const std::string direction{"xyz"[entry.frf.response_axis], "xyz"[entry.frf.reference_axis]};
    entry.frf.label = fmt::format("H{} {} of {}", direction, dynamics::kind_name(kind),
                                  job.name.empty() ? job.source.filename().string() : job.name);
    entry.id_lines[0] = fmt::format("robomill frf: {} modes, noise {:g} %, seed {}",
                                    synthesis.modes, 100.0 * options.noise_relative, options.seed);
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
                            {"noise_relative", options.noise_relative},
                            {"seed", options.seed},
                            {"frfs", frfs.size()},
                            {"files", files}};
  result.summary = std::move(summary);
  result.message =
      fmt::format("frf: {} FRF(s), {} points {:g}-{:g} Hz, noise {:g} %\n", frfs.size(),
                  grid.size(), from_hz, grid.back(), 100.0 * options.noise_relative);
  return result;
}

}  // namespace robomill::commands
