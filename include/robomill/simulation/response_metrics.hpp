#pragma once
// What a simulated response means (002 Tables 1-2, the chatter verdict):
// static deviation, overshoot, settling time, the first (dominant low)
// frequency of the tool's displacement per direction, the vibration, and
// whether the cut chatters.
//
// Definitions (docs/simulation.md):
//  * steady window: the last `steady_window_s` of the run;
//  * static deviation x_s: the mean displacement over the steady window;
//  * overshoot PO and settling time τs (5 % band) from the displacement
//    averaged over each tooth period (the tooth-passing ripple removed):
//    PO = (max of the averaged displacement along the sign of x_s − |x_s|) /
//    |x_s|, τs = end of the last tooth period whose average lies outside
//    x_s ± 5 % |x_s|, counted from the first contact (002's t = 0);
//  * first frequency f1: the largest peak of the displacement spectrum below
//    half the spindle frequency, over the part of the run after the cutter is
//    fully engaged (the centre has passed the border);
//  * chatter: in the steady window, the fraction of the displacement's
//    spectral energy (above half the forced frequency) lying away from the
//    harmonics of the forced period — the tooth period for a cutter without
//    runout, the revolution with runout — and the spread of the displacement
//    sampled once per forced period relative to its RMS vibration; the cut
//    chatters when both exceed their thresholds.

#include <Eigen/Core>
#include <array>

#include "robomill/simulation/simulator.hpp"

namespace robomill::simulation {

struct ResponseOptions {
  double spindle_rad_s = 0.0;
  int teeth = 1;
  bool runout = false;           ///< forced period: one revolution instead of one tooth period
  double steady_window_s = 0.0;  ///< the last part of the run treated as steady
  double settling_band = 0.05;
  double chatter_energy_fraction = 0.1;  ///< threshold of the non-harmonic energy fraction
  double chatter_sample_spread = 0.1;    ///< threshold of the once-per-period spread
};

struct DirectionResponse {
  double static_deviation_m = 0.0;
  double overshoot_pct = 0.0;
  double settling_time_s = 0.0;
  double first_frequency_hz = 0.0;  ///< 0 when the direction does not move
  double peak_to_peak_m = 0.0;      ///< over the steady window
  double rms_vibration_m = 0.0;     ///< about the static deviation, steady window
};

struct ChatterVerdict {
  bool chatter = false;
  double frequency_hz = 0.0;          ///< largest non-harmonic peak (0: none)
  double nonharmonic_fraction = 0.0;  ///< of the displacement energy
  double sample_spread = 0.0;         ///< once-per-period samples' RMS / RMS vibration
};

struct ResponseMetrics {
  std::array<DirectionResponse, 3> direction;
  ChatterVerdict chatter;
  Eigen::Vector3d mean_force_n = Eigen::Vector3d::Zero();  ///< steady window
  Eigen::Vector3d peak_force_n = Eigen::Vector3d::Zero();  ///< largest |F| component, signed
  double steady_from_s = 0.0;
  double analysis_from_s = 0.0;  ///< start of the f1 window
};

/// Throws std::invalid_argument when the steady window is not positive or
/// does not fit the run.
ResponseMetrics analyze_response(const SimulationResult& result, const ResponseOptions& options);

}  // namespace robomill::simulation
