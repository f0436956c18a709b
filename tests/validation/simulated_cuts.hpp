#pragma once
// The cases the time-domain checks share (test_simulate_vs_stability.cpp,
// test_listen_synthetic.cpp): the two-mode robot and `simulate`'s automatic
// step. The 1-DOF benchmark is tests/stability/benchmark_1dof.hpp.

#include <algorithm>
#include <cmath>
#include <numbers>

#include "robomill/simulation/simulator.hpp"
#include "robomill/stability/regenerative_model.hpp"

namespace robomill::test {

/// The depths each check simulates, as fractions of the predicted limit:
/// below it the cut must settle, above it chatter must grow.
inline constexpr double kLimitRatios[] = {0.8, 1.25};
/// The run length in tooth periods: long enough that growth at 1.25x and
/// decay at 0.8x are both visible (test_simulate_vs_stability.cpp).
inline constexpr double kSimulatedToothPeriods = 600.0;
/// simulate's default steady window: the last fifth of the run.
inline constexpr double kSteadyWindowShare = 0.2;

/// 003 Tab. 1's robot modes X1 and Y1 under a 20 mm two-flute end mill in
/// half immersion down milling (000 Eq 39 aluminium).
inline stability::RegenerativeModel robot_two_modes() {
  tool::ToolSpec spec;
  spec.diameter_m = 20e-3;
  spec.teeth = 2;
  spec.overhang_m = 60e-3;
  const cutting::LinearLaw law{855e6, 270.93e6, 0.0, 15.64e3, 14.167e3, 0.0};
  const cutting::MillingProcess process{1000.0, 0.1e-3, 1e-3, 10e-3,
                                        cutting::MillingDirection::down};
  const dynamics::ModalModel modes({dynamics::directional_mode(0, 17.8, 0.0176, 2.31e6),
                                    dynamics::directional_mode(1, 19.88, 0.0081, 3.65e6)});
  return stability::RegenerativeModel(tool::Tool(spec), law, process, modes);
}

/// `simulate`'s automatic step: 40 steps per tooth period, raised to 8 per
/// period of the highest mode and 12 across the engaged arc
/// (apps/robomill/command_simulate.cpp, check_settings).
inline int simulate_steps(const stability::RegenerativeModel& model,
                          const cutting::MillingProcess& process) {
  const double tooth_s = 2.0 * std::numbers::pi / (process.spindle_rad_s * model.tool().teeth());
  int steps = 40;
  steps = std::max(
      steps, static_cast<int>(std::ceil(8.0 * model.modes().highest_frequency_hz() * tooth_s)));
  steps = std::max(steps,
                   simulation::engaged_arc_resolution(model.tool(), process, {}).steps_per_tooth);
  return steps;
}

}  // namespace robomill::test
