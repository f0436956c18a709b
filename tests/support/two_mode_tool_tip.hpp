#pragma once
// The job sections of a two-mode tool tip that the uncertainty tests and
// benchmark share (tests/analysis/test_stability_band.cpp,
// test_robust_advice.cpp, bench/bench_uncertainty.cpp): a 12 mm three-flute
// end mill (30° helix, 100 mm overhang) in quarter immersion (ae 3 mm) down
// milling, 0.08 mm per tooth, on modes at 703 Hz along x and 761 Hz along
// y. Kte and Kre are set: they add to the forces but not to the zero-order
// limit, which depends on Ktc and Krc only.

#include <string>

namespace robomill::test {

/// tool:, cutting:, process: and dynamics: as YAML lines.
inline std::string two_mode_tool_tip_yaml() {
  return "tool: {type: flat, diameter: 12 mm, teeth: 3, helix: 30 deg, overhang: 100 mm}\n"
         "cutting: {law: linear, Ktc: 712 N/mm^2, Krc: 213.6 N/mm^2, Kte: 21.3 N/mm, "
         "Kre: 14.7 N/mm}\n"
         "process: {spindle: 9000 rpm, feed_per_tooth: 0.08 mm, ap: 2 mm, ae: 3 mm, "
         "direction: down}\n"
         "dynamics:\n"
         "  modes:\n"
         "    - {direction: x, fn: 703 Hz, zeta: 3.1 %, k: 8.3e6 N/m}\n"
         "    - {direction: y, fn: 761 Hz, zeta: 3.6 %, k: 9.2e6 N/m}\n";
}

}  // namespace robomill::test
