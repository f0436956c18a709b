#pragma once
// `robomill frf` of a job: the tool-tip FRFs of the job's modal table
// (001 Eq 19-22) on a frequency grid, optionally with measurement-like noise
// (dynamics/frf_noise.hpp). Users check a modal table against their
// measurement with them; the project makes its example measurements with them.
//
// Everything is in SI units; commands::compute_frf writes the FRFs as UFF58
// (what hammer-test software exchanges) or CSV, and summary.json.

#include <cstdint>
#include <string>
#include <vector>

#include "robomill/dynamics/frf.hpp"
#include "robomill/job/job.hpp"

namespace robomill::analysis {

/// The grid, the kind and the noise as typed on the command line: the
/// frequencies are parsed where the grid is made, since their defaults come
/// from the modal table; InputErrors name the options (--from, --to, --step,
/// --spacing, --points, --noise, --kind).
struct FrfSynthesisSettings {
  /// Frequencies as typed ("10 Hz", "6 kHz" or a bare number in Hz); empty:
  /// automatic.
  std::string from, to, step;
  std::string spacing = "linear";   ///< linear (from, to, step) or log (from, to, points)
  int points = 5000;                ///< frequencies of a log-spaced grid
  std::string kind = "receptance";  ///< receptance, mobility or accelerance
  double noise_relative = 0.0;      ///< relative complex noise (0.02 = 2 %), in [0, 1]
  std::uint32_t seed = 1;           ///< of the noise: seed + 3 response + reference per FRF
};

/// The job's FRFs on one grid.
struct FrfSynthesis {
  dynamics::FrfKind kind = dynamics::FrfKind::receptance;
  int modes = 0;  ///< modes of the job's table, all in every FRF
  /// The grid's first frequency: --from, or 0 Hz (linear) and half the first
  /// mode's natural frequency (log) by default.
  double from_hz = 0.0;
  /// The grid, ascending: linear from from_hz to 1.5 × the highest mode (or
  /// --to) with 10 points in the half-power band 2ζfn of the sharpest mode (or
  /// --step), so every peak is resolved; or log-spaced, which resolves every
  /// peak alike with far fewer points when the modes span decades.
  std::vector<double> frequencies_hz;
  /// A driving-point FRF for every direction some mode moves (x, y, z), then
  /// a cross FRF for every pair of directions some mode moves together (xy,
  /// xz, yz); each with its own noise seed, so adding one leaves the others'
  /// data unchanged. Labels are left to the writer.
  std::vector<dynamics::Frf> frfs;
};

/// The FRFs of the job's `dynamics.modes`. Throws InputError naming
/// `dynamics.modes` when the job has none, or the option whose value is
/// invalid (see FrfSynthesisSettings).
FrfSynthesis frf_synthesis(const job::Job& job, const FrfSynthesisSettings& settings);

}  // namespace robomill::analysis
