#pragma once
// Shared by the recording readers (recording_*.cpp), private to src/io: the
// error helper every reader raises through, the start/duration window, the
// in-memory source that MAT and UFF files deliver from, and the uniform-time
// check of a time column.

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "robomill/core/error.hpp"
#include "robomill/io/recording.hpp"

namespace robomill::io::recording_detail {

/// The file's name (no folder), as messages show it.
std::string file_name(const RecordingSpec& spec);

/// Throws InputError(spec.path + "." + key, spec.line, message). `key` is
/// "file", "channel", "variable", "column", "sample_rate", "start" or
/// "duration"; an empty spec.path gives "recording".
[[noreturn]] void fail(const RecordingSpec& spec, const char* key, const std::string& message);

/// A number for messages: up to 6 significant digits ("48000", "0.0001").
std::string number(double value);
/// "12.50 s".
std::string seconds(double value);

/// The samples to deliver out of `total` at `rate_hz`: spec.start_s skipped,
/// at most spec.duration_s kept (a longer duration stops at the end).
/// Throws (key "start") when the start lies at or past the end.
struct Window {
  std::int64_t first = 0;
  std::int64_t count = 0;
};
Window window(const RecordingSpec& spec, std::int64_t total, double rate_hz);
/// The sample index spec.start_s falls on (checked >= 0 and finite).
std::int64_t start_index(const RecordingSpec& spec, double rate_hz);
/// How many samples spec.duration_s asks for; -1 for "to the end".
std::int64_t duration_samples(const RecordingSpec& spec, double rate_hz);

/// When the job gives a sample rate and the file has its own time base, they
/// must agree (relative 1e-3); else InputError (key "sample_rate").
void check_rate_agrees(const RecordingSpec& spec, double file_rate_hz);

/// What is wrong with one step of a time column spanning `span_s` in `steps`
/// steps (its mean interval: span_s / steps), or "" when the step keeps the
/// sampling uniform. Rounding of the time (a DAQ export writing 7 decimals) and clock
/// jitter move a step by well under half an interval, and are accepted; a
/// dropped sample or block lengthens it by at least a whole interval, a
/// repeated or reversed time shortens it by at least half: those are refused.
std::string irregular_time_step(double time_s, double step_s, double span_s, std::int64_t steps);

/// The time base of `time` (seconds, one per sample): increasing, its rate
/// the whole column's mean interval, every step within half an interval of it
/// (irregular_time_step). Returns the sample rate, or throws (key `key`)
/// naming the first bad entry as "`what` N" (1-based, offset by
/// `first_number`).
double uniform_rate(const RecordingSpec& spec, std::span<const double> time, const char* key,
                    const std::string& what, std::int64_t first_number = 1);

/// Samples held in memory (a MAT variable, a UFF record), delivered in blocks.
class MemorySource final : public monitoring::SignalSource {
 public:
  MemorySource(std::vector<double> samples, monitoring::SignalInfo info)
      : samples_(std::move(samples)), info_(std::move(info)) {}
  const monitoring::SignalInfo& info() const override { return info_; }
  std::size_t read(std::span<double> out) override;

 private:
  std::vector<double> samples_;
  std::size_t next_ = 0;
  monitoring::SignalInfo info_;
};

/// Cuts `samples` (the whole recording at `rate_hz`, its first sample at
/// `time0_s`) to the spec's window, applies spec.scale and wraps it.
/// `description` gets ", N Hz, D s" appended.
std::unique_ptr<monitoring::SignalSource> memory_source(const RecordingSpec& spec,
                                                        std::vector<double> samples, double rate_hz,
                                                        double time0_s, std::string description,
                                                        double full_scale = 0.0);

std::unique_ptr<monitoring::SignalSource> open_sound_file(const RecordingSpec& spec);
std::unique_ptr<monitoring::SignalSource> open_mat(const RecordingSpec& spec);
std::unique_ptr<monitoring::SignalSource> open_csv(const RecordingSpec& spec);
std::unique_ptr<monitoring::SignalSource> open_uff(const RecordingSpec& spec);

}  // namespace robomill::io::recording_detail
