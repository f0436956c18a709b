// The chatter verdict of a recorded (or simulated) signal
// (recording_analysis.hpp; the method, the thresholds and the evidence behind
// them: docs/monitoring.md).

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

#include "robomill/monitoring/harmonic_comb.hpp"
#include "welch_stream.hpp"

namespace robomill::monitoring {
namespace {

constexpr std::size_t kBlock = 65536;  // samples read at a time
/// Welch segment: at least this many bins between spindle harmonics, so that
/// the comb is resolved with room between its teeth for other lines.
constexpr double kBinsPerSpindleHarmonic = 32.0;
/// ... and at least 1 Hz: mains lines (held to 0.2 % by the grid) and lines
/// that stay put are told from the cut's by their frequency, which a coarser
/// grid blurs (a fast spindle's 32 bins per harmonic can be 6 Hz wide) ...
constexpr double kCoarsestResolutionHz = 1.0;
/// ... but at least this many segments over the recording (ν ≥ 2·3·0.95
/// degrees of freedom for the floor's statistics).
constexpr double kMinSegments = 3.0;
/// A bin is part of a line when its PSD exceeds the local floor by more than
/// noise would anywhere in the band with probability 1 % (Bonferroni: 0.01 /
/// the band's bins per bin): noise alone then shows no line in 99 of 100
/// recordings, and says "unknown".
constexpr double kFalseLineProbability = 0.01;

/// The one-sided standard normal quantile z with P(Z > z) = p (bisection on
/// erfc; p in (0, 0.5)).
double normal_quantile(double p) {
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}
/// A spindle comb's score (the harmonics' height above the line level) must
/// be this many times the median of the scores over the search range.
constexpr double kCombProminence = 3.0;
/// Hann main lobe: a line at a harmonic fills ±2 bins; 2.5 allows for the
/// harmonic lying between bins (as simulation::detect_chatter).
constexpr double kMainLobeBins = 2.5;
/// Mains: 50 and 60 Hz harmonics to the 10th (rectifiers and transformers
/// put their power in the low ones: 120 Hz dominates the Khasawneh
/// recordings), within ±0.2 % (the grid's frequency tolerance). Higher orders
/// are not set aside: every 50 or 60 Hz above 600 Hz would otherwise be a
/// blind spot, and chatter does fall there (the 1-DOF benchmark chatters at
/// 900 Hz = 15 × 60 Hz at 20 000 rpm).
constexpr int kMainsHarmonics = 10;
constexpr double kMainsTolerance = 0.002;
/// A narrow line: its run of line bins no wider than twice the main lobe.
constexpr std::size_t kNarrowLineBins = 10;
/// Clipping: samples within 0.1 % of full scale; more than 0.1 % of them and
/// the spectrum holds the clipping's harmonics, not the cut's.
constexpr double kClipLevel = 0.999;
constexpr double kMaxClippedFraction = 1e-3;
/// Welch's correlation of 50 %-overlapped Hann segments (Welch 1967): the
/// average of K segments has ν = 2K / (1 + 2 (1 − 1/K) ρ²) degrees of freedom.
constexpr double kHannOverlapCorrelation = 0.167;
/// Steady lines: judged only with this many spectrogram columns, and only
/// when the line's short-time power varies by less than this coefficient of
/// variation (a fan's or a pump's line; regenerative chatter is modulated).
constexpr std::size_t kSteadyMinColumns = 8;
constexpr double kSteadyMaxVariation = 0.1;
/// Onset: from the first frame whose chatter share exceeds the threshold and
/// after which at least this share of frames do (short dips allowed).
constexpr double kOnsetPersistence = 0.8;
/// Memory of the spectrogram at full resolution (doubles): the columns are
/// capped so that columns × bins stays below this (32 MB).
constexpr std::size_t kSpectrogramBudget = std::size_t{1} << 22;
/// The public spectrogram: at most this many frequency columns (bins averaged).
constexpr std::size_t kDisplayBins = 1024;

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

/// The running median of the PSD over half an octave each side (at least
/// ±16 bins): a robust local floor under the lines as long as lines hold
/// fewer than half the bins of the window — a comb with ≥ 32 bins between
/// its teeth, or a chatter hump narrower than the octave, leaves it alone.
std::vector<double> running_median(const std::vector<double>& psd, std::size_t first,
                                   std::size_t last) {
  std::vector<double> floor(psd.size(), 0.0);
  std::vector<double> scratch;
  scratch.reserve(psd.size());
  std::vector<std::size_t> anchors;
  std::vector<double> values;
  for (std::size_t k = first; k <= last;) {
    std::size_t lo = static_cast<std::size_t>(std::floor(static_cast<double>(k) / std::sqrt(2.0)));
    std::size_t hi = static_cast<std::size_t>(std::ceil(static_cast<double>(k) * std::sqrt(2.0)));
    lo = std::max(first, std::min(lo, k > 16 ? k - 16 : std::size_t{0}));
    hi = std::min(last, std::max(hi, k + 16));
    scratch.assign(psd.begin() + static_cast<std::ptrdiff_t>(lo),
                   psd.begin() + static_cast<std::ptrdiff_t>(hi + 1));
    const auto middle = scratch.begin() + static_cast<std::ptrdiff_t>(scratch.size() / 2);
    std::nth_element(scratch.begin(), middle, scratch.end());
    anchors.push_back(k);
    values.push_back(*middle);
    if (k == last)
      break;
    k = std::min(last, k + std::max<std::size_t>(1, (hi - lo) / 64));
  }
  for (std::size_t a = 0; a + 1 < anchors.size(); ++a)
    for (std::size_t k = anchors[a]; k <= anchors[a + 1]; ++k) {
      const double t =
          static_cast<double>(k - anchors[a]) / static_cast<double>(anchors[a + 1] - anchors[a]);
      floor[k] = values[a] + t * (values[a + 1] - values[a]);
    }
  if (anchors.size() == 1)
    floor[anchors[0]] = values[0];
  return floor;
}

/// Linear interpolation of ln PSD at a frequency between bins.
double log_psd_at(const std::vector<double>& psd, double bin) {
  const auto k = static_cast<std::size_t>(std::floor(bin));
  if (k + 1 >= psd.size())
    return std::log(std::max(psd.back(), 1e-300));
  const double t = bin - static_cast<double>(k);
  return (1.0 - t) * std::log(std::max(psd[k], 1e-300)) +
         t * std::log(std::max(psd[k + 1], 1e-300));
}

std::string hz_text(double hz) {
  return fmt::format("{:.4g} Hz", hz);
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
  if (!(fs > 0.0)) {
    r.reason = "the signal has no sample rate";
    return r;
  }
  // A sample rate below twice the tooth frequency cannot show the comb that
  // the forced response is recognised by (Nyquist).
  if (fs < 2.0 * r.tooth_hz) {
    r.reason = fmt::format(
        "the sample rate {} is below twice the tooth-passing frequency {}: the forced comb "
        "cannot be seen",
        hz_text(fs), hz_text(r.tooth_hz));
    return r;
  }
  const double revolution_s = 1.0 / options.commanded_spindle_hz;
  const double min_duration_s = options.min_revolutions * revolution_s;
  if (info.samples >= 0 && static_cast<double>(info.samples) / fs < min_duration_s) {
    r.duration_s = static_cast<double>(info.samples) / fs;
    r.reason =
        fmt::format("the recording ({:.3g} s) is shorter than {} spindle revolutions ({:.3g} s)",
                    r.duration_s, options.min_revolutions, min_duration_s);
    return r;
  }

  // The Welch segment: ≥ 32 bins per spindle harmonic, but ≥ 3 segments.
  const double wanted = std::max(kBinsPerSpindleHarmonic * fs / options.commanded_spindle_hz,
                                 fs / kCoarsestResolutionHz);
  std::size_t length = options.segment_s > 0.0
                           ? static_cast<std::size_t>(std::llround(options.segment_s * fs))
                           : static_cast<std::size_t>(std::ceil(wanted));
  length = smooth_length(length, true);
  if (info.samples > 0) {
    const auto cap =
        static_cast<std::size_t>(static_cast<double>(info.samples) / (0.5 * (kMinSegments + 1.0)));
    if (length > cap)
      length = smooth_length(cap, false);
  }
  const std::size_t bins = length / 2 + 1;
  const std::size_t max_columns = std::max<std::size_t>(
      2,
      std::min<std::size_t>(static_cast<std::size_t>(std::max(2, options.max_spectrogram_frames)),
                            kSpectrogramBudget / bins));

  // The one streaming pass.
  detail::WelchStream welch(length, max_columns, kBlock);
  std::size_t delivered = 0, clipped = 0, nonfinite = 0;
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
      nonfinite += bad;
      clipped += high;
      delivered += block.size();
      if (options.progress && info.samples > 0)
        options.progress(
            std::min(1.0, static_cast<double>(delivered) / static_cast<double>(info.samples)));
    }
  }
  welch.finish();
  r.duration_s = static_cast<double>(delivered) / fs;
  r.clipped_fraction = delivered > 0 ? static_cast<double>(clipped) / delivered : 0.0;
  if (nonfinite > 0) {
    r.reason = fmt::format("{} samples are not finite numbers", nonfinite);
    return r;
  }
  if (r.duration_s < min_duration_s) {
    r.reason =
        fmt::format("the recording ({:.3g} s) is shorter than {} spindle revolutions ({:.3g} s)",
                    r.duration_s, options.min_revolutions, min_duration_s);
    return r;
  }
  if (welch.segments() == 0) {
    r.reason =
        fmt::format("the recording ({:.3g} s) is shorter than one spectral segment ({:.3g} s)",
                    r.duration_s, static_cast<double>(length) / fs);
    return r;
  }

