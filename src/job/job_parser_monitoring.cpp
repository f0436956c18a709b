// The `recording:`, `recordings:` and `listen:` sections of a job
// (docs/monitoring.md): which recorded signal, how to read it, and how
// `robomill listen` judges it. Frequencies in Hz, times in s, spindle speeds
// in rpm, depths in mm unless written.

#include <fmt/format.h>

#include <charconv>

#include "job_parser_monitoring.hpp"
#include "quantity_fields.hpp"

namespace robomill::job::detail {
namespace {

QuantityField hertz(std::optional<Bound> min = kPositive) {
  return field(dimensions::frequency, 1.0, "Hz", min);
}
QuantityField seconds(std::optional<Bound> min = kNonNegative) {
  return field(dimensions::time, 1.0, "s", min);
}
QuantityField rpm() {
  return field(dimensions::angular_speed, kRpm, "rpm", kPositive);
}

/// A channel number of a sound or UFF file, 1 … 4096; nullopt for
/// anything else (a sign, a fraction, trailing text).
std::optional<int> channel_number(const std::string& text) {
  int number = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), number);
  if (error != std::errc() || end != text.data() + text.size() || number < 1 || number > 4096)
    return std::nullopt;
  return number;
}

monitoring::SignalKind signal_kind(const std::string& word) {
  using monitoring::SignalKind;
  if (word == "acceleration")
    return SignalKind::acceleration;
  if (word == "velocity")
    return SignalKind::velocity;
  if (word == "displacement")
    return SignalKind::displacement;
  if (word == "force")
    return SignalKind::force;
  return SignalKind::sound;
}

// One recording: `recording:` or an entry of `recordings:`.
/// `commanded_spindle_rad_s`: the speed of the section the recording sits
/// in (an experiment's), the default of its `spindle`.
io::RecordingSpec read_recording(SectionReader& r, const Job& job, bool listed,
                                 std::optional<double> commanded_spindle_rad_s = std::nullopt) {
  r.allow_schema(listed ? "recordings[]" : "recording");
  io::RecordingSpec spec;
  spec.path = r.path();
  spec.line = r.line();
  const auto file = r.optional_text("file");
  if (!file)
    r.fail("file", "required: the recorded signal (.wav .flac .aiff .mat .csv .uff)");
  spec.file = job.resolve(*file);
  if (r.has("format")) {
    const std::string format =
        r.choice("format", {"wav", "flac", "aiff", "sound", "mat", "csv", "uff"});
    spec.format = format == "mat"   ? io::RecordingFormat::mat
                  : format == "csv" ? io::RecordingFormat::csv
                  : format == "uff" ? io::RecordingFormat::uff
                                    : io::RecordingFormat::sound_file;
  } else {
    spec.format =
        io::recording_format_from_extension(spec.file, r.path_of("file"), r.line_of("file"));
  }
  if (const auto channel = r.optional_text("channel")) {
    if (*channel == "mix") {
      spec.channel = 0;
    } else {
      const std::optional<int> number = channel_number(*channel);
      if (!number)
        r.fail("channel", fmt::format("expected a channel number from 1 (or mix, the mean of all "
                                      "channels), got '{}'",
                                      *channel));
      spec.channel = *number;
    }
  }
  spec.variable = r.optional_text("variable").value_or("");
  spec.column = r.optional_text("column").value_or("");
  if (!spec.variable.empty() && spec.format != io::RecordingFormat::mat)
    r.fail("variable", "only for MATLAB files (format: mat)");
  if (!spec.column.empty() && spec.format != io::RecordingFormat::mat &&
      spec.format != io::RecordingFormat::csv)
    r.fail("column", "only for MATLAB and CSV files (format: mat or csv)");
  spec.sample_rate_hz = r.optional_quantity("sample_rate", hertz());
  spec.signal = signal_kind(
      r.choice("signal", {"sound", "acceleration", "velocity", "displacement", "force"}, "sound"));
  spec.scale = r.quantity_or("scale", dimensionless(kPositive), 1.0);
  spec.start_s = r.quantity_or("start", seconds(), 0.0);
  spec.duration_s = r.quantity_or("duration", seconds(kPositive), 0.0);
  if (const auto ignore = r.quantities("ignore", hertz())) {
    const double half_width_hz = r.quantity_or("ignore_width", hertz(kNonNegative), 0.0) / 2.0;
    for (double f : *ignore)
      spec.ignore.push_back({f, half_width_hz});
  } else if (r.has("ignore_width")) {
    r.fail("ignore_width", "needs ignore: the lines it widens");
  }
  spec.tachometer = r.optional_text("tachometer").value_or("");
  if (!spec.tachometer.empty() &&
      (spec.format == io::RecordingFormat::sound_file || spec.format == io::RecordingFormat::uff)) {
    const std::optional<int> number = channel_number(spec.tachometer);
    if (!number)
      r.fail("tachometer", fmt::format("expected the channel number (from 1) of the pulse train, "
                                       "got '{}'",
                                       spec.tachometer));
    if (*number == spec.channel)
      r.fail("tachometer", fmt::format("channel {} is the signal's own (channel:)", *number));
  } else if (!spec.tachometer.empty() && spec.tachometer == spec.column) {
    r.fail("tachometer", fmt::format("column '{}' is the signal's own (column:)", spec.column));
  }
  if (r.has("tachometer_pulses")) {
    if (spec.tachometer.empty())
      r.fail("tachometer_pulses", "needs tachometer: the pulse channel it describes");
    spec.tachometer_pulses = r.integer("tachometer_pulses", 1, 1000);
  }
  spec.spindle_rad_s = r.optional_quantity("spindle", rpm());
  if (!spec.spindle_rad_s)
    spec.spindle_rad_s = commanded_spindle_rad_s;
  spec.depth_m = r.optional_quantity("depth", length_mm());
  spec.note = r.optional_text("note").value_or("");
  r.finish();
  if (!spec.spindle_rad_s && !job.process)
    r.fail("spindle", fmt::format("required: the commanded spindle speed of this cut (or give "
                                  "the job a process: section with spindle)"));
  return spec;
}

