#pragma once
// DESIGN.md §5: the one-degree-of-freedom milling benchmark used by every
// semi-/full-discretization paper (Insperger & Stépán 2004; Ding et al. 2010):
// 2 teeth, Kt = 6e8 N/m², Kn = 2e8 N/m², fn = 922 Hz, ζ = 0.011,
// m = 0.03993 kg, down milling, vibration along the feed (x) only.
// Straight flutes; D = 10 mm so that a/D = ae / 10 mm.

#include <numbers>

#include "robomill/stability/regenerative_model.hpp"

namespace robomill::test {

inline stability::RegenerativeModel benchmark_1dof(double radial_immersion) {
  tool::ToolSpec spec;
  spec.diameter_m = 10e-3;
  spec.teeth = 2;
  spec.overhang_m = 50e-3;
  const cutting::LinearLaw law{6e8, 2e8, 0.0, 0.0, 0.0, 0.0};
  const cutting::MillingProcess process{1000.0, 0.1e-3, 1e-3, radial_immersion * 10e-3,
                                        cutting::MillingDirection::down};
  const double stiffness = 0.03993 * std::pow(2.0 * std::numbers::pi * 922.0, 2);
  const dynamics::ModalModel modes({dynamics::directional_mode(0, 922.0, 0.011, stiffness)});
  return stability::RegenerativeModel(tool::Tool(spec), law, process, modes);
}

inline double rpm(double value) {
  return value * 2.0 * std::numbers::pi / 60.0;
}

}  // namespace robomill::test
