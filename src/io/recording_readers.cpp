// open_recording: picks the reader by format, and the helpers every reader
// shares (messages, the start/duration window, the uniform time base, the
// in-memory source). The readers themselves live in recording_sndfile.cpp,
// recording_mat.cpp, recording_csv.cpp and recording_uff.cpp.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <system_error>

#include "recording_detail.hpp"
#include "robomill/io/recording.hpp"

namespace robomill::io {
namespace recording_detail {

std::string file_name(const RecordingSpec& spec) {
  const std::string name = spec.file.filename().string();
  return name.empty() ? spec.file.string() : name;
}

void fail(const RecordingSpec& spec, const char* key, const std::string& message) {
  throw InputError((spec.path.empty() ? std::string("recording") : spec.path) + "." + key,
                   spec.line, message);
}

std::string number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", value);
  return buffer;
}

std::string seconds(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2f s", value);
  return buffer;
}

std::int64_t start_index(const RecordingSpec& spec, double rate_hz) {
  if (!std::isfinite(spec.start_s) || spec.start_s < 0.0)
    fail(spec, "start", "must be a time >= 0 s, got " + number(spec.start_s) + " s");
  const double index = std::round(spec.start_s * rate_hz);
  if (index > 9e18)
    fail(spec, "start",
         "start " + number(spec.start_s) + " s is past the end of " + file_name(spec));
  return static_cast<std::int64_t>(index);
}

std::int64_t duration_samples(const RecordingSpec& spec, double rate_hz) {
  if (!std::isfinite(spec.duration_s) || spec.duration_s < 0.0)
    fail(spec, "duration",
         "must be a time >= 0 s (0: to the end), got " + number(spec.duration_s) + " s");
  if (spec.duration_s == 0.0)
    return -1;
  const double count = std::round(spec.duration_s * rate_hz);
  if (count < 1.0)
    fail(spec, "duration",
         "duration " + number(spec.duration_s) + " s is shorter than one sample (" +
             number(rate_hz) + " Hz)");
  return count > 9e18 ? -1 : static_cast<std::int64_t>(count);
}

Window window(const RecordingSpec& spec, std::int64_t total, double rate_hz) {
  Window result;
  result.first = start_index(spec, rate_hz);
  if (result.first >= total)
    fail(spec, "start",
         "start " + number(spec.start_s) + " s is past the end of " + file_name(spec) + " (" +
             seconds(static_cast<double>(total) / rate_hz) + ")");
  result.count = total - result.first;
  if (const std::int64_t wanted = duration_samples(spec, rate_hz); wanted >= 0)
    result.count = std::min(result.count, wanted);
  return result;
}

void check_rate_agrees(const RecordingSpec& spec, double file_rate_hz) {
  if (spec.sample_rate_hz && std::abs(*spec.sample_rate_hz - file_rate_hz) > 1e-3 * file_rate_hz)
    fail(spec, "sample_rate",
         file_name(spec) + " is sampled at " + number(file_rate_hz) + " Hz, sample_rate says " +
             number(*spec.sample_rate_hz) + " Hz (leave it out to use the file's)");
}

double uniform_rate(const RecordingSpec& spec, std::span<const double> time, const char* key,
                    const std::string& what, std::int64_t first_number) {
  if (time.size() < 2)
    fail(spec, key,
         file_name(spec) + ": a time column needs at least 2 samples, got " +
             std::to_string(time.size()));
  for (std::size_t i = 0; i < time.size(); ++i) {
    if (!std::isfinite(time[i]))
      fail(spec, key,
           file_name(spec) + ": " + what + " " +
               std::to_string(static_cast<std::int64_t>(i) + first_number) +
               ": time is not a finite number");
  }
  const double interval = (time.back() - time.front()) / static_cast<double>(time.size() - 1);
  if (!(interval > 0.0) || !std::isfinite(interval))
    fail(spec, key,
         file_name(spec) + ": the time column must increase (from " + number(time.front()) +
             " s to " + number(time.back()) + " s)");
  for (std::size_t i = 1; i < time.size(); ++i) {
    if (const std::string problem =
            irregular_time_step(time[i], time[i] - time[i - 1], time.back() - time.front(),
                                static_cast<std::int64_t>(time.size() - 1));
        !problem.empty())
      fail(spec, key,
           file_name(spec) + ": " + what + " " +
               std::to_string(static_cast<std::int64_t>(i) + first_number) + ": " + problem);
  }
  return 1.0 / interval;
}

std::string irregular_time_step(double time_s, double step_s, double span_s, std::int64_t steps) {
  const double interval_s = span_s / static_cast<double>(steps);
  if (std::abs(step_s - interval_s) < 0.5 * interval_s)
    return {};
  const std::string what = "time " + number(time_s) + " s comes " + number(step_s) +
                           " s after the row before, where the whole column's mean interval is " +
                           number(interval_s) + " s";
  if (step_s > interval_s) {
    // The interval of the other steps: the gap's own length lengthens the
    // whole column's mean (a 100-sample gap in 3000 rows by 3 %).
    const double others_s =
        steps > 1 ? (span_s - step_s) / static_cast<double>(steps - 1) : interval_s;
    const double missing = std::round(step_s / (others_s > 0.0 ? others_s : interval_s)) - 1.0;
    return what + ": a gap in the uniform sampling (about " + number(std::max(1.0, missing)) +
           " sample(s) missing); cut the recording before or after it with start and duration, "
           "or resample it";
  }
  return what +
         ": the time repeats or goes back, which breaks the uniform sampling; give a "
         "uniform time column or resample the recording";
}

std::size_t MemorySource::read(std::span<double> out) {
  const std::size_t count = std::min(out.size(), samples_.size() - next_);
  std::copy_n(samples_.begin() + static_cast<std::ptrdiff_t>(next_), count, out.begin());
  next_ += count;
  if (next_ == samples_.size()) {
    // Delivered once: the memory goes back as soon as the end is reached.
    samples_ = {};
    next_ = 0;
  }
  return count;
}

std::unique_ptr<monitoring::SignalSource> memory_source(const RecordingSpec& spec,
                                                        std::vector<double> samples, double rate_hz,
                                                        double time0_s, std::string description,
                                                        double full_scale) {
  const Window cut = window(spec, static_cast<std::int64_t>(samples.size()), rate_hz);
  const auto first = static_cast<std::ptrdiff_t>(cut.first);
  samples.erase(samples.begin() + first + static_cast<std::ptrdiff_t>(cut.count), samples.end());
  samples.erase(samples.begin(), samples.begin() + first);
  samples.shrink_to_fit();
  for (double& value : samples) {
    value *= spec.scale;
    if (!std::isfinite(value))
      fail(spec, "file",
           file_name(spec) + ": a sample overflows after scaling by " + number(spec.scale));
  }
  monitoring::SignalInfo info;
  info.sample_rate_hz = rate_hz;
  info.samples = cut.count;
  info.start_s = time0_s + static_cast<double>(cut.first) / rate_hz;
  info.kind = spec.signal;
  info.full_scale = full_scale;
  info.description = std::move(description) + ", " + number(rate_hz) + " Hz, " +
                     seconds(static_cast<double>(cut.count) / rate_hz);
  return std::make_unique<MemorySource>(std::move(samples), std::move(info));
}

}  // namespace recording_detail

