#pragma once
// One measured FRF per CSV file, in one of two layouts (header row required):
//   freq_hz,re,im            real and imaginary parts
//   freq_hz,mag,phase_deg    magnitude and phase in degrees
// The file carries no unit: the caller says what it measures (the kind) and
// the factor from its unit to SI (1e-3 for mm/N). Blank lines and lines
// starting with '#' are skipped, as in io::read_csv.

#include <filesystem>
#include <string>

#include "robomill/dynamics/frf.hpp"

namespace robomill::io {

struct FrfCsvOptions {
  dynamics::FrfKind kind = dynamics::FrfKind::receptance;
  double scale_to_si = 1.0;  ///< multiplies re/im or mag; must be > 0
  int response_axis = 0;     ///< tool frame 0 x, 1 y, 2 z (the file does not say)
  int reference_axis = 0;
};

/// Throws InputError("<file>", line, why) for a wrong header, a bad number, a
/// frequency that is negative or not strictly increasing, or an empty table;
/// std::invalid_argument for invalid options.
dynamics::Frf read_frf_csv(const std::filesystem::path& file, const FrfCsvOptions& options = {});
dynamics::Frf parse_frf_csv(const std::string& text, const std::string& source_name,
                            const FrfCsvOptions& options = {});

/// `freq_hz,re,im` in SI, preceded by a '#' line naming the kind and unit;
/// shortest round-trip digits, so reading it back gives the same doubles.
std::string format_frf_csv(const dynamics::Frf& frf);
void write_frf_csv(const std::filesystem::path& file, const dynamics::Frf& frf);

}  // namespace robomill::io
