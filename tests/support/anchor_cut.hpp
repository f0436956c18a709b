#pragma once
// The cut of the Bayesian stability anchor's numerical case (Cornelius,
// Karandikar & Schmitz 2024; examples/learn/anchor_tool.yaml): a 12.7 mm
// three-flute cutter with straight flutes, 50 % radial immersion down
// (climb) milling at 0.1 mm per tooth, the prior means of Ktc and Krc and
// an edge coefficient Kte. Shared by the learning tests and bench_learning.

#include <string>

namespace robomill::test {

/// The job's tool:, cutting: and process: lines.
inline std::string anchor_cut_yaml() {
  return "tool: {type: flat, diameter: 12.7 mm, teeth: 3, helix: 0 deg, overhang: 40 mm}\n"
         "cutting: {law: linear, Ktc: 556 N/mm^2, Krc: 225 N/mm^2, Kte: 50 N/mm}\n"
         "process: {spindle: 8000 rpm, feed_per_tooth: 0.1 mm, ap: 2 mm, ae: 6.35 mm, "
         "direction: down}\n";
}

/// The anchor's nominal symmetric mode (the prior means: 1500 Hz, ζ 0.03,
/// 10 N/µm in x and y) and a coarse 11-speed zero-order grid: the job's
/// dynamics: and stability: lines for tests whose evidence is no cut's limit.
inline std::string anchor_mode_and_coarse_grid_yaml() {
  return "dynamics:\n"
         "  modes:\n"
         "    - {direction: x, fn: 1500 Hz, zeta: 0.03, k: 1.0e7 N/m}\n"
         "    - {direction: y, fn: 1500 Hz, zeta: 0.03, k: 1.0e7 N/m}\n"
         "stability: {method: zoa, speeds: {from: 4000 rpm, to: 12000 rpm, count: 11}, "
         "depth_max: 8 mm, depths: 10}\n";
}

}  // namespace robomill::test