RecordingFormat recording_format_from_extension(const std::filesystem::path& file,
                                                const std::string& field, int line) {
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".wav" || extension == ".wave" || extension == ".flac" || extension == ".aif" ||
      extension == ".aiff" || extension == ".aifc" || extension == ".ogg" || extension == ".au" ||
      extension == ".w64" || extension == ".rf64")
    return RecordingFormat::sound_file;
  if (extension == ".mat")
    return RecordingFormat::mat;
  if (extension == ".csv" || extension == ".txt")
    return RecordingFormat::csv;
  if (extension == ".uff" || extension == ".unv" || extension == ".uf")
    return RecordingFormat::uff;
  throw InputError(field, line,
                   "cannot tell the format of " + file.filename().string() +
                       " from its extension '" + extension +
                       "' (known: .wav, .flac, .aiff, .mat, .csv, .uff, .unv); give `format: "
                       "wav|mat|csv|uff`");
}

std::unique_ptr<monitoring::SignalSource> open_recording(const RecordingSpec& spec) {
  using namespace recording_detail;
  if (!std::isfinite(spec.scale) || spec.scale == 0.0)
    fail(spec, "scale", "must be a finite, non-zero factor, got " + number(spec.scale));
  if (spec.sample_rate_hz &&
      (!std::isfinite(*spec.sample_rate_hz) || !(*spec.sample_rate_hz > 0.0)))
    fail(spec, "sample_rate",
         "must be a positive frequency, got " + number(*spec.sample_rate_hz) + " Hz");
  if (spec.channel < 0)
    fail(spec, "channel",
         "must be 1 or more (0: the mean of all channels), got " + std::to_string(spec.channel));
  std::error_code error;
  if (std::filesystem::is_directory(spec.file, error))
    fail(spec, "file", spec.file.string() + " is a folder, not a recording");
  if (!std::filesystem::exists(spec.file, error))
    fail(spec, "file", "no such file: " + spec.file.string());
  switch (spec.format) {
    case RecordingFormat::sound_file:
      return open_sound_file(spec);
    case RecordingFormat::mat:
      return open_mat(spec);
    case RecordingFormat::csv:
      return open_csv(spec);
    case RecordingFormat::uff:
      return open_uff(spec);
  }
  fail(spec, "format", "unknown recording format");
}

}  // namespace robomill::io
