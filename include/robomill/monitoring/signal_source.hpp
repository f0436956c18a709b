#pragma once
// A recorded or simulated signal read in blocks (issue 22): the detector
// (recording_analysis.hpp) pulls samples from a SignalSource so that memory
// does not grow with the recording's length. The readers of recorded files
// (io/recording.hpp: WAV/FLAC/AIFF, MATLAB, CSV, UFF58 time records)
// implement it at the edge; the core sees SI samples at a uniform rate.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace robomill::monitoring {

/// What the samples measure. Sound in Pa (a WAV's full scale is 1, an
/// uncalibrated pressure), the others in SI (m/s^2, m/s, m, N).
enum class SignalKind { sound, acceleration, velocity, displacement, force };
const char* signal_kind_name(SignalKind kind) noexcept;
/// The SI unit of a kind ("Pa", "m/s^2", "m/s", "m", "N").
const char* signal_kind_unit(SignalKind kind) noexcept;

struct SignalInfo {
  double sample_rate_hz = 0.0;
  /// Samples the source will deliver (after start/duration), or −1 when
  /// unknown until the end (a source that cannot count ahead; the CSV reader
  /// counts its rows when it opens the file).
  std::int64_t samples = -1;
  double start_s = 0.0;  ///< time of the first delivered sample in the recording
  SignalKind kind = SignalKind::sound;
  /// Full scale of the recording in SI units (a PCM file's ±1 times the
  /// file's scale): samples within 0.1 % of it count as clipped. 0: unknown
  /// (no clipping test).
  double full_scale = 0.0;
  std::string description;  ///< "file.wav, channel 1 of 2, 48000 Hz, PCM 24-bit"
};

/// A signal delivered in blocks, once, from start to end.
class SignalSource {
 public:
  virtual ~SignalSource() = default;
  virtual const SignalInfo& info() const = 0;
  /// Fills the front of `out` with the next samples (SI) and returns how many;
  /// 0 at the end. Throws robomill::InputError when the file turns out to be
  /// malformed part way (a truncated block, a NaN in a CSV row).
  virtual std::size_t read(std::span<double> out) = 0;
};

/// A signal held in memory (simulations, tests, NumPy arrays).
class VectorSource final : public SignalSource {
 public:
  VectorSource(std::vector<double> samples, double sample_rate_hz,
               SignalKind kind = SignalKind::displacement, double full_scale = 0.0);
  const SignalInfo& info() const override { return info_; }
  std::size_t read(std::span<double> out) override;

 private:
  std::vector<double> samples_;
  std::size_t next_ = 0;
  SignalInfo info_;
};

}  // namespace robomill::monitoring
