// The `recording:`, `recordings:` and `listen:` sections (docs/monitoring.md):
// complete sections reach SI values, defaults are the documented ones, and
// every malformed section is an InputError naming the field and its line.

#include <gtest/gtest.h>

#include <numbers>
#include <string>

#include "job/expect_input_error.hpp"
#include "robomill/job/job.hpp"

namespace test_monitoring_section_cpp {

namespace {

using robomill::io::RecordingFormat;
using robomill::job::parse_job;
using robomill::monitoring::SignalKind;
using robomill::test::expect_error;

constexpr double kRpm = 2.0 * std::numbers::pi / 60.0;

TEST(MonitoringSection, RecordingReachesSi) {
  const auto job = parse_job(R"(recording:
  file: cut.wav
  channel: 2
  signal: acceleration
  scale: 9.80665
  start: 0.5 s
  duration: 2000 ms
  ignore: [120 Hz, 0.3 kHz]
  ignore_width: 2 Hz
  tachometer: 3
  tachometer_pulses: 2
  spindle: 8200 rpm
  depth: 2 mm
  note: first pass
listen:
  teeth: 3
  spindle_search: 5 %
  threshold: 0.6
  mains: off
  steady_lines: false
  band: [10 Hz, 5 kHz]
  segment: 0.5
  spindle_range: [6000 rpm, 12000 rpm]
)",
                             "/jobs/job.yaml");
  ASSERT_EQ(job.recordings.size(), 1u);
  EXPECT_FALSE(job.recordings_listed);
  const auto& r = job.recordings[0];
  EXPECT_EQ(r.file, std::filesystem::path("/jobs/cut.wav"));
  EXPECT_EQ(r.format, RecordingFormat::sound_file);
  EXPECT_EQ(r.channel, 2);
  EXPECT_EQ(r.signal, SignalKind::acceleration);
  EXPECT_DOUBLE_EQ(r.scale, 9.80665);
  EXPECT_DOUBLE_EQ(r.start_s, 0.5);
  EXPECT_DOUBLE_EQ(r.duration_s, 2.0);
  ASSERT_EQ(r.ignore.size(), 2u);
  EXPECT_DOUBLE_EQ(r.ignore[1].frequency_hz, 300.0);
  EXPECT_DOUBLE_EQ(r.ignore[1].half_width_hz, 1.0);
  EXPECT_EQ(r.tachometer, "3");
  EXPECT_EQ(r.tachometer_pulses, 2);
  EXPECT_NEAR(*r.spindle_rad_s, 8200 * kRpm, 1e-9);
  EXPECT_DOUBLE_EQ(*r.depth_m, 2e-3);
  EXPECT_EQ(r.note, "first pass");
  EXPECT_EQ(r.path, "recording");
  EXPECT_EQ(r.line, 1);  // the section key's line
  ASSERT_TRUE(job.listen);
  EXPECT_EQ(*job.listen->teeth, 3);
  EXPECT_DOUBLE_EQ(job.listen->detector.spindle_search_fraction, 0.05);
  EXPECT_DOUBLE_EQ(job.listen->detector.chatter_line_threshold, 0.6);
  EXPECT_FALSE(job.listen->detector.detect_mains);
  EXPECT_FALSE(job.listen->detector.detect_steady_lines);
  EXPECT_DOUBLE_EQ(job.listen->detector.band_high_hz, 5000.0);
  EXPECT_DOUBLE_EQ(job.listen->detector.segment_s, 0.5);
  EXPECT_NEAR(job.listen->spindle_range_rad_s->second, 12000 * kRpm, 1e-9);
}

TEST(MonitoringSection, DefaultsAndFormatsFromTheExtension) {
  const auto job =
      parse_job(R"(process: {spindle: 3000 rpm, feed_per_tooth: 0.1 mm, ap: 1 mm, ae: 1 mm}
tool: {diameter: 10 mm, teeth: 2}
recordings:
  - {file: a.FLAC}
  - {file: b.mat, variable: tsDS, column: "3"}
  - {file: c.csv, column: ax, sample_rate: 10 kHz, tachometer: rpm_pulse}
  - {file: d.uff, channel: mix}
)",
                "job.yaml");
  ASSERT_EQ(job.recordings.size(), 4u);
  EXPECT_TRUE(job.recordings_listed);
  EXPECT_EQ(job.recordings[0].format, RecordingFormat::sound_file);
  EXPECT_EQ(job.recordings[0].channel, 1);
  EXPECT_EQ(job.recordings[0].signal, SignalKind::sound);
  EXPECT_FALSE(job.recordings[0].spindle_rad_s);  // process.spindle applies
  EXPECT_EQ(job.recordings[1].format, RecordingFormat::mat);
  EXPECT_EQ(job.recordings[1].variable, "tsDS");
  EXPECT_EQ(job.recordings[2].format, RecordingFormat::csv);
  EXPECT_DOUBLE_EQ(*job.recordings[2].sample_rate_hz, 1e4);
  EXPECT_EQ(job.recordings[2].tachometer, "rpm_pulse");
  EXPECT_EQ(job.recordings[2].tachometer_pulses, 1);
  EXPECT_TRUE(job.recordings[0].tachometer.empty());
  EXPECT_EQ(job.recordings[3].format, RecordingFormat::uff);
  EXPECT_EQ(job.recordings[3].channel, 0);
  EXPECT_EQ(job.recordings[3].path, "recordings[3]");
  EXPECT_FALSE(job.listen);
}