  // The Welch PSD, one-sided, signal unit²/Hz.
  const double df = fs / static_cast<double>(length);
  r.resolution_hz = df;
  const double segments = static_cast<double>(welch.segments());
  const double scale = 1.0 / (fs * welch.window_power());
  r.frequency_hz.resize(bins);
  r.psd.resize(bins);
  for (std::size_t k = 0; k < bins; ++k) {
    r.frequency_hz[k] = static_cast<double>(k) * df;
    const double one_sided = (k == 0 || 2 * k == length) ? 1.0 : 2.0;
    r.psd[k] = one_sided * scale * welch.periodogram_sum()[k] / segments;
  }
  const double band_low = options.band_low_hz > 0.0 ? options.band_low_hz : 3.0 * df;
  const double band_high =
      options.band_high_hz > 0.0 ? std::min(options.band_high_hz, 0.5 * fs) : 0.45 * fs;
  const auto first_bin = static_cast<std::size_t>(std::ceil(band_low / df));
  const auto last_bin = std::min(bins - 1, static_cast<std::size_t>(std::floor(band_high / df)));
  if (first_bin + 8 > last_bin) {
    r.reason = "the analysed band holds fewer than 8 bins";
    return r;
  }

  // The floor and the line threshold. The Welch average of K segments is
  // χ²_ν/ν distributed about the true PSD; the running median sits at its
  // median, (1 − 2/(9ν))³ of the mean (Wilson–Hilferty); a line is a bin
  // above the median by more than the 1e-4 quantile's ratio.
  const double nu =
      2.0 * segments /
      (1.0 + 2.0 * (1.0 - 1.0 / segments) * kHannOverlapCorrelation * kHannOverlapCorrelation);
  const double a = 2.0 / (9.0 * nu);
  const double median_to_mean = std::pow(1.0 - a, 3.0);
  const double z =
      normal_quantile(kFalseLineProbability / static_cast<double>(last_bin - first_bin + 1));
  const double line_ratio = std::pow((1.0 - a + z * std::sqrt(a)) / (1.0 - a), 3.0);
  const std::vector<double> floor = running_median(r.psd, first_bin, last_bin);
  std::vector<double> noise(bins, 0.0);
  for (std::size_t k = first_bin; k <= last_bin; ++k)
    noise[k] = floor[k] / median_to_mean;

