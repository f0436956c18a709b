// Throughput and memory of the recorded-signal chatter detector
// (monitoring::analyze_recording, `robomill listen`) — issue 22's yardstick:
// "a 10-minute, 48 kHz stereo recording analysed in under 3 s on two cores,
// memory flat in the recording's length".
//
//  * BM_ListenStereo/<minutes>: the two channels generated on the fly and
//    averaged into one stream (what `channel: mix` reads), so that the
//    figure is the detector's alone, with no file and no storage: 48 kHz,
//    a 3-tooth comb at 9000 rpm (10 harmonics), a chatter line, white noise
//    and a 50 Hz hum. 1 and 10 minutes: the peak RSS growth of the two shows
//    whether memory stays flat in the length.
//  * BM_ListenWavStereo/<minutes>: the same signal written once as a real
//    10-minute, 48 kHz, 16-bit stereo WAV (io::write_wav, ~115 MB in /tmp,
//    removed at exit), then io::open_recording (channel mix) +
//    analyze_recording over its first 1 or all 10 minutes: the file's
//    decoding included.
//
// Counters: items/s = samples of the analysed stream per second;
// elapsed_s = wall seconds per analysis; peak_rss_MB = the peak resident set
// over the run (the kernel's high-water mark reset first through
// /proc/self/clear_refs), peak_rss_growth_MB = that less the resident set
// before the run. Run one benchmark per process
// (--benchmark_filter=BM_ListenStereo/10) for the cleanest memory figures.

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "robomill/io/recording.hpp"
#include "robomill/monitoring/recording_analysis.hpp"
#include "robomill/monitoring/signal_source.hpp"

namespace {

using namespace robomill;
constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kRate = 48000.0;             // Hz
constexpr double kSpindleHz = 9000.0 / 60.0;  // 150 Hz: 320 samples per revolution
constexpr int kTeeth = 3;
constexpr int kHarmonics = 10;  // of the tooth frequency (450 Hz … 4.5 kHz)
constexpr double kChatterHz = 2317.3;
constexpr double kHumHz = 50.0;
constexpr std::size_t kRevolutionSamples = 320;  // 48 000 / 150

/// Two channels of a milling sound, generated sample by sample without
/// storage: the forced comb and the hum from one-period tables (both are
/// periodic in a whole number of samples), the chatter line from a rotating
/// phasor, the noise from a 64-bit LCG (a std::normal_distribution would
/// cost more than the analysis).
class StereoSynth {
 public:
  StereoSynth() {
    for (int c = 0; c < 2; ++c) {
      comb_[c].resize(kRevolutionSamples);
      for (std::size_t i = 0; i < kRevolutionSamples; ++i) {
        const double t = static_cast<double>(i) / kRate;
        double v = 0.0;
        for (int k = 1; k <= kHarmonics; ++k)
          v += (0.08 / k) * std::sin(kTwoPi * k * kTeeth * kSpindleHz * t + 0.7 * k + 1.3 * c);
        comb_[c][i] = v;
      }
      hum_[c].resize(static_cast<std::size_t>(kRate / kHumHz));
      for (std::size_t i = 0; i < hum_[c].size(); ++i)
        hum_[c][i] = 0.03 * std::sin(kTwoPi * kHumHz * static_cast<double>(i) / kRate + c);
    }
  }
  /// The next frame (left, right).
  void next(double& left, double& right) {
    const double chatter_re = re_, chatter_im = im_;
    // Rotate the chatter phasor; renormalize now and then against round-off.
    const double re = re_ * step_re_ - im_ * step_im_;
    im_ = re_ * step_im_ + im_ * step_re_;
    re_ = re;
    if ((++count_ & 0xffff) == 0) {
      const double norm = std::hypot(re_, im_);
      re_ /= norm;
      im_ /= norm;
    }
    const std::size_t comb = revolution_++;
    if (revolution_ == kRevolutionSamples)
      revolution_ = 0;
    const std::size_t hum = hum_index_++;
    if (hum_index_ == hum_[0].size())
      hum_index_ = 0;
    left = comb_[0][comb] + 0.15 * chatter_im + hum_[0][hum] + 0.05 * uniform();
    right = comb_[1][comb] + 0.12 * chatter_re + hum_[1][hum] + 0.05 * uniform();
  }