ListenSettings read_listen(SectionReader& r) {
  r.allow_schema("listen");
  ListenSettings s;
  s.line = r.line();
  if (r.has("teeth"))
    s.teeth = r.integer("teeth", 1, 1000);
  monitoring::ListenOptions& d = s.detector;
  d.spindle_search_fraction =
      r.quantity_or("spindle_search", dimensionless(kNonNegative, Bound{0.5, true}), 0.1);
  d.chatter_line_threshold = r.quantity_or("threshold", dimensionless(kPositive, Bound{1.0, false}),
                                           monitoring::ListenOptions{}.chatter_line_threshold);
  d.detect_mains = r.choice("mains", {"auto", "off"}, "auto") == "auto";
  d.detect_steady_lines = r.boolean_or("steady_lines", true);
  d.judge_engaged_stretch = r.boolean_or("engaged_only", true);
  if (const auto band = r.quantities("band", hertz(kNonNegative), 2)) {
    d.band_low_hz = (*band)[0];
    d.band_high_hz = (*band)[1];
    if (!(d.band_high_hz > d.band_low_hz))
      r.fail("band", fmt::format("the upper edge ({:.6g} Hz) must exceed the lower ({:.6g} Hz)",
                                 d.band_high_hz, d.band_low_hz));
  }
  d.segment_s = r.quantity_or("segment", seconds(kPositive), 0.0);
  if (const auto range = r.quantities("spindle_range", rpm(), 2)) {
    if (!((*range)[1] > (*range)[0]))
      r.fail("spindle_range", "the upper speed must exceed the lower");
    s.spindle_range_rad_s = std::make_pair((*range)[0], (*range)[1]);
  }
  r.finish();
  return s;
}

}  // namespace

io::RecordingSpec read_nested_recording(SectionReader& r, const Job& job, double spindle_rad_s) {
  return read_recording(r, job, false, spindle_rad_s);
}

void read_monitoring(SectionReader& root, Job& job) {
  if (root.has("recording") && root.has("recordings"))
    root.fail("recordings", "give recording: (one cut) or recordings: (several), not both");
  if (auto section = root.section("recording"))
    job.recordings.push_back(read_recording(*section, job, false));
  if (auto list = root.sections("recordings")) {
    if (list->empty())
      root.fail("recordings", "the list is empty; give at least one recording");
    for (SectionReader& entry : *list)
      job.recordings.push_back(read_recording(entry, job, true));
    job.recordings_listed = true;
  }
  if (auto section = root.section("listen"))
    job.listen = read_listen(*section);
}

}  // namespace robomill::job::detail
