#pragma once
// The chatter verdict of a recorded cut (issue 22, docs/monitoring.md): a
// signal (sound, acceleration, ...) in, whether the cut chattered, at which
// frequency, since when, and the spindle speeds that would put a
// tooth-passing harmonic on that frequency out.
//
// Method (docs/monitoring.md gives the reasoning and the thresholds' why):
//  1. one streaming pass: Welch's power spectral density (Hann, 50 %
//     overlap) and short-time spectra (the spectrogram, at most
//     `max_spectrogram_frames` columns: consecutive frames are averaged, so
//     memory stays flat in the recording's length);
//  2. the spindle frequency: a tachometer channel's when the recording has
//     one, else measured from the spectrum near the commanded one (the comb
//     whose harmonics, to 20 tooth harmonics, stand highest within
//     ±spindle_search_fraction), refined on its high harmonics;
//  3. every PSD bin attributed (LineCause): the spindle's and the tooth's
//     harmonics (forced), lines set aside (the job's `ignore`, mains 50/60 Hz
//     and harmonics, lines that stay put), the broadband floor, and what
//     remains: chatter evidence, from a robot's low modes (10-100 Hz) to a
//     tool's kHz modes, its sidebands around the tooth harmonics included;
//  4. the indicators and the verdict (docs/monitoring.md, "The verdict"):
//     the chatter line fraction — of the power off the spindle's harmonics
//     (lines set aside removed), the share that stands in lines above the
//     broadband floor — against `chatter_line_threshold`, chosen on the
//     labelled recordings with each held out in turn; and Schmitz's
//     once-per-period sampling variance (the share of the cut's power that
//     once-per-tooth samples do not repeat), which must reach
//     kMinOncePerPeriodVariance: a cut whose samples repeat is stable
//     whatever its lines. "unknown" with a reason when the signal cannot
//     decide;
//  5. the onset: the first short-time frame from which the chatter share
//     stays above the threshold.
//  With a measured comb, the short-time spectra also give the engaged
//  stretch (the tooth comb's power within 10 dB of its level in the cut):
//  when the recording holds air before or after it, stages 2-5 run again on
//  the PSD of that stretch alone.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "robomill/monitoring/signal_source.hpp"

