// The chatter verdict of a recorded (or simulated) signal
// (recording_analysis.hpp; the method, the thresholds and the evidence behind
// them: docs/monitoring.md). This file runs the detector's stages in order:
// stage 1 (the streaming pass and the Welch PSD) and stages 4 and 5 (the
// energies, the verdict, the onset) are here; stages 2 and 3 (the line bins,
// the spindle's comb, every bin's cause) are in line_attribution.cpp.

#include "robomill/monitoring/recording_analysis.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <limits>
#include <mutex>
#include <numeric>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

#include "line_attribution.hpp"
#include "welch_stream.hpp"

namespace robomill::monitoring {
namespace {

using detail::kMainLobeBins;
using detail::LineBins;
using detail::Peak;
using detail::Spectrum;

constexpr std::size_t kBlock = 65536;  // samples read at a time
/// Welch segment: at least this many bins between spindle harmonics, so that
/// the comb is resolved with room between its teeth for other lines.
constexpr double kBinsPerSpindleHarmonic = 32.0;
/// ... and at least 1 Hz: mains lines (held to 0.2 % by the grid) and lines
/// that stay put are told from the cut's by their frequency, which a coarser
/// grid blurs (a fast spindle's 32 bins per harmonic can be 6 Hz wide) ...
constexpr double kCoarsestResolutionHz = 1.0;
/// ... but at least this many segments over the recording (ν ≥ 2·3·0.95
/// degrees of freedom for the floor's statistics) ...
constexpr double kMinSegments = 3.0;
/// ... unless 3 segments would leave fewer than this many bins between
/// spindle harmonics: a Hann line's main lobe spans ±2 bins, so at 4 bins
/// apart a line midway between two harmonics stands clear of both. A short
/// recording then gets 2 segments (issue 34: 0.75-1 s of turning at 570 rpm
/// holds 7-9 revolutions but hundreds of cycles of chatter near 1 kHz).
/// Shorter still, the comb cannot be told from other lines: "unknown".
constexpr double kMinBinsPerSpindleHarmonic = 4.0;
constexpr double kFewestSegments = 2.0;

/// The longest Welch segment (samples) that gives `segments` 50 %-overlapped
/// segments in `samples`: (n − L) / (L / 2) + 1 ≥ K ⇔ L ≤ 2 n / (K + 1).
double longest_segment(double samples, double segments) {
  return samples / (0.5 * (segments + 1.0));
}
/// A chatter-candidate line that is strongest in the judged stretch's first
/// frame and within this many dB of that for less than half of the stretch
/// rings down: a transient (judged from kMinHistoryFrames frames).
constexpr double kMaxChatterDecayDb = 10.0;
constexpr std::size_t kMinHistoryFrames = 4;
/// Clipping: samples within 0.1 % of full scale; more than 0.1 % of them and
/// the spectrum holds the clipping's harmonics, not the cut's.
constexpr double kClipLevel = 0.999;
constexpr double kMaxClippedFraction = 1e-3;
/// Onset: from the first frame whose chatter share exceeds the threshold and
/// after which at least this share of frames do (short dips allowed).
constexpr double kOnsetPersistence = 0.8;
/// Memory of the spectrogram at full resolution (doubles): the columns are
/// capped so that columns × bins stays below this (32 MB).
constexpr std::size_t kSpectrogramBudget = std::size_t{1} << 22;
/// The public spectrogram: at most this many frequency columns (bins averaged).
constexpr std::size_t kDisplayBins = 1024;
/// The engaged stretch: frames whose forced-comb power lies within this
/// factor (10 dB) of the cut's level, the 90th percentile over the frames.
constexpr double kEngagedFactor = 0.1;
constexpr double kEngagedReferenceQuantile = 0.9;

bool is_smooth(std::size_t n) {
  for (std::size_t p : {2u, 3u, 5u})
    while (n % p == 0)
      n /= p;
  return n == 1;
}

/// An even length with only the prime factors 2, 3, 5 (fast FFTW), the
/// smallest ≥ n or the largest ≤ n.
std::size_t smooth_length(std::size_t n, bool up) {
  n = std::max<std::size_t>(n, 16);
  if (up) {
    while (n % 2 != 0 || !is_smooth(n))
      ++n;
  } else {
    while (n > 16 && (n % 2 != 0 || !is_smooth(n)))
      --n;
  }
  return n;
}

/// Reads the source on a second thread into three rotating blocks while the
/// caller's thread transforms the previous ones (a file's decoding and the
/// FFTs overlap on two cores).
class BlockReader {
 public:
  explicit BlockReader(SignalSource& source) : source_(source) {
    for (auto& slot : slots_)
      slot.resize(kBlock);
    thread_ = std::thread([this] { run(); });
  }
  ~BlockReader() {
    {
      const std::lock_guard lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  /// The next block (empty at the end); rethrows the source's exception.
  std::span<const double> next() {
    std::unique_lock lock(mutex_);
    if (holding_) {
      ++consumed_;
      holding_ = false;
      changed_.notify_all();
    }
    changed_.wait(lock, [&] { return produced_ > consumed_ || done_; });
    if (produced_ == consumed_) {
      if (error_)
        std::rethrow_exception(error_);
      return {};
    }
    holding_ = true;
    const std::size_t slot = consumed_ % slots_.size();
    return {slots_[slot].data(), counts_[slot]};
  }

 private:
  void run() {
    for (;;) {
      std::size_t slot = 0;
      {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [&] { return produced_ - consumed_ < slots_.size() || stop_; });
        if (stop_)
          return;
        slot = produced_ % slots_.size();
      }
      std::size_t count = 0;
      std::exception_ptr error;
      try {
        count = source_.read(slots_[slot]);
      } catch (...) {
        error = std::current_exception();
      }
      {
        const std::lock_guard lock(mutex_);
        if (count > 0 && !error) {
          counts_[slot] = count;
          ++produced_;
        } else {
          done_ = true;
          error_ = error;
        }
      }
      changed_.notify_all();
      if (done_)
        return;
    }
  }

  SignalSource& source_;
  std::array<std::vector<double>, 3> slots_;
  std::array<std::size_t, 3> counts_{};
  std::size_t produced_ = 0, consumed_ = 0;
  bool holding_ = false, done_ = false, stop_ = false;
  std::exception_ptr error_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::thread thread_;
};

std::string hz_text(double hz) {
  return fmt::format("{:.4g} Hz", hz);
}

/// The shortest recording judged (s): the frequency resolution the verdict
/// needs, kMinBinsPerSpindleHarmonic bins between the commanded spindle's
/// harmonics, in kFewestSegments segments (6 revolutions).
double shortest_recording_s(const ListenOptions& options) {
  const double segment_s = kMinBinsPerSpindleHarmonic / options.commanded_spindle_hz;
  return 0.5 * (kFewestSegments + 1.0) * segment_s;
}

/// "unknown" for a recording shorter than shortest_recording_s, in words.
std::string too_short_reason(double duration_s, double min_duration_s) {
  return fmt::format(
      "the recording ({:.3g} s) is too short to resolve the spindle's harmonics: that takes {} "
      "spectral segments of {:g} bins per harmonic ({:.3g} s)",
      duration_s, kFewestSegments, kMinBinsPerSpindleHarmonic, min_duration_s);
}

/// Before stage 1: whether the signal can be judged at all, from its
/// description (a sample rate, one fast enough for the tooth comb, a length
/// not known to be too short). False with r.reason set when it cannot.
bool can_judge_signal(const SignalInfo& info, double min_duration_s, RecordingAnalysis& r) {
  const double fs = info.sample_rate_hz;
  if (!(fs > 0.0)) {
    r.reason = "the signal has no sample rate";
    return false;
  }
  // A sample rate below twice the tooth frequency cannot show the comb that
  // the forced response is recognised by (Nyquist).
  if (fs < 2.0 * r.tooth_hz) {
    r.reason = fmt::format(
        "the sample rate {} is below twice the tooth-passing frequency {}: the forced comb "
        "cannot be seen",
        hz_text(fs), hz_text(r.tooth_hz));
    return false;
  }
  if (info.samples >= 0 && static_cast<double>(info.samples) / fs < min_duration_s) {
    r.duration_s = static_cast<double>(info.samples) / fs;
    r.reason = too_short_reason(r.duration_s, min_duration_s);
    return false;
  }
  return true;
}

/// Stage 1, the Welch segment (samples): ≥ 32 bins per spindle harmonic and
/// ≥ 1 Hz resolution, but ≥ 3 segments (2 when 3 would resolve the comb
/// with fewer than 4 bins a harmonic); an FFT-friendly length.
std::size_t welch_segment_length(const SignalInfo& info, const ListenOptions& options) {
  const double fs = info.sample_rate_hz;
  const double wanted = std::max(kBinsPerSpindleHarmonic * fs / options.commanded_spindle_hz,
                                 fs / kCoarsestResolutionHz);
  std::size_t length = options.segment_s > 0.0
                           ? static_cast<std::size_t>(std::llround(options.segment_s * fs))
                           : static_cast<std::size_t>(std::ceil(wanted));
  length = smooth_length(length, true);
  if (info.samples > 0) {
    const auto samples = static_cast<double>(info.samples);
    const double resolving = kMinBinsPerSpindleHarmonic * fs / options.commanded_spindle_hz;
    double cap = longest_segment(samples, kMinSegments);
    if (cap < resolving)
      cap = longest_segment(samples, kFewestSegments);
    if (static_cast<double>(length) > cap)
      length = smooth_length(static_cast<std::size_t>(cap), false);
  }
  return length;
}

/// Stage 1, the spectrogram's columns: max_spectrogram_frames (at least 2),
/// within the memory budget at `bins` bins a column.
std::size_t spectrogram_column_cap(const ListenOptions& options, std::size_t bins) {
  return std::max<std::size_t>(
      2,
      std::min<std::size_t>(static_cast<std::size_t>(std::max(2, options.max_spectrogram_frames)),
                            kSpectrogramBudget / bins));
}

/// What stage 1's pass counted: samples read, clipped, not finite.
struct StreamCounts {
  std::size_t delivered = 0, clipped = 0, nonfinite = 0;
};

/// Stage 1, the one streaming pass: every block of the source into the Welch
/// accumulator (closed at the end), the reading on a second thread.
StreamCounts stream_into_welch(SignalSource& source, const SignalInfo& info,
                               const ListenOptions& options, detail::WelchStream& welch) {
  StreamCounts counts;
  const double clip_level = kClipLevel * info.full_scale;
  {
    BlockReader reader(source);
    for (;;) {
      std::span<const double> block = reader.next();
      if (block.empty())
        break;
      std::size_t bad = 0, high = 0;
      for (double v : block) {
        bad += !std::isfinite(v);
        high += info.full_scale > 0.0 && std::abs(v) >= clip_level;
      }
      if (bad > 0) {
        // Keep the transform finite; the verdict is "unknown" anyway.
        std::vector<double> clean(block.begin(), block.end());
        for (double& v : clean)
          if (!std::isfinite(v))
            v = 0.0;
        welch.push(clean.data(), clean.size());
      } else {
        welch.push(block.data(), block.size());
      }
      counts.nonfinite += bad;
      counts.clipped += high;
      counts.delivered += block.size();
      if (options.progress && info.samples > 0)
        options.progress(std::min(
            1.0, static_cast<double>(counts.delivered) / static_cast<double>(info.samples)));
    }
  }
  welch.finish();
  return counts;
}

/// Stage 1's outcome: the duration and the clipped share; false with
/// r.reason set when what was read cannot be judged (samples not finite,
/// too short a recording, not one whole segment).
bool can_judge_stream(const StreamCounts& counts, const detail::WelchStream& welch, double fs,
                      std::size_t length, double min_duration_s, RecordingAnalysis& r) {
  const std::size_t delivered = counts.delivered;
  r.duration_s = static_cast<double>(delivered) / fs;
  r.clipped_fraction = delivered > 0 ? static_cast<double>(counts.clipped) / delivered : 0.0;
  if (counts.nonfinite > 0) {
    r.reason = fmt::format("{} samples are not finite numbers", counts.nonfinite);
    return false;
  }
  if (r.duration_s < min_duration_s) {
    r.reason = too_short_reason(r.duration_s, min_duration_s);
    return false;
  }
  if (welch.segments() == 0) {
    r.reason =
        fmt::format("the recording ({:.3g} s) is shorter than one spectral segment ({:.3g} s)",
                    r.duration_s, static_cast<double>(length) / fs);
    return false;
  }
  return true;
}

/// Stage 1's result: the Welch PSD, one-sided, signal unit²/Hz (r.psd,
/// r.frequency_hz, r.resolution_hz), and the grid the later stages share
/// (its band still unset: choose_band).
Spectrum welch_psd(const detail::WelchStream& welch, double fs, std::size_t length,
                   RecordingAnalysis& r) {
  Spectrum s;
  s.fs = fs;
  s.length = length;
  s.bins = length / 2 + 1;
  const std::size_t bins = s.bins;
  s.df = fs / static_cast<double>(length);
  const double df = s.df;
  r.resolution_hz = df;
  s.segments = static_cast<double>(welch.segments());
  s.scale = 1.0 / (fs * welch.window_power());
  r.frequency_hz.resize(bins);
  r.psd.resize(bins);
  for (std::size_t k = 0; k < bins; ++k) {
    r.frequency_hz[k] = static_cast<double>(k) * df;
    const double one_sided = (k == 0 || 2 * k == length) ? 1.0 : 2.0;
    r.psd[k] = one_sided * s.scale * welch.periodogram_sum()[k] / s.segments;
  }
  return s;
}

/// Stage 1, the analysed band (s.band_high, s.first_bin, s.last_bin): the
/// options' or 3 bins to 0.45 fs. False with r.reason set when it holds
/// fewer than 8 bins.
bool choose_band(const ListenOptions& options, Spectrum& s, RecordingAnalysis& r) {
  const double df = s.df, fs = s.fs;
  const double band_low = options.band_low_hz > 0.0 ? options.band_low_hz : 3.0 * df;
  s.band_high = options.band_high_hz > 0.0 ? std::min(options.band_high_hz, 0.5 * fs) : 0.45 * fs;
  s.first_bin = static_cast<std::size_t>(std::ceil(band_low / df));
  s.last_bin = std::min(s.bins - 1, static_cast<std::size_t>(std::floor(s.band_high / df)));
  if (s.first_bin + 8 > s.last_bin) {
    r.reason = "the analysed band holds fewer than 8 bins";
    return false;
  }
  return true;
}

/// Stage 4's sums over the band: the lines' power above the noise by cause
/// (forced: spindle and tooth harmonics; runout: the spindle's harmonics
/// that are not the tooth's) and the broadband floor (the band's power less
/// every line's excess: the noise under the lines included).
struct LineEnergies {
  double forced = 0.0, runout = 0.0, chatter = 0.0, aside = 0.0, floor = 0.0, total = 0.0;
  double doubled = 0.0;  ///< the chatter on spindle harmonics (period doubling)
};

/// The indicators of stage 4 from the band's sums (r's fractions): the
/// energy fractions of the band's total, the chatter line fraction and the
/// once-per-period sampling variances. Shared by the whole spectrum and the
/// short-time frames (the onset).
void set_indicators(const LineEnergies& e, RecordingAnalysis& r) {
  // The fractions of everything the sensor recorded in the band (they add
  // up to one): chatter, forced lines, lines set aside, the broadband floor.
  if (e.total > 0.0) {
    r.chatter_energy_fraction = e.chatter / e.total;
    r.forced_energy_fraction = e.forced / e.total;
    r.ignored_energy_fraction = e.aside / e.total;
    r.floor_energy_fraction = e.floor / e.total;
  }
  // The verdict's indicator weighs chatter evidence against the rest of the
  // power off the spindle's harmonics only: neither the forced lines nor the
  // lines set aside enter it, so a loud tooth comb with chatter beside it
  // (issue 34: 32 % chatter, 59 % forced in a 9100 rpm cut) and a loud hum
  // over a chattering slot (57 % in a 150 Hz line) do not hide the chatter.
  if (e.chatter + e.floor > 0.0)
    r.chatter_line_fraction = e.chatter / (e.chatter + e.floor);
  // Period-doubling chatter sits on the spindle's harmonics: it repeats once
  // per revolution and varies once per tooth (Schmitz samples once per
  // tooth for it).
  const double cut = e.chatter + e.forced + e.floor;
  if (cut > 0.0) {
    r.once_per_revolution_variance = (e.chatter - e.doubled + e.floor) / cut;
    r.once_per_tooth_variance = (e.chatter + e.runout + e.floor) / cut;
  }
}

/// Stage 4, the band's sums of power by cause (the PSD's or a frame's:
/// `power(k)` in signal unit²/Hz, `noise` the mean noise under it).
template <class Power>
LineEnergies band_energies(const Spectrum& s, const std::vector<LineCause>& cause,
                           const LineBins& lines, Power power) {
  const std::vector<double>& noise = lines.noise;
  LineEnergies e;
  double lines_total = 0.0;
  for (std::size_t k = s.first_bin; k <= s.last_bin; ++k) {
    const double p = power(k);
    e.total += p * s.df;
    if (cause[k] == LineCause::floor)
      continue;
    const double excess = std::max(0.0, p - noise[k]) * s.df;
    lines_total += excess;
    switch (cause[k]) {
      case LineCause::spindle:
        e.runout += excess;
        e.forced += excess;
        break;
      case LineCause::tooth:
        e.forced += excess;
        break;
      case LineCause::chatter:
        e.chatter += excess;
        if (lines.doubled[k])
          e.doubled += excess;
        break;
      default:
        e.aside += excess;
    }
  }
  e.floor = std::max(0.0, e.total - lines_total);
  return e;
}

/// Stage 4, the energies and the indicators of the whole spectrum.
LineEnergies energy_fractions(const Spectrum& s, const LineBins& lines, RecordingAnalysis& r) {
  const LineEnergies e = band_energies(s, r.cause, lines, [&](std::size_t k) { return r.psd[k]; });
  set_indicators(e, r);
  return e;
}

/// Stage 4, the lines (r.lines): the peaks sorted strongest first (in
/// place: chatter_frequency relies on it), at most 200 of them.
void list_lines(std::vector<Peak>& peaks, RecordingAnalysis& r) {
  std::sort(peaks.begin(), peaks.end(),
            [](const Peak& x, const Peak& y) { return x.power > y.power; });
  for (const Peak& p : peaks)
    if (r.lines.size() < 200)
      r.lines.push_back({r.frequency_hz[p.bin], p.power, r.cause[p.bin]});
}

/// Stage 4, the chatter frequency (r.chatter_hz): the strongest line of the
/// chatter family that holds the most power, a family being a chatter line
/// and its sidebands fc ± j·f_tooth. `peaks` sorted strongest first.
void chatter_frequency(const Spectrum& s, const std::vector<Peak>& peaks, RecordingAnalysis& r) {
  const double df = s.df;
  std::vector<const Peak*> candidates;
  for (const Peak& p : peaks)
    if (r.cause[p.bin] == LineCause::chatter)
      candidates.push_back(&p);
  std::vector<char> grouped(candidates.size(), 0);
  double best_family = 0.0;
  const double tolerance = kMainLobeBins * df;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (grouped[i])
      continue;
    grouped[i] = 1;
    const double f = r.frequency_hz[candidates[i]->bin];
    double family = candidates[i]->power;
    for (std::size_t j = i + 1; j < candidates.size(); ++j) {
      if (grouped[j])
        continue;
      const double g = r.frequency_hz[candidates[j]->bin];
      const double n = std::round(std::abs(g - f) / r.tooth_hz);
      const double folded = std::round((g + f) / r.tooth_hz);
      if ((n >= 1 && std::abs(std::abs(g - f) - n * r.tooth_hz) <= tolerance) ||
          (folded >= 1 && std::abs(g + f - folded * r.tooth_hz) <= tolerance)) {
        grouped[j] = 1;
        family += candidates[j]->power;
      }
    }
    if (family > best_family) {
      best_family = family;
      // The family's strongest line (the first, candidates being sorted),
      // refined by a parabola through ln PSD.
      const std::size_t k = candidates[i]->bin;
      const double left = std::log(std::max(r.psd[k - 1], 1e-300));
      const double centre = std::log(r.psd[k]);
      const double right = std::log(std::max(r.psd[k + 1], 1e-300));
      const double curvature = left - 2.0 * centre + right;
      const double offset =
          curvature < 0.0 ? std::clamp(0.5 * (left - right) / curvature, -0.5, 0.5) : 0.0;
      r.chatter_hz = (static_cast<double>(k) + offset) * df;
    }
  }
}

/// Stage 5's input: the spectrogram (bins averaged to at most kDisplayBins
/// columns) and each frame's chatter line fraction (the same causes, the
/// frame's own power above the mean noise).
void fill_spectrogram(const SignalInfo& info, const Spectrum& s, const LineBins& lines,
                      const detail::WelchStream& welch, RecordingAnalysis& r) {
  const std::size_t bins = s.bins, length = s.length, columns = welch.columns();
  const std::size_t group = (bins + kDisplayBins - 1) / kDisplayBins;
  const std::size_t display_bins = (bins + group - 1) / group;
  r.spectrogram_frequency_hz.resize(display_bins);
  for (std::size_t d = 0; d < display_bins; ++d) {
    const std::size_t from = d * group, to = std::min(bins, from + group);
    r.spectrogram_frequency_hz[d] = 0.5 * (r.frequency_hz[from] + r.frequency_hz[to - 1]);
  }
  r.spectrogram_psd.assign(columns * display_bins, 0.0);
  r.spectrogram_time_s.resize(columns);
  r.frame_chatter_fraction.resize(columns);
  for (std::size_t c = 0; c < columns; ++c) {
    const double* col = welch.column(c);
    const double norm = s.scale / static_cast<double>(welch.column_segments(c));
    r.spectrogram_time_s[c] =
        info.start_s + static_cast<double>(welch.column_first_sample(c)) / s.fs;
    for (std::size_t d = 0; d < display_bins; ++d) {
      const std::size_t from = d * group, to = std::min(bins, from + group);
      double sum = 0.0;
      for (std::size_t k = from; k < to; ++k)
        sum += (k == 0 || 2 * k == length ? 1.0 : 2.0) * norm * col[k];
      r.spectrogram_psd[c * display_bins + d] = sum / static_cast<double>(to - from);
    }
    // The frame's chatter line fraction, as the verdict's, with the
    // whole spectrum's causes.
    const LineEnergies e =
        band_energies(s, r.cause, lines, [&](std::size_t k) { return 2.0 * norm * col[k]; });
    r.frame_chatter_fraction[c] =
        e.chatter + e.floor > 0.0 ? e.chatter / (e.chatter + e.floor) : 0.0;
  }
}

/// Stage 5, the onset (r.onset_s): the first frame from which the share
/// stays above the threshold (at least kOnsetPersistence of the later
/// frames).
void find_onset(double threshold, std::size_t columns, RecordingAnalysis& r) {
  std::size_t above_after = 0;
  std::optional<std::size_t> onset;
  for (std::size_t c = columns; c-- > 0;) {
    above_after += r.frame_chatter_fraction[c] > threshold;
    if (r.frame_chatter_fraction[c] > threshold &&
        static_cast<double>(above_after) >= kOnsetPersistence * static_cast<double>(columns - c))
      onset = c;
  }
  if (onset)
    r.onset_s = r.spectrogram_time_s[*onset];
}

/// Stage 4, the history of the strongest chatter-candidate line over the
/// judged stretch: its short-time power per frame (the main lobe's bins
/// summed), the least-squares slope (r.chatter_growth_db_per_s, dB/s, from
/// 3 frames), and whether it dies away.
struct LineHistory {
  bool dies_away = false;
  double peak_s = 0.0;      ///< the frame where the line is strongest
  double strong_share = 1;  ///< of the frames, those within kMaxChatterDecayDb of its peak
};

LineHistory chatter_line_history(const Spectrum& s, const detail::WelchStream& welch,
                                 RecordingAnalysis& r) {
  LineHistory h;
  if (!(r.chatter_hz > 0.0))
    return h;
  const auto centre = static_cast<std::size_t>(std::llround(r.chatter_hz / s.df));
  const auto reach = static_cast<std::size_t>(kMainLobeBins);
  if (centre < s.first_bin + reach || centre + reach > s.last_bin)
    return h;
  std::vector<double> time_s, level_db;
  for (std::size_t c = 0; c < welch.columns(); ++c) {
    const double t = r.spectrogram_time_s[c];
    if ((r.engaged_start_s && t < *r.engaged_start_s) || (r.engaged_end_s && t > *r.engaged_end_s))
      continue;
    const double* col = welch.column(c);
    double power = 0.0;
    for (std::size_t k = centre - reach; k <= centre + reach; ++k)
      power += col[k];
    power /= static_cast<double>(welch.column_segments(c));
    if (power > 0.0) {
      time_s.push_back(t);
      level_db.push_back(10.0 * std::log10(power));
    }
  }
  const auto n = static_cast<double>(time_s.size());
  double st = 0.0, sy = 0.0, stt = 0.0, sty = 0.0;
  for (std::size_t i = 0; i < time_s.size(); ++i) {
    st += time_s[i];
    sy += level_db[i];
    stt += time_s[i] * time_s[i];
    sty += time_s[i] * level_db[i];
  }
  const double spread = n * stt - st * st;
  if (n >= 3.0 && spread > 0.0)
    r.chatter_growth_db_per_s = (n * sty - st * sy) / spread;
  // Dies away: strongest in the stretch's first frame and within 10 dB of
  // that for less than half of it. A transient of the cut's start (the
  // tool's entry) rings down from there; chatter grows and holds. A
  // recording that starts before the cut has its peak later, where the cut
  // begins, and is not judged by this rule: chatter in a short cut amid air
  // is strong for less than half of it too.
  if (time_s.size() >= kMinHistoryFrames) {
    const auto peak = static_cast<std::size_t>(std::max_element(level_db.begin(), level_db.end()) -
                                               level_db.begin());
    std::size_t strong = 0;
    for (double db : level_db)
      strong += db > level_db[peak] - kMaxChatterDecayDb;
    h.peak_s = time_s[peak];
    h.strong_share = static_cast<double>(strong) / n;
    h.dies_away = peak == 0 && 2 * strong < time_s.size();
  }
  return h;
}

/// Stage 4, the verdict (r.verdict, r.reason): unknown for a clipped signal
/// or one without lines, else chatter when the chatter evidence's share
/// exceeds the threshold (then stage 5, the onset), else stable.
void judge(const SignalInfo& info, const ListenOptions& options, const LineEnergies& energies,
           std::size_t columns, const LineHistory& history, RecordingAnalysis& r) {
  const double threshold = options.chatter_line_threshold;
  const std::string spindle_text =
      r.spindle_source == "tachometer"
          ? fmt::format("spindle {} from the tachometer ({} commanded)",
                        hz_text(r.spindle_hz_measured), hz_text(r.spindle_hz_commanded))
      : r.spindle_refined
          ? fmt::format("spindle {} measured ({} commanded)", hz_text(r.spindle_hz_measured),
                        hz_text(r.spindle_hz_commanded))
          : fmt::format("spindle {} as commanded (no comb of harmonics stood above the floor)",
                        hz_text(r.spindle_hz_commanded));
  if (info.full_scale > 0.0 && r.clipped_fraction > kMaxClippedFraction) {
    r.verdict = Verdict::unknown;
    r.reason = fmt::format(
        "{:.2g} % of the samples are clipped (at full scale): the spectrum holds the clipping's "
        "harmonics",
        100.0 * r.clipped_fraction);
    return;
  }
  if (energies.forced + energies.chatter <= 0.0) {
    r.verdict = Verdict::unknown;
    r.reason = fmt::format(
        "no spindle, tooth or chatter line rises above the floor ({}): the signal cannot decide",
        spindle_text);
    return;
  }
  const bool lines_say_chatter = r.chatter_line_fraction > threshold;
  const bool samples_repeat = r.once_per_tooth_variance < kMinOncePerPeriodVariance;
  // Chatter is self-excited: it grows to a limit cycle and holds while the
  // cut lasts. A line that rings down from the start of the stretch was
  // excited once (the tool's entry) and is a free vibration decaying.
  if (lines_say_chatter && !samples_repeat && history.dies_away) {
    r.verdict = Verdict::stable;
    r.reason = fmt::format(
        "stable: the line at {} off the spindle's harmonics rings down from {:.2f} s (within "
        "{:.0f} dB of its peak for {:.0f} % of the frames): a decaying free vibration, not "
        "self-excited chatter (lines off the harmonics hold {:.1f} % of the power off them); {}",
        hz_text(r.chatter_hz), history.peak_s, kMaxChatterDecayDb, 100.0 * history.strong_share,
        100.0 * r.chatter_line_fraction, spindle_text);
  } else if (lines_say_chatter && !samples_repeat) {
    r.verdict = Verdict::chatter;
    r.reason = fmt::format(
        "chatter at {}: lines off the spindle's harmonics hold {:.1f} % of the power off them "
        "(threshold {:.0f} %; {:.1f} % of everything recorded, the spindle's and the teeth's "
        "harmonics {:.1f} %); {}",
        hz_text(r.chatter_hz), 100.0 * r.chatter_line_fraction, 100.0 * threshold,
        100.0 * r.chatter_energy_fraction, 100.0 * r.forced_energy_fraction, spindle_text);
    find_onset(threshold, columns, r);
  } else if (lines_say_chatter) {
    r.verdict = Verdict::stable;
    r.reason = fmt::format(
        "stable: once-per-tooth samples repeat ({:.1f} % of the cut's power is off the tooth "
        "harmonics, below {:.0f} %), though lines off the spindle's harmonics hold {:.1f} % of "
        "the power off them; {}",
        100.0 * r.once_per_tooth_variance, 100.0 * kMinOncePerPeriodVariance,
        100.0 * r.chatter_line_fraction, spindle_text);
  } else {
    r.verdict = Verdict::stable;
    r.reason = fmt::format(
        "stable: lines off the spindle's harmonics hold {:.1f} % of the power off them "
        "(threshold {:.0f} %; the rest is broadband floor); the spindle's and the teeth's "
        "harmonics {:.1f} % of everything recorded; {}",
        100.0 * r.chatter_line_fraction, 100.0 * threshold, 100.0 * r.forced_energy_fraction,
        spindle_text);
  }
}

}  // namespace

const char* verdict_name(Verdict verdict) noexcept {
  switch (verdict) {
    case Verdict::stable:
      return "stable";
    case Verdict::chatter:
      return "chatter";
    case Verdict::unknown:
      return "unknown";
  }
  return "unknown";
}

const char* line_cause_name(LineCause cause) noexcept {
  switch (cause) {
    case LineCause::below_band:
      return "below_band";
    case LineCause::spindle:
      return "spindle";
    case LineCause::tooth:
      return "tooth";
    case LineCause::ignored:
      return "ignored";
    case LineCause::mains:
      return "mains";
    case LineCause::steady_line:
      return "steady_line";
    case LineCause::floor:
      return "floor";
    case LineCause::chatter:
      return "chatter";
  }
  return "floor";
}

std::vector<SpindleSuggestion> suggest_spindle_speeds(double chatter_hz, int teeth, double min_hz,
                                                      double max_hz) {
  std::vector<SpindleSuggestion> out;
  if (!(chatter_hz > 0.0) || teeth < 1 || !(max_hz >= min_hz) || !(max_hz > 0.0))
    return out;
  // n = 60 fc / (N (k + 1)): the (k+1)-th tooth-passing harmonic on fc
  // (Altintas' lobe centres); the speed falls with the harmonic, so the
  // search ends below min_hz. The lowest harmonic is the widest lobe.
  for (int harmonic = 1;; ++harmonic) {
    const double spindle_hz = chatter_hz / (static_cast<double>(teeth) * harmonic);
    if (spindle_hz < min_hz || harmonic > 100000)
      break;
    if (spindle_hz <= max_hz)
      out.push_back({spindle_hz, harmonic});
  }
  return out;
}

namespace {

/// Stages 2-5 on the spectrum in r.psd (s its grid, s.segments its Welch
/// count): the line bins, the spindle's comb, every bin's cause, the
/// energies, the lines, the spectrogram, the verdict and the onset. Returns
/// the bins of the comb's narrow lines (detail::narrow_comb_bins).
std::vector<char> judge_spectrum(const SignalInfo& info, const ListenOptions& options, Spectrum& s,
                                 const detail::WelchStream& welch, RecordingAnalysis& r) {
  // Stages 2 and 3 (line_attribution.cpp): the line bins, the mains lines,
  // the spindle's comb, then every bin's cause, refined rule by rule.
  LineBins lines = detail::find_line_bins(s, r.psd);
  lines.mains_bin = detail::mains_line_bins(options, s, lines, r.psd);
  const detail::SpindleComb comb = detail::measure_spindle(options, s, lines, r);
  detail::attribute_bins(options, s, lines, comb, r);
  detail::reattribute_period_doubling(options, s, lines, r);
  std::vector<Peak> peaks = detail::find_line_peaks(s, lines, r);
  detail::set_aside_mains_combs(options, s, lines, comb, peaks, r);
  detail::set_aside_steady_lines(options, s, lines, peaks, welch, r);
  detail::give_skirts_to_their_peaks(s, lines, r);

  // Stages 4 and 5: the energies, the lines, the spectrogram, the verdict
  // and the onset.
  const LineEnergies energies = energy_fractions(s, lines, r);
  list_lines(peaks, r);
  chatter_frequency(s, peaks, r);
  fill_spectrogram(info, s, lines, welch, r);
  const LineHistory history = chatter_line_history(s, welch, r);
  judge(info, options, energies, welch.columns(), history, r);
  return detail::narrow_comb_bins(s, lines, r);
}

/// The engaged stretch (first and last short-time column): where the power
/// in the measured comb's narrow lines (`comb`: its spindle and tooth
/// harmonics) stands within kEngagedFactor of its level in the cut. Issue 34: a recording that
/// starts before the tool engages holds air, whose broadband noise reads as chatter evidence over
/// the whole spectrum. None when no comb was measured (a turning cut has none to rise) or the comb
/// spans the whole recording.
std::optional<std::pair<std::size_t, std::size_t>> engaged_stretch(const Spectrum& s,
                                                                   const detail::WelchStream& welch,
                                                                   const std::vector<char>& comb,
                                                                   const RecordingAnalysis& r) {
  const std::size_t columns = welch.columns();
  if (!r.spindle_refined || columns < 4)
    return std::nullopt;
  std::vector<double> comb_power(columns, 0.0);
  for (std::size_t c = 0; c < columns; ++c) {
    const double* col = welch.column(c);
    double sum = 0.0;
    for (std::size_t k = s.first_bin; k <= s.last_bin; ++k)
      if (comb[k])
        sum += col[k];
    comb_power[c] = sum / static_cast<double>(welch.column_segments(c));
  }
  std::vector<double> sorted = comb_power;
  const auto at = sorted.begin() +
                  static_cast<std::ptrdiff_t>(
                      std::llround(kEngagedReferenceQuantile * static_cast<double>(columns - 1)));
  std::nth_element(sorted.begin(), at, sorted.end());
  const double level = kEngagedFactor * *at;
  if (!(level > 0.0))
    return std::nullopt;
  std::size_t first = 0, last = columns - 1;
  while (first < last && comb_power[first] < level)
    ++first;
  while (last > first && comb_power[last] < level)
    --last;
  if (first == 0 && last == columns - 1)
    return std::nullopt;
  return std::pair{first, last};
}

/// The Welch PSD of the columns [first, last] alone (r.psd, s.segments).
void stretch_psd(const detail::WelchStream& welch, std::size_t first, std::size_t last, Spectrum& s,
                 RecordingAnalysis& r) {
  std::size_t segments = 0;
  std::fill(r.psd.begin(), r.psd.end(), 0.0);
  for (std::size_t c = first; c <= last; ++c) {
    const double* col = welch.column(c);
    for (std::size_t k = 0; k < s.bins; ++k)
      r.psd[k] += col[k];
    segments += welch.column_segments(c);
  }
  s.segments = static_cast<double>(segments);
  for (std::size_t k = 0; k < s.bins; ++k) {
    const double one_sided = (k == 0 || 2 * k == s.length) ? 1.0 : 2.0;
    r.psd[k] *= one_sided * s.scale / s.segments;
  }
}

}  // namespace

RecordingAnalysis analyze_recording(SignalSource& source, const ListenOptions& options) {
  if (!(options.commanded_spindle_hz > 0.0))
    throw std::invalid_argument("analyze_recording: the commanded spindle speed must be > 0");
  if (options.teeth < 1)
    throw std::invalid_argument("analyze_recording: the tooth count must be ≥ 1");
  const SignalInfo& info = source.info();
  RecordingAnalysis r;
  r.sample_rate_hz = info.sample_rate_hz;
  r.spindle_hz_commanded = options.commanded_spindle_hz;
  r.spindle_hz_measured = options.commanded_spindle_hz;
  r.tooth_hz = options.commanded_spindle_hz * options.teeth;
  const double fs = info.sample_rate_hz;
  const double min_duration_s = shortest_recording_s(options);
  if (!can_judge_signal(info, min_duration_s, r))
    return r;

  // Stage 1: the one streaming pass, then the Welch PSD over the band.
  const std::size_t length = welch_segment_length(info, options);
  detail::WelchStream welch(length, spectrogram_column_cap(options, length / 2 + 1), kBlock);
  const StreamCounts counts = stream_into_welch(source, info, options, welch);
  if (!can_judge_stream(counts, welch, fs, length, min_duration_s, r))
    return r;
  Spectrum s = welch_psd(welch, fs, length, r);
  if (!choose_band(options, s, r))
    return r;
  const RecordingAnalysis read = r;  // stage 1's outcome, before any verdict
  const std::vector<char> comb = judge_spectrum(info, options, s, welch, r);

  // Air before or after the cut: judge the engaged stretch alone, when it
  // holds the Welch segments the floor's statistics need.
  const auto stretch =
      options.judge_engaged_stretch ? engaged_stretch(s, welch, comb, r) : std::nullopt;
  if (!stretch)
    return r;
  std::size_t segments = 0;
  for (std::size_t c = stretch->first; c <= stretch->second; ++c)
    segments += welch.column_segments(c);
  if (static_cast<double>(segments) < kMinSegments)
    return r;
  RecordingAnalysis engaged = read;
  engaged.engaged_start_s =
      info.start_s + static_cast<double>(welch.column_first_sample(stretch->first)) / fs;
  engaged.engaged_end_s = std::min(
      info.start_s + r.duration_s,
      info.start_s +
          static_cast<double>(welch.column_first_sample(stretch->second) +
                              welch.column_segments(stretch->second) * length / 2 + length / 2) /
              fs);
  stretch_psd(welch, stretch->first, stretch->second, s, engaged);
  judge_spectrum(info, options, s, welch, engaged);
  engaged.reason += fmt::format(
      "; judged from {:.2f} s to {:.2f} s, where the spindle's comb stands within 10 dB of its "
      "level in the cut (the rest is air)",
      *engaged.engaged_start_s, *engaged.engaged_end_s);
  return engaged;
}

}  // namespace robomill::monitoring
