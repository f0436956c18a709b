#pragma once
// Readers of recorded signals (issue 22, docs/monitoring.md), parsing at the
// edge: each opens a file and delivers one channel as SI samples in blocks
// (monitoring::SignalSource), so memory does not grow with the recording.
//  * wav/flac/aiff (libsndfile): any channel count; 16/24/32-bit integer and
//    float PCM; integer PCM scaled to ±1 full scale, times `scale`.
//  * mat (matio): MATLAB v5 and v7.3; the named `variable` (or the only
//    numeric one) is a [time, value...] matrix (time column 1, `column`
//    picks the value column, default 2) or a vector with `sample_rate`.
//  * csv: a header row; a time column (`t_s`, `time`, `time_s`, or the first
//    column when it is named so) or `sample_rate`; `column` names the value
//    column (default: the first that is not time). Streamed row by row.
//  * uff: UFF58 time records (function type 1) with the io/uff58 reader's
//    conventions; `channel` picks the record (1-based).
// Every malformed input throws robomill::InputError naming the file, the
// line or sample where possible, and what was expected. Its field is
// RecordingSpec::path plus ".file", ".channel", ".variable", ".column",
// ".sample_rate", ".start" or ".duration"; its line is RecordingSpec::line.
//
// Conventions (src/io/recording_*.cpp):
//  * A time column (MAT, CSV) gives the rate from the whole column,
//    (last − first) / (rows − 1); every step must lie within half an
//    interval of it (rounding and jitter pass, a dropped block is refused
//    at its line). A UFF record gives its abscissa increment. A
//    `sample_rate` given as well must agree with the file's within 0.1 %.
//  * info().start_s is the file's time of the first delivered sample (a time
//    column's value; start_s / rate for a WAV). `start` skips from the first
//    sample; a `duration` past the end stops at the end.
//  * info().samples is known for every format (a CSV's rows are counted in one
//    pass when it is opened, before the values are streamed).
//  * MAT v4 files are refused (save as v5 or v7.3); a MAT variable is loaded
//    whole by matio, the others are read block by block.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "robomill/monitoring/recording_analysis.hpp"
#include "robomill/monitoring/signal_source.hpp"

namespace robomill::io {

enum class RecordingFormat { sound_file, mat, csv, uff };
/// "wav" ("flac", "aiff" too), "mat", "csv", "uff"; from the extension when
/// the job does not say. Throws InputError for an unknown extension.
RecordingFormat recording_format_from_extension(const std::filesystem::path& file,
                                                const std::string& field, int line);

/// One recording (`recording:` or an entry of `recordings:`), validated, SI.
struct RecordingSpec {
  std::filesystem::path file;  ///< resolved against the job's folder
  RecordingFormat format = RecordingFormat::sound_file;
  int channel = 1;                       ///< 1-based; 0: the mean of all channels (`channel: mix`)
  std::string variable;                  ///< mat: the variable (empty: the only numeric one)
  std::string column;                    ///< csv: value column name; mat: 1-based column as text
  std::optional<double> sample_rate_hz;  ///< required when the file has no time base
  monitoring::SignalKind signal = monitoring::SignalKind::sound;
  double scale = 1.0;       ///< file unit → SI (`scale:`), e.g. 9.80665 for g
  double start_s = 0.0;     ///< skip this much of the recording
  double duration_s = 0.0;  ///< analyse this much (0: to the end)
  std::vector<monitoring::IgnoredLine> ignore;
  /// A pulse channel beside the signal (`tachometer:`, io/tachometer.hpp):
  /// the channel number (sound, uff) or the column (mat: 1-based number,
  /// csv: name); empty: none. `tachometer_pulses` per revolution.
  std::string tachometer;
  int tachometer_pulses = 1;
  /// Per recording (`recordings:` entries; else process.spindle / ap).
  std::optional<double> spindle_rad_s;
  std::optional<double> depth_m;
  std::string note;
  std::string path;  ///< job path for messages: "recording", "recordings[2]"
  int line = 0;
};

/// Opens the recording for reading in blocks. Throws InputError (file and
/// reason) for a missing, empty, truncated or malformed file, a channel,
/// variable or column that is not there, a missing sample rate, or a start
/// past the end.
std::unique_ptr<monitoring::SignalSource> open_recording(const RecordingSpec& spec);

/// Writes samples as a WAV file (the synthetic examples, tests): `bits` 16 or
/// 24 (integer PCM, full scale ±`full_scale`, values beyond it clipped) or 32
/// (float, written as is). One channel per inner vector, all the same length.
void write_wav(const std::filesystem::path& file, const std::vector<std::vector<double>>& channels,
               double sample_rate_hz, int bits = 24, double full_scale = 1.0);

}  // namespace robomill::io