TEST(MonitoringSection, MalformedSectionsNameFieldAndLine) {
  expect_error("recording: {spindle: 100 rpm}\n", "recording.file", 1, "required");
  expect_error("recording:\n  file: a.xyz\n  spindle: 100 rpm\n", "recording.file", 2, "a.xyz");
  expect_error("recording:\n  file: a.wav\n  channel: 0\n  spindle: 100 rpm\n", "recording.channel",
               3, "mix");
  expect_error("recording:\n  file: a.wav\n  variable: x\n  spindle: 100 rpm\n",
               "recording.variable", 3, "only for MATLAB");
  expect_error("recording:\n  file: a.wav\n", "recording.spindle", 1, "process:");
  expect_error("recording:\n  file: a.wav\n  spindle: 100 rpm\n  signal: pressure\n",
               "recording.signal", 4, "acceleration");
  expect_error("recording:\n  file: a.wav\n  spindle: 100 rpm\n  ignore_width: 2 Hz\n",
               "recording.ignore_width", 4, "needs ignore");
  expect_error("recording:\n  file: a.wav\n  spindle: 100 rpm\n  tachometer: tacho\n",
               "recording.tachometer", 4, "channel number");
  expect_error("recording:\n  file: a.wav\n  channel: 2\n  spindle: 100 rpm\n  tachometer: 2\n",
               "recording.tachometer", 5, "the signal's own");
  expect_error("recording:\n  file: a.csv\n  column: ax\n  spindle: 100 rpm\n  tachometer: ax\n",
               "recording.tachometer", 5, "the signal's own");
  expect_error("recording:\n  file: a.wav\n  spindle: 100 rpm\n  tachometer_pulses: 2\n",
               "recording.tachometer_pulses", 4, "needs tachometer");
  expect_error(
      "recording:\n  file: a.wav\n  spindle: 100 rpm\n  tachometer: 2\n  tachometer_pulses: 0\n",
      "recording.tachometer_pulses", 5, "positive integer");
  expect_error(
      "recording: {file: a.wav, spindle: 100 rpm}\nrecordings: [{file: b.wav, "
      "spindle: 100 rpm}]\n",
      "recordings", 2, "not both");
  expect_error("recordings: []\n", "recordings", 1, "empty");
  expect_error("recordings:\n  - {file: a.wav, spindle: 100 rpm}\n  - {file: b.wav, spindel: 1}\n",
               "recordings[1].spindel", 3, "");
  expect_error("listen:\n  band: [5 kHz, 10 Hz]\n", "listen.band", 2, "must exceed");
  expect_error("listen:\n  threshold: 1.5\n", "listen.threshold", 2, "");
  expect_error("listen:\n  spindle_range: [9000 rpm, 3000 rpm]\n", "listen.spindle_range", 2,
               "upper");
}

}  // namespace

}  // namespace test_monitoring_section_cpp