  // Line bins: above the line level, extended along their skirts while above
  // the mean noise.
  std::vector<char> in_line(bins, 0);
  for (std::size_t k = first_bin; k <= last_bin; ++k)
    in_line[k] = r.psd[k] > line_ratio * floor[k];
  for (std::size_t k = first_bin + 1; k <= last_bin; ++k)
    if (in_line[k - 1] && r.psd[k] > noise[k])
      in_line[k] = 1;
  for (std::size_t k = last_bin; k-- > first_bin;)
    if (in_line[k + 1] && r.psd[k] > noise[k])
      in_line[k] = 1;

  // Mains lines: a line of the PSD whose peak (refined by a parabola through
  // ln PSD) lies within 0.2 % of a 50 or 60 Hz harmonic — the grid holds its
  // frequency to that — or a quarter bin. Its run of line bins (at most the
  // main lobe each side) is set aside. Judged on the peak, not bin by bin: at
  // a coarse resolution a band of ±2.5 bins around every 60 Hz harmonic
  // would swallow half the spectrum (a 910 Hz chatter line 10 Hz from 900 Hz
  // at 6 Hz resolution).
  const double f0 = options.commanded_spindle_hz;
  std::vector<char> mains_bin(bins, 0);
  const auto refined_peak_hz = [&](std::size_t k) {
    const double left = std::log(std::max(r.psd[k - 1], 1e-300));
    const double centre = std::log(std::max(r.psd[k], 1e-300));
    const double right = std::log(std::max(r.psd[k + 1], 1e-300));
    const double curvature = left - 2.0 * centre + right;
    const double offset =
        curvature < 0.0 ? std::clamp(0.5 * (left - right) / curvature, -0.5, 0.5) : 0.0;
    return (static_cast<double>(k) + offset) * df;
  };
  if (options.detect_mains) {
    for (std::size_t k = first_bin + 1; k < last_bin; ++k) {
      if (!in_line[k] || r.psd[k] < r.psd[k - 1] || r.psd[k] <= r.psd[k + 1])
        continue;
      const double f = refined_peak_hz(k);
      bool mains = false;
      for (double base : {50.0, 60.0}) {
        const double m = std::round(f / base);
        mains = mains || (m >= 1 && m <= kMainsHarmonics &&
                          std::abs(f - m * base) <= std::max(kMainsTolerance * f, 0.25 * df));
      }
      // ... unless it is also a harmonic of the commanded spindle speed to
      // within a quarter bin: then the comb explains it (400 Hz at
      // 12 000 rpm is 8 × 50 Hz and the second tooth harmonic).
      const double h = std::round(f / f0);
      if (!mains || (h >= 1 && std::abs(f - h * f0) <= 0.25 * df))
        continue;
      const auto reach = static_cast<std::size_t>(kMainLobeBins) + 1;
      for (std::size_t j = k; j >= first_bin && j + reach >= k && in_line[j]; --j)
        mains_bin[j] = 1;
      for (std::size_t j = k; j <= last_bin && j <= k + reach && in_line[j]; ++j)
        mains_bin[j] = 1;
    }
  }
  // Lines set aside: the user's (by frequency and width) and the mains'.
  // The spindle's comb is searched among all lines but the user's: a tooth
  // harmonic may well sit on a mains harmonic (400 Hz at 12 000 rpm, 2 teeth).
  const auto is_ignored = [&](double f) {
    for (const IgnoredLine& line : options.ignore) {
      const double half = line.half_width_hz > 0.0 ? line.half_width_hz : kMainLobeBins * df;
      if (std::abs(f - line.frequency_hz) <= half)
        return true;
    }
    return false;
  };
  const auto set_aside = [&](double f) -> LineCause {
    if (is_ignored(f))
      return LineCause::ignored;
    const auto k = static_cast<std::size_t>(std::llround(f / df));
    if (k < bins && mains_bin[k])
      return LineCause::mains;
    return LineCause::floor;
  };

