#pragma once
// Stages 2 and 3 of the recording analysis (recording_analysis.hpp's method;
// recording_analysis.cpp runs them in order after the streaming pass): which
// PSD bins are lines, the spindle frequency measured from the comb of its
// harmonics, and every bin's cause. Private to src/monitoring.

#include <algorithm>
#include <cstddef>
#include <vector>

#include "robomill/monitoring/recording_analysis.hpp"

namespace robomill::monitoring::detail {

class WelchStream;

/// Hann main lobe: a line at a harmonic fills ±2 bins; 2.5 allows for the
/// harmonic lying between bins (as simulation::detect_chatter).
inline constexpr double kMainLobeBins = 2.5;

/// The Welch spectrum's grid and analysed band, shared by every stage after
/// the streaming pass (stage 1 sets it; the PSD itself is the result's).
struct Spectrum {
  double fs = 0.0;                          ///< sample rate (Hz)
  std::size_t length = 0;                   ///< Welch segment (samples)
  std::size_t bins = 0;                     ///< length / 2 + 1
  double df = 0.0;                          ///< resolution (Hz)
  double segments = 0.0;                    ///< Welch segments averaged
  double scale = 0.0;                       ///< 1 / (fs Σ w²): a periodogram sum to unit²/Hz
  double band_high = 0.0;                   ///< the analysed band's top (Hz)
  std::size_t first_bin = 0, last_bin = 0;  ///< the analysed band
};

/// The floor under the lines and the bins that are lines (stage 3's start);
/// mains_bin marks the line bins of mains lines.
struct LineBins {
  std::vector<double> floor;    ///< running median of the PSD
  std::vector<double> noise;    ///< mean noise: the floor over the median-to-mean ratio
  std::vector<char> in_line;    ///< the bin belongs to a line
  std::vector<char> mains_bin;  ///< the bin belongs to a mains line
  std::vector<char> doubled;    ///< a spindle-harmonic bin made chatter (period doubling)
  double line_ratio = 0.0;      ///< a line's PSD over the floor
  double threshold_ln = 0.0;    ///< ln line_ratio
};

/// The spindle as the comb measured it (stage 2), for the bins' causes.
struct SpindleComb {
  int coarse_harmonics = 1;     ///< harmonics of the coarse search
  int fine_harmonics = 1;       ///< harmonics of the refinement
  double spindle_hz = 0.0;      ///< measured (or commanded) spindle frequency
  double uncertainty_hz = 0.0;  ///< of the fundamental; k times that at the k-th harmonic
};

/// A line: a local maximum of the line bins and its power over the main lobe.
struct Peak {
  std::size_t bin;
  double power;
};

/// Bin k's power above the mean noise (signal unit²).
inline double excess_power(const Spectrum& s, const LineBins& lines, const std::vector<double>& psd,
                           std::size_t k) {
  return std::max(0.0, psd[k] - lines.noise[k]) * s.df;
}

/// Stage 3, the line bins: the floor, the line level and the bins above it
/// (mains_bin left empty: mains_line_bins fills it).
LineBins find_line_bins(const Spectrum& s, const std::vector<double>& psd);

/// Stage 3, mains lines: the line bins of the lines on a 50 or 60 Hz
/// harmonic (all zero unless options.detect_mains).
std::vector<char> mains_line_bins(const ListenOptions& options, const Spectrum& s,
                                  const LineBins& lines, const std::vector<double>& psd);

/// Stage 2: the spindle frequency from the comb of its harmonics; sets
/// r.spindle_hz_measured, r.spindle_refined and r.tooth_hz.
SpindleComb measure_spindle(const ListenOptions& options, const Spectrum& s, const LineBins& lines,
                            RecordingAnalysis& r);

/// Stage 3, each bin's cause (r.cause): below the band, floor, forced
/// (spindle, tooth), set aside (ignored, mains) or chatter.
void attribute_bins(const ListenOptions& options, const Spectrum& s, const LineBins& lines,
                    const SpindleComb& comb, RecordingAnalysis& r);

/// Stage 3, period doubling: the spindle-but-not-tooth harmonics become
/// chatter when they hold more than the tooth harmonics (several teeth).
/// Marks those bins in lines.doubled (they repeat once per revolution).
void reattribute_period_doubling(const ListenOptions& options, const Spectrum& s, LineBins& lines,
                                 RecordingAnalysis& r);

/// Stage 3, the lines: local maxima of the line bins, in frequency order.
std::vector<Peak> find_line_peaks(const Spectrum& s, const LineBins& lines,
                                  const RecordingAnalysis& r);

/// Stage 3, mains-modulated combs: chains of chatter-candidate lines 100 or
/// 120 Hz apart become mains (when options.detect_mains).
void set_aside_mains_combs(const ListenOptions& options, const Spectrum& s, const LineBins& lines,
                           const SpindleComb& comb, const std::vector<Peak>& peaks,
                           RecordingAnalysis& r);

/// Stage 3, steady lines: narrow chatter-candidate lines of constant
/// short-time power become steady_line (when options.detect_steady_lines).
void set_aside_steady_lines(const ListenOptions& options, const Spectrum& s, const LineBins& lines,
                            const std::vector<Peak>& peaks, const WelchStream& welch,
                            RecordingAnalysis& r);

/// Stage 3, skirts: a chatter-candidate line bin whose way uphill ends on a
/// forced or set-aside peak takes that peak's cause.
void give_skirts_to_their_peaks(const Spectrum& s, const LineBins& lines, RecordingAnalysis& r);

/// The bins of the measured comb's narrow lines: forced (spindle or tooth)
/// line bins whose run of line bins is no wider than a steady line's. What
/// the engaged stretch follows frame by frame: a broad hump that a harmonic
/// happens to fall in (air noise exciting a mode) is not the cut's comb.
std::vector<char> narrow_comb_bins(const Spectrum& s, const LineBins& lines,
                                   const RecordingAnalysis& r);

}  // namespace robomill::monitoring::detail
