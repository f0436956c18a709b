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
//  * chatter: detect_chatter over the steady window (below).

#include <Eigen/Core>
#include <array>
#include <vector>

#include "robomill/simulation/simulator.hpp"

namespace robomill::simulation {

/// The chatter detector's thresholds (detect_chatter; docs/simulation.md,
/// "The chatter verdict", for the reasoning and the evidence behind them).
struct ChatterOptions {
  /// The physical floor: the non-harmonic RMS vibration must exceed this
  /// fraction of the feed per tooth fz. Chatter grows until the teeth leave
  /// the cut, i.e. to amplitudes comparable with the chip (≈ fz); a vibration
  /// of 1 % of fz changes the chip by about 1 % and is either a transient or
  /// numerical noise.
  double floor_feed_fraction = 0.01;
  /// The numerical floor: this fraction of the vibration's own scale,
  /// max(|x_s|, RMS vibration) (the issue-20 noise was 2e-8 of |x_s|). It is
  /// the floor when no feed is known and a guard when fz is tiny.
  double floor_numerical_fraction = 1e-6;
  /// Persistence: the non-harmonic RMS over the second half of the window
  /// must be at least this fraction of the first half's (a decaying transient
  /// is not chatter). Not judged for windows shorter than four forced periods.
  double min_persistence = 0.8;
};

/// Which floor the non-harmonic vibration was weighed against.
enum class ChatterFloor { feed_per_tooth, numerical };
const char* chatter_floor_name(ChatterFloor floor) noexcept;

struct ChatterVerdict {
  bool chatter = false;
  double frequency_hz = 0.0;          ///< largest non-harmonic peak (0: none)
  double nonharmonic_fraction = 0.0;  ///< of the displacement energy (evidence, not a gate)
  double sample_spread = 0.0;         ///< once-per-period samples' RMS / RMS vibration (evidence)
  double nonharmonic_rms_m = 0.0;     ///< RMS of the non-harmonic part (all directions)
  double forced_rms_m = 0.0;          ///< RMS of the forced (harmonic) part (all directions)
  double floor_m = 0.0;               ///< what nonharmonic_rms_m is weighed against
  ChatterFloor floor = ChatterFloor::feed_per_tooth;
  /// Non-harmonic RMS over the window's second half / first half (1 when the
  /// window is too short to judge).
  double persistence = 1.0;
};

/// The chatter verdict of a vibration (docs/simulation.md, "The chatter
/// verdict"). Inputs: `displacement_m`, the tool-tip displacement (tool
/// frame) sampled every `interval_s` over the steady part of a cut — its last
/// whole forced periods are judged (to within half a sample when the period
/// is not a whole number of samples); `forced_period_s`, the period the cut
/// forces the structure at (the tooth period, or the revolution with
/// runout); `feed_per_tooth_m`, fz (0: unknown, the numerical floor alone
/// applies); the thresholds. Per direction the window less a straight line
/// through its period means is Hann-transformed, and the spectrum above three
/// resolution bins is split into the harmonics of 1/forced_period_s (within
/// 2.5 bins) and the rest, the non-harmonic part. The cut chatters when the
/// non-harmonic RMS exceeds the floor, max(floor_feed_fraction · fz,
/// floor_numerical_fraction · max(|x_s|, RMS vibration)), and persists
/// (second half ≥ min_persistence × first half). Throws std::invalid_argument
/// for a non-positive interval or period, or fewer than 8 samples or one
/// forced period.
ChatterVerdict detect_chatter(const std::vector<Eigen::Vector3d>& displacement_m, double interval_s,
                              double forced_period_s, double feed_per_tooth_m,
                              const ChatterOptions& options = {});

struct ResponseOptions {
  double spindle_rad_s = 0.0;
  int teeth = 1;
  bool runout = false;           ///< forced period: one revolution instead of one tooth period
  double steady_window_s = 0.0;  ///< the last part of the run treated as steady
  double settling_band = 0.05;
  /// fz of the cut, for the chatter verdict's floor (0: the numerical floor alone).
  double feed_per_tooth_m = 0.0;
  ChatterOptions chatter;
};

struct DirectionResponse {
  double static_deviation_m = 0.0;
  double overshoot_pct = 0.0;
  double settling_time_s = 0.0;
  double first_frequency_hz = 0.0;  ///< 0 when the direction does not move
  double peak_to_peak_m = 0.0;      ///< over the steady window
  double rms_vibration_m = 0.0;     ///< about the static deviation, steady window
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