  // The spindle frequency: the fundamental within ±search whose harmonics
  // stand highest above the floor (Σ ln(PSD / line level) over the harmonics
  // that exceed it), first with the low harmonics on a coarse grid, then with
  // all of them (to 200) near the best, where k·f moves k times faster.
  const double threshold_ln = std::log(line_ratio);
  const auto comb_score = [&](double f, int harmonics, bool interpolate, int* count) {
    double score = 0.0;
    int found = 0;
    for (int k = 1; k <= harmonics; ++k) {
      const double fk = k * f;
      const double bin = fk / df;
      if (bin < static_cast<double>(first_bin) || bin > static_cast<double>(last_bin) - 1.0)
        continue;
      if (set_aside(fk) != LineCause::floor)
        continue;
      const auto nearest = static_cast<std::size_t>(std::llround(bin));
      double level;
      if (interpolate) {
        level = log_psd_at(r.psd, bin);
      } else {
        level = -1e300;
        for (std::size_t j = nearest - 1; j <= nearest + 1; ++j)
          level = std::max(level, std::log(std::max(r.psd[j], 1e-300)));
      }
      const double above = level - std::log(std::max(floor[nearest], 1e-300)) - threshold_ln;
      if (above > 0.0) {
        score += above;
        ++found;
      }
    }
    if (count)
      *count = found;
    return score;
  };
  const double search = std::max(0.0, options.spindle_search_fraction) * f0;
  const int coarse_harmonics = std::max(1, std::min(20, static_cast<int>(band_high / f0)));
  const int fine_harmonics = std::max(1, std::min(200, static_cast<int>(band_high / f0)));
  double best_f = f0, best_score = -1.0;
  std::vector<double> scores;
  {
    const double step = std::max(df / (2.0 * coarse_harmonics), 2.0 * search / 20000.0);
    for (double f = f0 - search; f <= f0 + search + 0.5 * step; f += step) {
      const double score = comb_score(f, coarse_harmonics, false, nullptr);
      scores.push_back(score);
      if (score > best_score || (score == best_score && std::abs(f - f0) < std::abs(best_f - f0))) {
        best_score = score;
        best_f = f;
      }
    }
  }
  int comb_count = 0;
  comb_score(best_f, coarse_harmonics, false, &comb_count);
  // A comb stands out: a spectrum full of unrelated lines (drives, a
  // structure's modes) lets many fundamentals hit a few of them, so the best
  // must also score several times what a typical fundamental of the search
  // range does (the median), or the commanded speed stands.
  if (!scores.empty()) {
    const auto at = scores.begin() + static_cast<std::ptrdiff_t>(0.5 * (scores.size() - 1));
    std::nth_element(scores.begin(), at, scores.end());
    if (best_score < kCombProminence * *at)
      comb_count = 0;
  }
  // A best fundamental at the edge of the search range is the tail of a
  // slope, not a comb's maximum (a recording whose lines are not the
  // spindle's pulls it there): the commanded speed stands.
  const double coarse_step = std::max(df / (2.0 * coarse_harmonics), 2.0 * search / 20000.0);
  if (search > 0.0 && std::abs(best_f - f0) > search - 2.0 * coarse_step)
    comb_count = 0;
  // A comb: at least a quarter of the low harmonics (and 3) above the line
  // level; a few lines that a wrong fundamental happens to hit are not one.
  const int comb_needed = std::min(coarse_harmonics, std::max(3, coarse_harmonics / 4));
  if (comb_count >= comb_needed && best_score > 0.0) {
    // Refinement: each harmonic that stands above the line level gives its
    // peak frequency p_k (a parabola through ln PSD at the local maximum);
    // the least-squares fundamental of p_k = k f, weighted by the line's
    // height above the line level, leans on the high harmonics, where a
    // speed error shows k times larger. It proceeds in octaves (harmonics to
    // 5, 10, 20, ...), each from the previous estimate, so that the k-th
    // harmonic is looked for within a bin of where it is.
    double estimate = best_f;
    for (int upto = std::min(5, fine_harmonics);; upto = std::min(2 * upto, fine_harmonics)) {
      double sum_kp = 0.0, sum_kk = 0.0;
      for (int k = 1; k <= upto; ++k) {
        const double fk = k * estimate;
        const double bin = fk / df;
        if (bin < static_cast<double>(first_bin) + 1.0 || bin > static_cast<double>(last_bin) - 2.0)
          continue;
        if (is_ignored(fk))
          continue;
        auto peak = static_cast<std::size_t>(std::llround(bin));
        for (std::size_t j = peak - 1; j <= peak + 1; ++j)
          if (r.psd[j] > r.psd[peak])
            peak = j;
        if (r.psd[peak] < r.psd[peak - 1] || r.psd[peak] < r.psd[peak + 1])
          continue;  // the maximum is at the window's edge: not this harmonic's line
        const double height = std::log(r.psd[peak] / std::max(floor[peak], 1e-300)) - threshold_ln;
        if (!(height > 0.0))
          continue;
        const double pk = refined_peak_hz(peak);
        if (std::abs(pk - fk) > df)
          continue;  // a neighbouring line's peak, not this harmonic's
        sum_kp += height * k * pk;
        sum_kk += height * static_cast<double>(k) * k;
      }
      if (sum_kk > 0.0)
        estimate = sum_kp / sum_kk;
      if (upto == fine_harmonics)
        break;
    }
    // The refined speed must stay inside the search range (away from its
    // edges, as the coarse maximum must): one that runs to the edge followed
    // lines that are not the spindle's.
    if (!(search > 0.0 && std::abs(estimate - f0) > search - 2.0 * coarse_step)) {
      r.spindle_hz_measured = estimate;
      r.spindle_refined = true;
    }
  }
  const double spindle = r.spindle_hz_measured;
  r.tooth_hz = spindle * options.teeth;
  // The uncertainty of the refined fundamental, times k at the k-th harmonic.
  // Unrefined, the commanded speed is taken as exact to the coarse grid's
  // step (a tolerance of k × the search range would swallow the spectrum).
  const double spindle_uncertainty =
      r.spindle_refined ? df / (2.0 * fine_harmonics) : df / (2.0 * coarse_harmonics);

