#pragma once
// `robomill listen` of a job: the chatter verdict of recorded cuts (issue 22,
// docs/monitoring.md). Each recording is read in blocks by its reader
// (io/recording.hpp) and judged by the monitoring module's detector
// (monitoring/recording_analysis.hpp); the advice puts a tooth-passing
// harmonic on the chatter frequency (Altintas' lobe-centre rule), and when
// the job also describes the structure (a stability: section with dynamics or
// a robot), the recorded cuts are drawn on the predicted lobes
// (analysis/stability_diagram.hpp) and the model's chatter frequency at each
// cut is set beside the recorded one. SI units.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "robomill/analysis/stability_diagram.hpp"
#include "robomill/io/recording.hpp"
#include "robomill/io/tachometer.hpp"
#include "robomill/job/job.hpp"
#include "robomill/monitoring/recording_analysis.hpp"

namespace robomill::analysis {

/// The model's prediction at a recorded cut: the primary diagram's limit and
/// chatter frequency at the measured spindle speed, linear between the
/// diagram's speeds.
struct PredictedCut {
  double depth_limit_m = 0.0;
  double chatter_hz = 0.0;
};

/// One recording judged.
struct RecordingVerdict {
  io::RecordingSpec recording;    ///< as the job gives it (file, note, ...)
  monitoring::SignalInfo signal;  ///< what its reader found (kind, rate, description)
  int teeth = 1;                  ///< of the tooth-passing comb: listen.teeth, else tool.teeth
  /// recording.spindle, else process.spindle.
  double commanded_spindle_rad_s = 0.0;
  /// recording.depth, else process.ap when the job gives one recording:
  /// (not recordings:); nullopt when neither.
  std::optional<double> depth_m;
  monitoring::RecordingAnalysis analysis;  ///< the detector's verdict, spectra and energies
  /// The pulse channel's count when the recording names one (tachometer:).
  std::optional<io::TachometerReading> tachometer;
  /// The spindle speeds the advice may recommend: listen.spindle_range, else
  /// advise.speeds, else stability.speeds, else half to one and a half times
  /// the commanded speed.
  double advice_spindle_min_rad_s = 0.0;
  double advice_spindle_max_rad_s = 0.0;
  /// Within that range, the best first; empty unless the verdict is chatter
  /// at a known frequency.
  std::vector<monitoring::SpindleSuggestion> advice;
  /// At the measured spindle speed; nullopt without a diagram, outside its
  /// speeds or where its limit is not finite.
  std::optional<PredictedCut> prediction;
};

struct RecordingVerdicts {
  std::vector<RecordingVerdict> recordings;  ///< in the job's order
  /// Where the advice's spindle range comes from: "listen.spindle_range",
  /// "advise.speeds", "stability.speeds" or "0.5-1.5 x the commanded speed".
  std::string advice_range_basis;
  /// The job's lobes when it has stability:, tool:, cutting: and process:
  /// sections (the predictions are on diagram->primary()).
  std::optional<StabilityDiagram> diagram;
};

/// A signal judged as `listen` judges a recording: the detector with
/// `options` (its commanded speed, teeth and ignore list set; the job's
/// listen: settings or the defaults), and for a chatter verdict the spindle
/// speeds between advice_min_hz and advice_max_hz that put a tooth-passing
/// harmonic on the chatter frequency. Sets `verdict.signal`, `analysis` and
/// `advice`; the caller sets what it knows of the cut (teeth, commanded
/// speed, depth, the advice range). Used for each recording of a job and by
/// the Python module's analyze_signal on samples in memory.
void judge_signal(monitoring::SignalSource& source, const monitoring::ListenOptions& options,
                  double advice_min_hz, double advice_max_hz, RecordingVerdict& verdict);

/// Every recording of the job judged, the diagram on up to `threads` threads
/// (0: all cores). `progress` (optional) gets the fraction of each recording
/// read, staged "listen" (or "listen i/n" for several recordings). Throws
/// InputError naming `recording` for a job without recordings and
/// `listen.teeth` when neither listen.teeth nor a tool gives the tooth count;
/// what the readers and stability_diagram throw.
RecordingVerdicts recording_verdicts(
    const job::Job& job, int threads,
    const std::function<void(const std::string& stage, double fraction)>& progress = {});

}  // namespace robomill::analysis
