// Stages 2 and 3 of the chatter detector (line_attribution.hpp): the line
// bins above the floor, the spindle measured from its comb, and every bin's
// cause (the method, the thresholds and the evidence behind them:
// docs/monitoring.md).

#include "line_attribution.hpp"

#include <cmath>

#include "robomill/monitoring/harmonic_comb.hpp"
#include "welch_stream.hpp"

namespace robomill::monitoring::detail {
namespace {

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
/// Without a measured comb the commanded speed places only its first 20
/// harmonics: a few % of speed error moves the k-th by k times as much. The
/// comb search scores 20 tooth harmonics (k to 20 N), at most this many.
constexpr int kUnrefinedHarmonics = 20;
constexpr int kMaxCoarseHarmonics = 160;
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
/// Welch's correlation of 50 %-overlapped Hann segments (Welch 1967): the
/// average of K segments has ν = 2K / (1 + 2 (1 − 1/K) ρ²) degrees of freedom.
constexpr double kHannOverlapCorrelation = 0.167;
/// Steady lines: judged only with this many spectrogram columns, and only
/// when the line's short-time power varies by less than this coefficient of
/// variation (a fan's or a pump's line; regenerative chatter is modulated).
constexpr std::size_t kSteadyMinColumns = 8;
constexpr double kSteadyMaxVariation = 0.1;

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

/// The frequency of the line peaking at bin k, refined by a parabola through
/// ln PSD at k − 1, k, k + 1 (at most half a bin from k).
double refined_psd_peak_hz(const std::vector<double>& psd, std::size_t k, double df) {
  const double left = std::log(std::max(psd[k - 1], 1e-300));
  const double centre = std::log(std::max(psd[k], 1e-300));
  const double right = std::log(std::max(psd[k + 1], 1e-300));
  const double curvature = left - 2.0 * centre + right;
  const double offset =
      curvature < 0.0 ? std::clamp(0.5 * (left - right) / curvature, -0.5, 0.5) : 0.0;
  return (static_cast<double>(k) + offset) * df;
}

// Lines set aside: the user's (by frequency and width) and the mains'.
// The spindle's comb is searched among all lines but the user's: a tooth
// harmonic may well sit on a mains harmonic (400 Hz at 12 000 rpm, 2 teeth).

/// A line of the user's `ignore` list holds frequency f.
bool is_ignored(const ListenOptions& options, double df, double f) {
  for (const IgnoredLine& line : options.ignore) {
    const double half = line.half_width_hz > 0.0 ? line.half_width_hz : kMainLobeBins * df;
    if (std::abs(f - line.frequency_hz) <= half)
      return true;
  }
  return false;
}

/// Why a line at frequency f is set aside: ignored, mains, or floor (it is not).
LineCause set_aside(const ListenOptions& options, const Spectrum& s, const LineBins& lines,
                    double f) {
  if (is_ignored(options, s.df, f))
    return LineCause::ignored;
  const auto k = static_cast<std::size_t>(std::llround(f / s.df));
  if (k < s.bins && lines.mains_bin[k])
    return LineCause::mains;
  return LineCause::floor;
}

/// Stage 2, a fundamental's comb score: Σ ln(PSD / line level) over its
/// first `harmonics` harmonics that exceed the line level (and are in the
/// band and not set aside); *count, when given, receives how many do. The
/// level at a harmonic is ln PSD interpolated there, or the highest of the
/// three nearest bins (the coarse search, whose grid may miss the peak).
double comb_score(const ListenOptions& options, const Spectrum& s, const LineBins& lines,
                  const std::vector<double>& psd, double f, int harmonics, bool interpolate,
                  int* count) {
  double score = 0.0;
  int found = 0;
  for (int k = 1; k <= harmonics; ++k) {
    const double fk = k * f;
    const double bin = fk / s.df;
    if (bin < static_cast<double>(s.first_bin) || bin > static_cast<double>(s.last_bin) - 1.0)
      continue;
    if (set_aside(options, s, lines, fk) != LineCause::floor)
      continue;
    const auto nearest = static_cast<std::size_t>(std::llround(bin));
    double level;
    if (interpolate) {
      level = log_psd_at(psd, bin);
    } else {
      level = -1e300;
      for (std::size_t j = nearest - 1; j <= nearest + 1; ++j)
        level = std::max(level, std::log(std::max(psd[j], 1e-300)));
    }
    const double above =
        level - std::log(std::max(lines.floor[nearest], 1e-300)) - lines.threshold_ln;
    if (above > 0.0) {
      score += above;
      ++found;
    }
  }
  if (count)
    *count = found;
  return score;
}

/// Stage 2, the coarse search's step: fine enough for the highest of its
/// harmonics to move by half a bin, at most 20 000 steps over the range.
double coarse_comb_step(double df, int coarse_harmonics, double search) {
  return std::max(df / (2.0 * coarse_harmonics), 2.0 * search / 20000.0);
}

/// Stage 2, the coarse search's outcome: the best fundamental, its score and
/// how many of its harmonics stand above the line level (0 when the comb
/// does not stand out).
struct CoarseComb {
  double best_f = 0.0;
  double best_score = -1.0;
  int count = 0;
};

/// Stage 2, the coarse search: the fundamental within f0 ± search whose low
/// harmonics stand highest above the floor.
CoarseComb coarse_comb_search(const ListenOptions& options, const Spectrum& s,
                              const LineBins& lines, const std::vector<double>& psd, double f0,
                              double search, int coarse_harmonics) {
  double best_f = f0, best_score = -1.0;
  std::vector<double> scores;
  {
    const double step = coarse_comb_step(s.df, coarse_harmonics, search);
    for (double f = f0 - search; f <= f0 + search + 0.5 * step; f += step) {
      const double score = comb_score(options, s, lines, psd, f, coarse_harmonics, false, nullptr);
      scores.push_back(score);
      if (score > best_score || (score == best_score && std::abs(f - f0) < std::abs(best_f - f0))) {
        best_score = score;
        best_f = f;
      }
    }
  }
  int comb_count = 0;
  comb_score(options, s, lines, psd, best_f, coarse_harmonics, false, &comb_count);
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
  const double coarse_step = coarse_comb_step(s.df, coarse_harmonics, search);
  if (search > 0.0 && std::abs(best_f - f0) > search - 2.0 * coarse_step)
    comb_count = 0;
  return {best_f, best_score, comb_count};
}

/// Stage 2, the refinement: each harmonic that stands above the line level
/// gives its peak frequency p_k (a parabola through ln PSD at the local
/// maximum); the least-squares fundamental of p_k = k f, weighted by the
/// line's height above the line level, leans on the high harmonics, where a
/// speed error shows k times larger. It proceeds in octaves (harmonics to
/// 5, 10, 20, ...), each from the previous estimate, so that the k-th
/// harmonic is looked for within a bin of where it is.
double refine_spindle(const ListenOptions& options, const Spectrum& s, const LineBins& lines,
                      const std::vector<double>& psd, double best_f, int fine_harmonics) {
  const double df = s.df;
  double estimate = best_f;
  for (int upto = std::min(5, fine_harmonics);; upto = std::min(2 * upto, fine_harmonics)) {
    double sum_kp = 0.0, sum_kk = 0.0;
    for (int k = 1; k <= upto; ++k) {
      const double fk = k * estimate;
      const double bin = fk / df;
      if (bin < static_cast<double>(s.first_bin) + 1.0 ||
          bin > static_cast<double>(s.last_bin) - 2.0)
        continue;
      if (is_ignored(options, df, fk))
        continue;
      auto peak = static_cast<std::size_t>(std::llround(bin));
      for (std::size_t j = peak - 1; j <= peak + 1; ++j)
        if (psd[j] > psd[peak])
          peak = j;
      if (psd[peak] < psd[peak - 1] || psd[peak] < psd[peak + 1])
        continue;  // the maximum is at the window's edge: not this harmonic's line
      const double height =
          std::log(psd[peak] / std::max(lines.floor[peak], 1e-300)) - lines.threshold_ln;
      if (!(height > 0.0))
        continue;
      const double pk = refined_psd_peak_hz(psd, peak, df);
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
  return estimate;
}

// The width of the run of line bins holding bin k: a line of a steady
// source fills the main lobe (5 bins); a chatter hump, broadened by the
// modulation of the cut, is wider.
std::size_t line_run_bins(const Spectrum& s, const LineBins& lines, std::size_t k) {
  std::size_t lo = k, hi = k;
  while (lo > s.first_bin && lines.in_line[lo - 1])
    --lo;
  while (hi < s.last_bin && lines.in_line[hi + 1])
    ++hi;
  return hi - lo + 1;
}

// Sidebands at the spindle's spacing: a vibration of the cut is modulated
// by the spindle's rotation (runout, the teeth's passing), so its lines
// come with neighbours at f ± j·f_spindle; an electrical or a fan's line
// does not. (In the Khasawneh chatter recordings every chatter line has
// them; the drives' lines of the stable ones have none.)
bool has_spindle_sidebands(const Spectrum& s, const SpindleComb& comb,
                           const std::vector<Peak>& peaks, const RecordingAnalysis& r,
                           std::size_t bin) {
  const double f = r.frequency_hz[bin];
  for (const Peak& q : peaks) {
    if (q.bin == bin)
      continue;
    const double delta = std::abs(r.frequency_hz[q.bin] - f);
    for (int j = 1; j <= 3; ++j)
      if (std::abs(delta - j * comb.spindle_hz) <= kMainLobeBins * s.df + j * comb.uncertainty_hz)
        return true;
  }
  return false;
}

/// Stage 3, mains-modulated combs at one mains frequency: sets aside every
/// chain of three or more candidate lines 2·mains apart (see
/// set_aside_mains_combs).
void set_aside_mains_chains(double mains, const Spectrum& s, const LineBins& lines,
                            const SpindleComb& comb, const std::vector<Peak>& peaks,
                            RecordingAnalysis& r) {
  const double tolerance = kMainLobeBins * s.df;
  const double spacing = 2.0 * mains;
  bool congruent = false;
  for (int j = 1; j <= 10 && !congruent; ++j) {
    const double m = std::round(j * r.tooth_hz / spacing);
    congruent = m >= 1 && std::abs(j * r.tooth_hz - m * spacing) <= tolerance;
  }
  if (congruent)
    return;
  std::vector<std::size_t> candidates;
  for (const Peak& p : peaks)
    if (r.cause[p.bin] == LineCause::chatter && line_run_bins(s, lines, p.bin) <= kNarrowLineBins &&
        !has_spindle_sidebands(s, comb, peaks, r, p.bin))
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

/// Stage 3, steady lines: the chatter-candidate line at bin f has
/// neighbours at the tooth spacing, f ± j·f_tooth or folded j·f_tooth − f (a
/// regenerative vibration is modulated by the tooth passing; a fan is not).
bool has_tooth_sidebands(const Spectrum& s, const std::vector<Peak>& peaks,
                         const RecordingAnalysis& r, std::size_t bin) {
  const double sideband_tolerance = kMainLobeBins * s.df;
  bool sidebands = false;
  const double f = r.frequency_hz[bin];
  for (const Peak& q : peaks) {
    if (q.bin == bin || r.cause[q.bin] != LineCause::chatter)
      continue;
    const double g = r.frequency_hz[q.bin];
    for (int j = 1; j <= 3 && !sidebands; ++j)
      sidebands = std::abs(std::abs(g - f) - j * r.tooth_hz) <= sideband_tolerance ||
                  std::abs(g + f - j * r.tooth_hz) <= sideband_tolerance;
    if (sidebands)
      break;
  }
  return sidebands;
}

}  // namespace

LineBins find_line_bins(const Spectrum& s, const std::vector<double>& psd) {
  const std::size_t first_bin = s.first_bin, last_bin = s.last_bin;
  const double segments = s.segments;
  LineBins lines;
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
  lines.line_ratio = std::pow((1.0 - a + z * std::sqrt(a)) / (1.0 - a), 3.0);
  lines.threshold_ln = std::log(lines.line_ratio);
  lines.floor = running_median(psd, first_bin, last_bin);
  const std::vector<double>& floor = lines.floor;
  lines.noise.assign(s.bins, 0.0);
  std::vector<double>& noise = lines.noise;
  for (std::size_t k = first_bin; k <= last_bin; ++k)
    noise[k] = floor[k] / median_to_mean;

  // Line bins: above the line level, extended along their skirts while above
  // the mean noise.
  lines.in_line.assign(s.bins, 0);
  std::vector<char>& in_line = lines.in_line;
  for (std::size_t k = first_bin; k <= last_bin; ++k)
    in_line[k] = psd[k] > lines.line_ratio * floor[k];
  for (std::size_t k = first_bin + 1; k <= last_bin; ++k)
    if (in_line[k - 1] && psd[k] > noise[k])
      in_line[k] = 1;
  for (std::size_t k = last_bin; k-- > first_bin;)
    if (in_line[k + 1] && psd[k] > noise[k])
      in_line[k] = 1;
  return lines;
}

// Mains lines: a line of the PSD whose peak (refined by a parabola through
// ln PSD) lies within 0.2 % of a 50 or 60 Hz harmonic — the grid holds its
// frequency to that — or a quarter bin. Its run of line bins (at most the
// main lobe each side) is set aside. Judged on the peak, not bin by bin: at
// a coarse resolution a band of ±2.5 bins around every 60 Hz harmonic
// would swallow half the spectrum (a 910 Hz chatter line 10 Hz from 900 Hz
// at 6 Hz resolution).
std::vector<char> mains_line_bins(const ListenOptions& options, const Spectrum& s,
                                  const LineBins& lines, const std::vector<double>& psd) {
  const double df = s.df;
  const double f0 = options.commanded_spindle_hz;
  const std::vector<char>& in_line = lines.in_line;
  std::vector<char> mains_bin(s.bins, 0);
  if (options.detect_mains) {
    for (std::size_t k = s.first_bin + 1; k < s.last_bin; ++k) {
      if (!in_line[k] || psd[k] < psd[k - 1] || psd[k] <= psd[k + 1])
        continue;
      const double f = refined_psd_peak_hz(psd, k, df);
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
      for (std::size_t j = k; j >= s.first_bin && j + reach >= k && in_line[j]; --j)
        mains_bin[j] = 1;
      for (std::size_t j = k; j <= s.last_bin && j <= k + reach && in_line[j]; ++j)
        mains_bin[j] = 1;
    }
  }
  return mains_bin;
}

// The spindle frequency: the fundamental within ±search whose harmonics
// stand highest above the floor (Σ ln(PSD / line level) over the harmonics
// that exceed it), first with the low harmonics on a coarse grid, then with
// all of them (to 200) near the best, where k·f moves k times faster.
SpindleComb measure_spindle(const ListenOptions& options, const Spectrum& s, const LineBins& lines,
                            RecordingAnalysis& r) {
  const double df = s.df;
  const double f0 = options.commanded_spindle_hz;
  SpindleComb comb;
  const double search = std::max(0.0, options.spindle_search_fraction) * f0;
  // The search scores the harmonics up to the 20th tooth harmonic: a
  // many-toothed cutter's comb is mostly its tooth harmonics (every N-th),
  // and a speed error shows k times larger at the k-th (issue 34: a 6-tooth
  // cut 2 % below its command, found only from its high tooth harmonics).
  const int teeth = std::max(1, options.teeth);
  const int in_band = static_cast<int>(s.band_high / f0);
  comb.coarse_harmonics =
      std::max(1, std::min({kUnrefinedHarmonics * teeth, kMaxCoarseHarmonics, in_band}));
  comb.fine_harmonics = std::max(1, std::min(200, in_band));
  const int coarse_harmonics = comb.coarse_harmonics, fine_harmonics = comb.fine_harmonics;
  if (options.tachometer_spindle_hz) {
    // Counted on a pulse channel over the whole stretch: known far better
    // than the spectrum's bins resolve it (taken as a refined comb's).
    r.spindle_hz_measured = *options.tachometer_spindle_hz;
    r.spindle_refined = true;
    r.spindle_source = "tachometer";
    comb.spindle_hz = r.spindle_hz_measured;
    r.tooth_hz = comb.spindle_hz * options.teeth;
    comb.uncertainty_hz = df / (2.0 * fine_harmonics);
    return comb;
  }
  const CoarseComb coarse =
      coarse_comb_search(options, s, lines, r.psd, f0, search, coarse_harmonics);
  const double coarse_step = coarse_comb_step(df, coarse_harmonics, search);
  // A comb: at least a quarter of its tooth harmonics (and 3) above the line
  // level; a few lines that a wrong fundamental happens to hit are not one.
  const int comb_needed = std::min(coarse_harmonics, std::max(3, coarse_harmonics / teeth / 4));
  if (coarse.count >= comb_needed && coarse.best_score > 0.0) {
    const double estimate = refine_spindle(options, s, lines, r.psd, coarse.best_f, fine_harmonics);
    // The refined speed must stay inside the search range (away from its
    // edges, as the coarse maximum must): one that runs to the edge followed
    // lines that are not the spindle's.
    if (!(search > 0.0 && std::abs(estimate - f0) > search - 2.0 * coarse_step)) {
      r.spindle_hz_measured = estimate;
      r.spindle_refined = true;
      r.spindle_source = "comb";
    }
  }
  comb.spindle_hz = r.spindle_hz_measured;
  r.tooth_hz = comb.spindle_hz * options.teeth;
  // The uncertainty of the refined fundamental, times k at the k-th harmonic.
  // Unrefined, the commanded speed is taken as exact to the coarse grid's
  // step (a tolerance of k × the search range would swallow the spectrum).
  comb.uncertainty_hz =
      r.spindle_refined ? df / (2.0 * fine_harmonics) : df / (2.0 * kUnrefinedHarmonics);
  return comb;
}

void attribute_bins(const ListenOptions& options, const Spectrum& s, const LineBins& lines,
                    const SpindleComb& comb, RecordingAnalysis& r) {
  const double df = s.df;
  const double spindle = comb.spindle_hz;
  r.cause.assign(s.bins, LineCause::below_band);
  std::vector<int> harmonic_of(s.bins, 0);
  for (std::size_t k = s.first_bin; k <= s.last_bin; ++k) {
    const double f = r.frequency_hz[k];
    const double k_guess = std::max(1.0, std::round(f / spindle));
    const double tolerance = kMainLobeBins * df + k_guess * comb.uncertainty_hz;
    int h = harmonic_number(f, spindle, tolerance);
    // Without a measured comb the commanded speed places only the low
    // harmonics: its error (an override, a slipping belt: a few %) moves the
    // k-th by k times as much, beyond a bin above the first tens.
    if (!r.spindle_refined && h > kUnrefinedHarmonics)
      h = 0;
    harmonic_of[k] = h;
    if (!lines.in_line[k]) {
      r.cause[k] = LineCause::floor;
      continue;
    }
    const LineCause aside = set_aside(options, s, lines, f);
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
}

// Period doubling with several teeth: without runout a flip chatter puts
// its power on the odd spindle harmonics (half the tooth frequency), which
// the comb would call runout. Runout modulates the tooth force by a
// fraction of it, so its lines hold less than the tooth harmonics; when
// the spindle-but-not-tooth harmonics hold more, they are chatter.
void reattribute_period_doubling(const ListenOptions& options, const Spectrum& s, LineBins& lines,
                                 RecordingAnalysis& r) {
  lines.doubled.assign(s.bins, 0);
  if (options.teeth > 1) {
    double spindle_power = 0.0, tooth_power = 0.0;
    for (std::size_t k = s.first_bin; k <= s.last_bin; ++k) {
      if (r.cause[k] == LineCause::spindle)
        spindle_power += excess_power(s, lines, r.psd, k);
      if (r.cause[k] == LineCause::tooth)
        tooth_power += excess_power(s, lines, r.psd, k);
    }
    if (spindle_power > tooth_power)
      for (std::size_t k = s.first_bin; k <= s.last_bin; ++k)
        if (r.cause[k] == LineCause::spindle) {
          r.cause[k] = LineCause::chatter;
          lines.doubled[k] = 1;
        }
  }
}

// The lines: local maxima of the line bins, power over the main lobe.
std::vector<Peak> find_line_peaks(const Spectrum& s, const LineBins& lines,
                                  const RecordingAnalysis& r) {
  const std::size_t first_bin = s.first_bin, last_bin = s.last_bin;
  const std::vector<char>& in_line = lines.in_line;
  std::vector<Peak> peaks;
  for (std::size_t k = first_bin + 1; k < last_bin; ++k) {
    if (!in_line[k] || r.psd[k] <= lines.line_ratio * lines.floor[k])
      continue;
    if (r.psd[k] < r.psd[k - 1] || r.psd[k] <= r.psd[k + 1])
      continue;
    double power = 0.0;
    for (std::size_t j = k - 2; j <= k + 2; ++j)
      if (j >= first_bin && j <= last_bin && in_line[j])
        power += excess_power(s, lines, r.psd, j);
    peaks.push_back({k, power});
  }
  return peaks;
}

// Mains-modulated combs: electrical lines of the drives (a motor's or an
// inverter's lines) are modulated at twice the mains frequency (rectified
// supply, magnetostriction) and appear as chains of lines exactly 100 or
// 120 Hz apart that do not move with the spindle (the Khasawneh turning
// recordings: 97 + m·120 Hz at 320 and at 425 rpm alike). A chain of three
// or more candidate lines on one residue modulo 2·f_mains is set aside,
// unless the tooth comb itself is congruent with that spacing (then the
// chain could be a chatter line's sidebands and the rule cannot tell).
void set_aside_mains_combs(const ListenOptions& options, const Spectrum& s, const LineBins& lines,
                           const SpindleComb& comb, const std::vector<Peak>& peaks,
                           RecordingAnalysis& r) {
  if (options.detect_mains) {
    for (double mains : {50.0, 60.0})
      set_aside_mains_chains(mains, s, lines, comb, peaks, r);
  }
}

// Steady lines: narrow chatter-candidate lines whose short-time power
// stays constant and that carry no sidebands at the tooth spacing (a
// regenerative vibration is modulated by the tooth passing; a fan is not).
void set_aside_steady_lines(const ListenOptions& options, const Spectrum& s, const LineBins& lines,
                            const std::vector<Peak>& peaks, const WelchStream& welch,
                            RecordingAnalysis& r) {
  const std::size_t columns = welch.columns();
  if (options.detect_steady_lines && columns >= kSteadyMinColumns) {
    for (const Peak& p : peaks) {
      if (r.cause[p.bin] != LineCause::chatter)
        continue;
      // Narrow: the run of line bins no wider than the main lobe.
      std::size_t lo = p.bin, hi = p.bin;
      while (lo > s.first_bin && lines.in_line[lo - 1])
        --lo;
      while (hi < s.last_bin && lines.in_line[hi + 1])
        ++hi;
      if (hi - lo + 1 > 2 * static_cast<std::size_t>(kMainLobeBins) + 1)
        continue;
      if (has_tooth_sidebands(s, peaks, r, p.bin))
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
}

// A line's skirts: the line bins extend from a peak while the PSD stays
// above the mean noise, beyond the main lobe that a forced or set-aside
// line is attributed by (a strong line's leakage reaches further). A
// chatter-candidate bin whose way uphill, within its run of line bins, ends
// on a peak of another cause is that line's skirt, not a line of its own:
// in a clean recording, where the floor is low, such skirts would otherwise
// be most of what is off the harmonics.
void give_skirts_to_their_peaks(const Spectrum& s, const LineBins& lines, RecordingAnalysis& r) {
  std::vector<LineCause> cause = r.cause;
  for (std::size_t k = s.first_bin; k <= s.last_bin; ++k) {
    if (r.cause[k] != LineCause::chatter || !lines.in_line[k])
      continue;
    std::size_t top = k;
    for (;;) {
      std::size_t next = top;
      if (top > s.first_bin && lines.in_line[top - 1] && r.psd[top - 1] > r.psd[next])
        next = top - 1;
      if (top < s.last_bin && lines.in_line[top + 1] && r.psd[top + 1] > r.psd[next])
        next = top + 1;
      if (next == top)
        break;
      top = next;
    }
    if (r.cause[top] != LineCause::chatter && r.cause[top] != LineCause::floor)
      cause[k] = r.cause[top];
  }
  r.cause = std::move(cause);
}

std::vector<char> narrow_comb_bins(const Spectrum& s, const LineBins& lines,
                                   const RecordingAnalysis& r) {
  std::vector<char> comb(s.bins, 0);
  for (std::size_t k = s.first_bin; k <= s.last_bin; ++k)
    comb[k] = (r.cause[k] == LineCause::spindle || r.cause[k] == LineCause::tooth) &&
              lines.in_line[k] && line_run_bins(s, lines, k) <= kNarrowLineBins;
  return comb;
}

}  // namespace robomill::monitoring::detail