  // Each bin's cause.
  r.cause.assign(bins, LineCause::below_band);
  std::vector<int> harmonic_of(bins, 0);
  for (std::size_t k = first_bin; k <= last_bin; ++k) {
    const double f = r.frequency_hz[k];
    const double k_guess = std::max(1.0, std::round(f / spindle));
    const double tolerance = kMainLobeBins * df + k_guess * spindle_uncertainty;
    int h = harmonic_number(f, spindle, tolerance);
    // Without a measured comb the commanded speed places only the low
    // harmonics: its error (an override, a slipping belt: a few %) moves the
    // k-th by k times as much, beyond a bin above the first tens.
    if (!r.spindle_refined && h > coarse_harmonics)
      h = 0;
    harmonic_of[k] = h;
    if (!in_line[k]) {
      r.cause[k] = LineCause::floor;
      continue;
    }
    const LineCause aside = set_aside(f);
    if (h > 0 && aside != LineCause::floor && !r.spindle_refined) {
      // On a harmonic of the commanded speed and on a line set aside (a mains
      // harmonic, an ignored line): without a measured comb the set-aside line
      // is the likelier (the Khasawneh stable recordings' 120 Hz mains is
      // 0.4 Hz from 17 × 7.083 Hz). With a measured comb the harmonic is
      // forced (400 Hz at 12 000 rpm with 2 teeth is a tooth harmonic, not
      // 8 × 50 Hz); a mains line hidden under it then counts as forced,
      // which errs towards "stable".
      r.cause[k] = aside;
      continue;
    }
    if (h > 0) {
      r.cause[k] = h % options.teeth == 0 ? LineCause::tooth : LineCause::spindle;
      continue;
    }
    r.cause[k] = aside != LineCause::floor ? aside : LineCause::chatter;
  }
  const auto excess = [&](std::size_t k) { return std::max(0.0, r.psd[k] - noise[k]) * df; };