 private:
  /// Uniform in [-1, 1) from Knuth's MMIX LCG (the high bits).
  double uniform() {
    lcg_ = lcg_ * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(static_cast<std::int64_t>(lcg_) >> 11) * 0x1.0p-52;
  }
  std::vector<double> comb_[2], hum_[2];
  std::size_t revolution_ = 0, hum_index_ = 0;
  double re_ = 1.0, im_ = 0.0;
  const double step_re_ = std::cos(kTwoPi * kChatterHz / kRate);
  const double step_im_ = std::sin(kTwoPi * kChatterHz / kRate);
  std::uint64_t count_ = 0;
  std::uint64_t lcg_ = 0x853c49e6748fea9bULL;
};

/// `channel: mix` of the generated stereo signal: the mean of the two
/// channels, delivered in blocks as a file reader would, nothing stored.
class MixedSynthSource final : public monitoring::SignalSource {
 public:
  explicit MixedSynthSource(std::int64_t samples) : remaining_(samples) {
    info_.sample_rate_hz = kRate;
    info_.samples = samples;
    info_.kind = monitoring::SignalKind::sound;
    info_.description = "generated stereo, mixed";
  }
  const monitoring::SignalInfo& info() const override { return info_; }
  std::size_t read(std::span<double> out) override {
    const auto n = static_cast<std::size_t>(
        std::min<std::int64_t>(remaining_, static_cast<std::int64_t>(out.size())));
    double left = 0.0, right = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      synth_.next(left, right);
      out[i] = 0.5 * (left + right);
    }
    remaining_ -= static_cast<std::int64_t>(n);
    return n;
  }

 private:
  StereoSynth synth_;
  std::int64_t remaining_;
  monitoring::SignalInfo info_;
};

/// A field of /proc/self/status in kB (VmRSS, VmHWM); -1 when unreadable.
long status_kb(const std::string& field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind(field + ":", 0) == 0)
      return std::stol(line.substr(field.size() + 1));
  return -1;
}

/// Resets the kernel's peak-RSS mark to the current RSS (Linux ≥ 4.0), so
/// that the peak measured after a run is that run's.
void reset_peak_rss() {
  std::ofstream("/proc/self/clear_refs") << "5";
}

monitoring::ListenOptions listen_options() {
  monitoring::ListenOptions options;
  options.commanded_spindle_hz = kSpindleHz;
  options.teeth = kTeeth;
  return options;
}

/// One analysis per iteration; the verdict is checked so that a fast wrong
/// answer does not pass for speed.
template <typename MakeSource>
void run_listen(benchmark::State& state, std::int64_t samples, MakeSource make_source) {
  reset_peak_rss();
  const long rss_before = status_kb("VmRSS");
  double elapsed = 0.0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    auto source = make_source();
    const auto r = monitoring::analyze_recording(*source, listen_options());
    elapsed += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (r.verdict != monitoring::Verdict::chatter || std::abs(r.chatter_hz - kChatterHz) > 2.0) {
      state.SkipWithError(("unexpected verdict: " + r.reason).c_str());
      break;
    }
    benchmark::DoNotOptimize(r.chatter_energy_fraction);
  }
  const long peak = status_kb("VmHWM");
  state.SetItemsProcessed(state.iterations() * samples);
  state.counters["elapsed_s"] = benchmark::Counter(elapsed, benchmark::Counter::kAvgIterations);
  // Both: the growth alone can read 0 when an earlier run of the same
  // benchmark left the allocator's pages resident; the peak itself is what
  // must not grow from 1 to 10 minutes.
  if (rss_before >= 0 && peak >= 0) {
    state.counters["peak_rss_MB"] = static_cast<double>(peak) / 1024.0;
    state.counters["peak_rss_growth_MB"] = static_cast<double>(peak - rss_before) / 1024.0;
  }
}

void BM_ListenStereo(benchmark::State& state) {
  const std::int64_t samples = state.range(0) * 60 * static_cast<std::int64_t>(kRate);
  run_listen(state, samples, [&] { return std::make_unique<MixedSynthSource>(samples); });
}
BENCHMARK(BM_ListenStereo)->Arg(1)->Arg(10)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The 10-minute WAV, written once on first use and removed at exit.
struct WavFile {
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / "robomill_bench_listen_10min_48k_stereo.wav";
  WavFile() {
    const auto frames = static_cast<std::size_t>(10 * 60 * kRate);
    std::vector<std::vector<double>> channels(2, std::vector<double>(frames));
    StereoSynth synth;
    for (std::size_t i = 0; i < frames; ++i)
      synth.next(channels[0][i], channels[1][i]);
    io::write_wav(path, channels, kRate, 16, 1.0);
  }
  ~WavFile() {
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
  }
};

void BM_ListenWavStereo(benchmark::State& state) {
  static const WavFile wav;  // before the RSS baseline: its buffers are freed again
  const std::int64_t samples = state.range(0) * 60 * static_cast<std::int64_t>(kRate);
  io::RecordingSpec spec;
  spec.file = wav.path;
  spec.format = io::RecordingFormat::sound_file;
  spec.channel = 0;  // mix
  spec.duration_s = static_cast<double>(state.range(0)) * 60.0;
  run_listen(state, samples, [&] { return io::open_recording(spec); });
}
BENCHMARK(BM_ListenWavStereo)->Arg(1)->Arg(10)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
