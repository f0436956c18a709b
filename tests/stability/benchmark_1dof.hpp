#pragma once
// DESIGN.md §5: the one-degree-of-freedom milling benchmark used by every
// semi-/full-discretization paper (Insperger & Stépán 2004; Ding et al. 2010):
// 2 teeth, Kt = 6e8 N/m², Kn = 2e8 N/m², fn = 922 Hz, ζ = 0.011,
// m = 0.03993 kg, down milling, vibration along the feed (x) only.
// Straight flutes; D = 10 mm so that a/D = ae / 10 mm.

#include <cmath>
#include <numbers>
#include <vector>

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

/// The benchmark with `modes` modes: the 922 Hz mode along x, then modes at
/// 1.3x, 1.6x, 1.9x … its frequency alternating between y and x (same ζ, same
/// modal stiffness), so that the state grows by one modal coordinate per mode
/// (the multi-mode rows of bench_stability, docs/stability-speed.md).
inline stability::RegenerativeModel benchmark_modes(int modes, double radial_immersion) {
  const auto one = benchmark_1dof(radial_immersion);
  if (modes == 1)
    return one;
  std::vector<dynamics::Mode> list;
  const double stiffness = 0.03993 * std::pow(2.0 * std::numbers::pi * 922.0, 2);
  for (int i = 0; i < modes; ++i)
    list.push_back(dynamics::directional_mode(i % 2, 922.0 * (1.0 + 0.3 * i), 0.011, stiffness));
  return stability::RegenerativeModel(one.tool(), one.law(), one.process(),
                                      dynamics::ModalModel(list));
}

inline double rpm(double value) {
  return value * 2.0 * std::numbers::pi / 60.0;
}

}  // namespace robomill::test