  // Period doubling with several teeth: without runout a flip chatter puts
  // its power on the odd spindle harmonics (half the tooth frequency), which
  // the comb would call runout. Runout modulates the tooth force by a
  // fraction of it, so its lines hold less than the tooth harmonics; when
  // the spindle-but-not-tooth harmonics hold more, they are chatter.
  if (options.teeth > 1) {
    double spindle_power = 0.0, tooth_power = 0.0;
    for (std::size_t k = first_bin; k <= last_bin; ++k) {
      if (r.cause[k] == LineCause::spindle)
        spindle_power += excess(k);
      if (r.cause[k] == LineCause::tooth)
        tooth_power += excess(k);
    }
    if (spindle_power > tooth_power)
      for (std::size_t k = first_bin; k <= last_bin; ++k)
        if (r.cause[k] == LineCause::spindle)
          r.cause[k] = LineCause::chatter;
  }

  // The lines: local maxima of the line bins, power over the main lobe.
  struct Peak {
    std::size_t bin;
    double power;
  };
  std::vector<Peak> peaks;
  for (std::size_t k = first_bin + 1; k < last_bin; ++k) {
    if (!in_line[k] || r.psd[k] <= line_ratio * floor[k])
      continue;
    if (r.psd[k] < r.psd[k - 1] || r.psd[k] <= r.psd[k + 1])
      continue;
    double power = 0.0;
    for (std::size_t j = k - 2; j <= k + 2; ++j)
      if (j >= first_bin && j <= last_bin && in_line[j])
        power += excess(j);
    peaks.push_back({k, power});
  }

  // The width of the run of line bins holding bin k: a line of a steady
  // source fills the main lobe (5 bins); a chatter hump, broadened by the
  // modulation of the cut, is wider.
  const auto line_run_bins = [&](std::size_t k) {
    std::size_t lo = k, hi = k;
    while (lo > first_bin && in_line[lo - 1])
      --lo;
    while (hi < last_bin && in_line[hi + 1])
      ++hi;
    return hi - lo + 1;
  };

  // Sidebands at the spindle's spacing: a vibration of the cut is modulated
  // by the spindle's rotation (runout, the teeth's passing), so its lines
  // come with neighbours at f ± j·f_spindle; an electrical or a fan's line
  // does not. (In the Khasawneh chatter recordings every chatter line has
  // them; the drives' lines of the stable ones have none.)
  const auto has_spindle_sidebands = [&](std::size_t bin) {
    const double f = r.frequency_hz[bin];
    for (const Peak& q : peaks) {
      if (q.bin == bin)
        continue;
      const double delta = std::abs(r.frequency_hz[q.bin] - f);
      for (int j = 1; j <= 3; ++j)
        if (std::abs(delta - j * spindle) <= kMainLobeBins * df + j * spindle_uncertainty)
          return true;
    }
    return false;
  };

