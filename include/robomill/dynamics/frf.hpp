#pragma once
// Frequency response functions at the tool tip: measured (hammer tests, read
// from UFF58 or CSV files) or synthesized from a modal model (001 Eq 19-22).
// One Frf is one response direction over one reference (force) direction on a
// frequency grid, in SI units.

#include <complex>
#include <string>
#include <vector>

#include "robomill/dynamics/modal_model.hpp"

namespace robomill::dynamics {

/// What the response measures per newton of force.
enum class FrfKind {
  receptance,   ///< displacement / force, m/N
  mobility,     ///< velocity / force, m/(s·N)
  accelerance,  ///< acceleration / force, m/(s²·N)
};

/// One frequency response function, SI units.
struct Frf {
  std::vector<double> frequency_hz;         ///< strictly increasing, ≥ 0, finite
  std::vector<std::complex<double>> value;  ///< one per frequency, in the unit of `kind`
  FrfKind kind = FrfKind::receptance;
  int response_axis = 0;   ///< tool frame: 0 x, 1 y, 2 z
  int reference_axis = 0;  ///< direction of the applied force, same convention
  std::string label;       ///< free text (a file's function name, a point id)
};

/// Throws std::invalid_argument when the grid is empty, not strictly
/// increasing, negative or non-finite, the sizes differ, a value is not finite
/// or an axis is outside 0..2.
void validate(const Frf& frf);

/// The same FRF as another kind: each derivative multiplies by iω
/// (receptance → mobility → accelerance), each integral divides by iω. A 0 Hz
/// point cannot be integrated and is dropped from the result.
Frf convert(const Frf& frf, FrfKind to);

/// The FRF H_rs(ω) = Σ φ_r φ_s / (ωn² − ω² + 2iζωnω) of a modal model
/// (001 Eq 19-22 for one response and reference direction) on a grid, as any kind.
Frf synthesize(const ModalModel& modes, int response_axis, int reference_axis,
               const std::vector<double>& frequency_hz, FrfKind kind = FrfKind::receptance);

/// Linear interpolation of the real and imaginary parts at f; throws
/// std::invalid_argument outside [first, last] frequency of the grid.
std::complex<double> interpolate(const Frf& frf, double frequency_hz);

/// Name used in files and messages: "receptance", "mobility", "accelerance".
const char* kind_name(FrfKind kind) noexcept;

}  // namespace robomill::dynamics
