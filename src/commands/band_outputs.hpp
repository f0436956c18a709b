#pragma once
// Private to the commands: the tables of a stability band (issue 33), as
// `stability` writes them and `learn` writes them for its prior and
// posterior (issue 35).

#include "robomill/analysis/stability_band.hpp"
#include "robomill/io/csv.hpp"

namespace robomill::commands {

/// lobes_quantiles.csv: per speed the 5 %, 50 % and 95 % quantile lobes and
/// the nominal limit (rpm, mm).
io::CsvTable band_quantiles_table(const analysis::StabilityBand& band);

/// chatter_probability.csv: speed-major, every depth of one speed, then the
/// next speed (as map.csv): P(chatter) and its standard error.
io::CsvTable band_probability_table(const analysis::StabilityBand& band);

}  // namespace robomill::commands