  // Mains-modulated combs: electrical lines of the drives (a motor's or an
  // inverter's lines) are modulated at twice the mains frequency (rectified
  // supply, magnetostriction) and appear as chains of lines exactly 100 or
  // 120 Hz apart that do not move with the spindle (the Khasawneh turning
  // recordings: 97 + m·120 Hz at 320 and at 425 rpm alike). A chain of three
  // or more candidate lines on one residue modulo 2·f_mains is set aside,
  // unless the tooth comb itself is congruent with that spacing (then the
  // chain could be a chatter line's sidebands and the rule cannot tell).
  if (options.detect_mains) {
    const double tolerance = kMainLobeBins * df;
    for (double mains : {50.0, 60.0}) {
      const double spacing = 2.0 * mains;
      bool congruent = false;
      for (int j = 1; j <= 10 && !congruent; ++j) {
        const double m = std::round(j * r.tooth_hz / spacing);
        congruent = m >= 1 && std::abs(j * r.tooth_hz - m * spacing) <= tolerance;
      }
      if (congruent)
        continue;
      std::vector<std::size_t> candidates;
      for (const Peak& p : peaks)
        if (r.cause[p.bin] == LineCause::chatter && line_run_bins(p.bin) <= kNarrowLineBins &&
            !has_spindle_sidebands(p.bin))
          candidates.push_back(p.bin);
      std::vector<char> used(candidates.size(), 0);
      for (std::size_t i = 0; i < candidates.size(); ++i) {
        if (used[i])
          continue;
        std::vector<std::size_t> chain{i};
        const double f = r.frequency_hz[candidates[i]];
        for (std::size_t j = i + 1; j < candidates.size(); ++j) {
          const double delta = std::abs(r.frequency_hz[candidates[j]] - f);
          const double m = std::round(delta / spacing);
          if (!used[j] && m >= 1 && std::abs(delta - m * spacing) <= tolerance)
            chain.push_back(j);
        }
        if (chain.size() < 3)
          continue;
        for (std::size_t c : chain) {
          used[c] = 1;
          // The line's main lobe.
          for (std::size_t k = candidates[c] - 2; k <= candidates[c] + 2; ++k)
            if (r.cause[k] == LineCause::chatter)
              r.cause[k] = LineCause::mains;
        }
      }
    }
  }

  // Steady lines: narrow chatter-candidate lines whose short-time power
  // stays constant and that carry no sidebands at the tooth spacing (a
  // regenerative vibration is modulated by the tooth passing; a fan is not).
  const std::size_t columns = welch.columns();
  if (options.detect_steady_lines && columns >= kSteadyMinColumns) {
    const double sideband_tolerance = kMainLobeBins * df;
    for (const Peak& p : peaks) {
      if (r.cause[p.bin] != LineCause::chatter)
        continue;
      // Narrow: the run of line bins no wider than the main lobe.
      std::size_t lo = p.bin, hi = p.bin;
      while (lo > first_bin && in_line[lo - 1])
        --lo;
      while (hi < last_bin && in_line[hi + 1])
        ++hi;
      if (hi - lo + 1 > 2 * static_cast<std::size_t>(kMainLobeBins) + 1)
        continue;
      bool sidebands = false;
      const double f = r.frequency_hz[p.bin];
      for (const Peak& q : peaks) {
        if (q.bin == p.bin || r.cause[q.bin] != LineCause::chatter)
          continue;
        const double g = r.frequency_hz[q.bin];
        for (int j = 1; j <= 3 && !sidebands; ++j)
          sidebands = std::abs(std::abs(g - f) - j * r.tooth_hz) <= sideband_tolerance ||
                      std::abs(g + f - j * r.tooth_hz) <= sideband_tolerance;
        if (sidebands)
          break;
      }
      if (sidebands)
        continue;
      double sum = 0.0, sum_sq = 0.0;
      for (std::size_t c = 0; c < columns; ++c) {
        const double* col = welch.column(c);
        double power = 0.0;
        for (std::size_t j = lo; j <= hi; ++j)
          power += col[j];
        power /= static_cast<double>(welch.column_segments(c));
        sum += power;
        sum_sq += power * power;
      }
      const double mean = sum / static_cast<double>(columns);
      const double variance = std::max(0.0, sum_sq / static_cast<double>(columns) - mean * mean);
      if (mean > 0.0 && std::sqrt(variance) / mean < kSteadyMaxVariation)
        for (std::size_t j = lo; j <= hi; ++j)
          r.cause[j] = LineCause::steady_line;
    }
  }