namespace robomill::monitoring {

/// A line set aside by the user (`recording.ignore`): centre and half width.
struct IgnoredLine {
  double frequency_hz = 0.0;
  double half_width_hz = 0.0;  ///< 0: the spectrum's own resolution (2 bins)
};

struct ListenOptions {
  double commanded_spindle_hz = 0.0;     ///< process.spindle / 60 (required > 0)
  int teeth = 1;                         ///< tool.teeth (1 for a single insert)
  double spindle_search_fraction = 0.1;  ///< search the comb within ±10 % of the command
  /// The spindle speed counted on a tachometer channel (io/tachometer.hpp):
  /// taken as measured, the comb is not searched.
  std::optional<double> tachometer_spindle_hz;
  std::vector<IgnoredLine> ignore;
  bool detect_mains = true;         ///< set aside 50/60 Hz lines and their harmonics
  bool detect_steady_lines = true;  ///< set aside lines that stay put over the recording
  double band_low_hz = 0.0;         ///< analysed band (0: automatic, 3 resolution bins)
  double band_high_hz = 0.0;        ///< 0: 0.45 × the sample rate
  /// Chatter when the chatter evidence holds more than this share of the
  /// power off the spindle's harmonics (the chatter line fraction): a stable
  /// cut's non-synchronous power is broadband noise and scattered lines, a
  /// chattering one's stands in the chatter lines. The default lies midway
  /// between the labelled stable and chatter recordings' fractions; held out
  /// one recording at a time it judges them as docs/monitoring.md reports.
  double chatter_line_threshold = 0.79;
  /// Welch segment (0: automatic, ≥ 32 bins per spindle harmonic and ≥ 3
  /// segments). The short-time spectra are these segments (merged when there
  /// are more than max_spectrogram_frames), so the onset is resolved to one
  /// segment.
  double segment_s = 0.0;
  int max_spectrogram_frames = 400;
  /// With a measured comb, judge only the stretch where it stands (air
  /// before or after the cut set aside); false: the whole recording.
  bool judge_engaged_stretch = true;
  /// Called with the fraction of the signal read (0..1) when the length is known.
  std::function<void(double)> progress;
};

/// Schmitz's periodic-sampling guard: a cut whose once-per-tooth samples
/// repeat to within a tenth of its variance (10 dB: the tooth comb holds
/// 90 % of the cut's power) is stable whatever its lines say. Once per
/// tooth, not per revolution: period-doubling chatter repeats every
/// revolution. The stable synthetic cuts (20 dB SNR) sit near 0.01, every
/// labelled chatter recording at 0.45 or more (docs/monitoring.md).
inline constexpr double kMinOncePerPeriodVariance = 0.1;

enum class Verdict { stable, chatter, unknown };
const char* verdict_name(Verdict verdict) noexcept;  ///< "stable", "chatter", "unknown"

/// Why a PSD bin holds its power.
enum class LineCause { below_band, spindle, tooth, ignored, mains, steady_line, floor, chatter };
const char* line_cause_name(LineCause cause) noexcept;

/// A spectral line (a local maximum of the PSD above the floor).
struct SpectralLine {
  double frequency_hz = 0.0;
  double power = 0.0;  ///< integrated over the line (signal unit²)
  LineCause cause = LineCause::floor;
};

struct RecordingAnalysis {
  Verdict verdict = Verdict::unknown;
  std::string reason;  ///< why, in words (always set; the cause of "unknown")
  double duration_s = 0.0;
  double sample_rate_hz = 0.0;
  double spindle_hz_commanded = 0.0;
  double spindle_hz_measured = 0.0;  ///< refined; the commanded one when no comb was found
  bool spindle_refined = false;
  /// Where spindle_hz_measured comes from: "tachometer", "comb" (the
  /// spectrum's harmonics) or "commanded" (no comb stood out).
  std::string spindle_source = "commanded";
  double tooth_hz = 0.0;                 ///< measured spindle × teeth
  double chatter_hz = 0.0;               ///< strongest chatter line (0: none)
  double chatter_energy_fraction = 0.0;  ///< chatter evidence, of the band's total
  double forced_energy_fraction = 0.0;   ///< spindle + tooth harmonics
  double ignored_energy_fraction = 0.0;  ///< ignored + mains + steady lines, of the total
  double floor_energy_fraction = 0.0;    ///< broadband floor, of the total
  /// The verdict's indicator: chatter / (chatter + floor), the chatter
  /// evidence's share of the non-synchronous power (lines set aside removed).
  double chatter_line_fraction = 0.0;
  /// Schmitz's periodic-sampling indicator: the variance of samples taken
  /// once per revolution (once per tooth) at the measured speed over the
  /// cut's variance, lines set aside removed. Sampling once per period
  /// aliases every harmonic of that period to a constant, so the variance is
  /// the power off those harmonics (Parseval): (chatter + floor [+ the
  /// spindle-but-not-tooth harmonics]) / (chatter + forced + floor).
  double once_per_revolution_variance = 0.0;
  double once_per_tooth_variance = 0.0;
  /// How fast the strongest chatter-candidate line (chatter_hz) grows over
  /// the judged stretch: the least-squares slope of its short-time power
  /// (dB/s). Unset without such a line or with fewer than 3 frames.
  std::optional<double> chatter_growth_db_per_s;
  std::optional<double> onset_s;  ///< from the recording's start
  double clipped_fraction = 0.0;  ///< of the samples at full scale
  /// The engaged stretch judged, on the recording's time axis: where the
  /// tooth comb's power stands within 10 dB of its level in the cut. Unset
  /// when the whole recording was judged (no measured comb, or a comb from
  /// start to end).
  std::optional<double> engaged_start_s, engaged_end_s;

  /// Welch PSD (signal unit²/Hz), one-sided, and each bin's cause.
  std::vector<double> frequency_hz, psd;
  std::vector<LineCause> cause;
  double resolution_hz = 0.0;
  std::vector<SpectralLine> lines;  ///< strongest first

  /// Short-time spectra: power (signal unit²/Hz) of frame i at bin j is
  /// spectrogram_psd[i * spectrogram_frequency_hz.size() + j].
  std::vector<double> spectrogram_time_s, spectrogram_frequency_hz, spectrogram_psd;
  std::vector<double> frame_chatter_fraction;  ///< the chatter line fraction per frame
};

/// Reads `source` once and judges it. Throws std::invalid_argument for a
/// non-positive commanded spindle speed or tooth count; InputError from the
/// source. Never throws for a signal that cannot decide: verdict unknown.
RecordingAnalysis analyze_recording(SignalSource& source, const ListenOptions& options);

/// One spindle speed that puts the (k+1)-th tooth-passing harmonic on the
/// chatter frequency: n = 60 fc / (N (k + 1)) (Altintas' lobe-centre rule).
struct SpindleSuggestion {
  double spindle_hz = 0.0;
  int harmonic = 1;  ///< k + 1
};

/// Candidates within [min_hz, max_hz], ranked: the lowest harmonic (the widest
/// lobe) first. Empty when none fits.
std::vector<SpindleSuggestion> suggest_spindle_speeds(double chatter_hz, int teeth, double min_hz,
                                                      double max_hz);

}  // namespace robomill::monitoring