  // The energies.
  double forced = 0.0, chatter = 0.0, aside = 0.0, total = 0.0, lines_total = 0.0;
  for (std::size_t k = first_bin; k <= last_bin; ++k) {
    total += r.psd[k] * df;
    if (r.cause[k] == LineCause::floor)
      continue;
    const double e = excess(k);
    lines_total += e;
    switch (r.cause[k]) {
      case LineCause::spindle:
      case LineCause::tooth:
        forced += e;
        break;
      case LineCause::chatter:
        chatter += e;
        break;
      default:
        aside += e;
    }
  }
  // The fractions are of everything the sensor recorded in the band (they
  // add up to one): chatter, forced lines, lines set aside, the broadband
  // floor. The verdict asks chatter evidence to outweigh all the rest, as an
  // operator hears chatter when it drowns the cut's other sounds (003 §4:
  // the robot's modes "outweigh" the spindle frequency). Weighed against the
  // forced comb alone, a turning cut, whose forced comb is weak, would be
  // called chatter for a few of the drives' lines (the Khasawneh stable
  // recordings: 58 % and 72 % of the non-mains power sit in such lines, 17 %
  // and 22 % of the total). Lines set aside are never chatter evidence, but
  // they are what the sensor heard: a hum louder than the chatter leaves the
  // cut "stable" (docs/monitoring.md, limits).
  if (total > 0.0) {
    r.chatter_energy_fraction = chatter / total;
    r.forced_energy_fraction = forced / total;
    r.ignored_energy_fraction = aside / total;
    r.floor_energy_fraction = std::max(0.0, total - lines_total) / total;
  }

  // The lines, strongest first, and the chatter family: the strongest
  // chatter line and its sidebands fc ± j·f_tooth.
  std::sort(peaks.begin(), peaks.end(),
            [](const Peak& x, const Peak& y) { return x.power > y.power; });
  for (const Peak& p : peaks)
    if (r.lines.size() < 200)
      r.lines.push_back({r.frequency_hz[p.bin], p.power, r.cause[p.bin]});
  {
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

  // The spectrogram and each frame's chatter share (the same causes, the
  // frame's own power above the mean noise).
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
    const double norm = scale / static_cast<double>(welch.column_segments(c));
    r.spectrogram_time_s[c] = info.start_s + static_cast<double>(welch.column_first_sample(c)) / fs;
    for (std::size_t d = 0; d < display_bins; ++d) {
      const std::size_t from = d * group, to = std::min(bins, from + group);
      double sum = 0.0;
      for (std::size_t k = from; k < to; ++k)
        sum += (k == 0 || 2 * k == length ? 1.0 : 2.0) * norm * col[k];
      r.spectrogram_psd[c * display_bins + d] = sum / static_cast<double>(to - from);
    }
    // The frame's chatter share, as the verdict's: the chatter lines' power
    // above the noise over the frame's power in the band.
    double frame_cut = 0.0, frame_chatter = 0.0;
    for (std::size_t k = first_bin; k <= last_bin; ++k) {
      const double p = 2.0 * norm * col[k];
      frame_cut += p;
      if (r.cause[k] == LineCause::chatter)
        frame_chatter += std::max(0.0, p - noise[k]);
    }
    r.frame_chatter_fraction[c] = frame_cut > 0.0 ? frame_chatter / frame_cut : 0.0;
  }

  // The verdict.
  const double threshold = options.chatter_energy_threshold;
  const std::string spindle_text =
      r.spindle_refined
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
    return r;
  }
  if (forced + chatter <= 0.0) {
    r.verdict = Verdict::unknown;
    r.reason = fmt::format(
        "no spindle, tooth or chatter line rises above the floor ({}): the signal cannot decide",
        spindle_text);
    return r;
  }
  if (r.chatter_energy_fraction > threshold) {
    r.verdict = Verdict::chatter;
    r.reason = fmt::format(
        "chatter at {}: lines off the spindle's harmonics and not set aside hold {:.1f} % of the "
        "recorded power (threshold {:.0f} %); {}",
        hz_text(r.chatter_hz), 100.0 * r.chatter_energy_fraction, 100.0 * threshold, spindle_text);
    // The onset: the first frame from which the share stays above the
    // threshold (at least kOnsetPersistence of the later frames).
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
  } else {
    r.verdict = Verdict::stable;
    r.reason = fmt::format(
        "stable: chatter evidence holds {:.1f} % of the recorded power (threshold {:.0f} %; the "
        "spindle's and the teeth's harmonics {:.1f} %); {}",
        100.0 * r.chatter_energy_fraction, 100.0 * threshold, 100.0 * r.forced_energy_fraction,
        spindle_text);
  }
  return r;
}

}  // namespace robomill::monitoring
