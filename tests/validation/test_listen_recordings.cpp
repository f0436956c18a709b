// The recorded-signal chatter detector (`robomill listen`,
// monitoring::analyze_recording) on real recordings — issue 22.
//
//   data  : four accelerometer recordings of a turning experiment with a
//           2-inch boring-bar stickout and one insert (Khasawneh, Otto,
//           Yesilli, "turning dataset for chatter diagnosis", Mendeley Data
//           hvm4wh3jzx), kept outside the repository in ../shared/recordings
//           (its README): MATLAB v5, variable tsDS = [time s, acceleration],
//           10 kHz. The file name holds the authors' label (s stable,
//           c chatter), the spindle rpm and the depth of cut in thousandths
//           of an inch. Skipped where the folder is absent.
//   judge : io::open_recording (format mat, variable tsDS, signal
//           acceleration) and analyze_recording with the spindle speed of the
//           file name and one tooth (the insert), every other option at
//           `robomill listen`'s default.
//   accept: the dataset's label; for the chatter recordings the chatter
//           frequency in 850-1000 Hz, the boring bar's mode (the README: the
//           chatter power lies near 0.9-1.0 kHz).

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include <fmt/format.h>

#include "robomill/io/recording.hpp"
#include "robomill/monitoring/recording_analysis.hpp"
#include "support/validation_record.hpp"

namespace test_listen_recordings_cpp {

namespace {

using namespace robomill;
using test::sig4;
const char* kSection = "listen-recordings";  // the validation report's issue-22 section
constexpr double kModeLowHz = 850.0, kModeHighHz = 1000.0;

std::filesystem::path recordings_dir() {
  return std::filesystem::path(ROBOMILL_SOURCE_DIR) / ".." / "shared" / "recordings";
}

struct Recording {
  const char* file;
  bool chatter;  // the dataset's label
  double rpm;
  double depth_in;
};

const Recording kRecordings[] = {
    {"khasawneh_turning_2in_s_425_015.mat", false, 425.0, 0.015},
    {"khasawneh_turning_2in_c_425_025.mat", true, 425.0, 0.025},
    {"khasawneh_turning_2in_s_320_050.mat", false, 320.0, 0.050},
    {"khasawneh_turning_2in_c_770_005.mat", true, 770.0, 0.005},
};

TEST(ListenRecordings, KhasawnehTurningLabels) {
  const auto dir = recordings_dir();
  if (!std::filesystem::is_directory(dir))
    GTEST_SKIP() << "no recordings at " << dir.string();
  for (const Recording& rec : kRecordings) {
    const auto path = dir / rec.file;
    if (!std::filesystem::exists(path)) {
      ADD_FAILURE() << "missing " << path.string();
      continue;
    }
    io::RecordingSpec spec;
    spec.file = path;
    spec.format = io::RecordingFormat::mat;
    spec.variable = "tsDS";
    spec.signal = monitoring::SignalKind::acceleration;
    auto source = io::open_recording(spec);
    monitoring::ListenOptions options;
    options.commanded_spindle_hz = rec.rpm / 60.0;
    options.teeth = 1;
    const auto r = monitoring::analyze_recording(*source, options);

    const bool verdict_ok =
        r.verdict == (rec.chatter ? monitoring::Verdict::chatter : monitoring::Verdict::stable);
    const bool band_ok =
        !rec.chatter || (r.chatter_hz >= kModeLowHz && r.chatter_hz <= kModeHighHz);
    std::printf(
        "[validation] listen %s (label %s, %.0f rpm, %.3f in): %s, chatter %.5g Hz, share %.3f, "
        "forced %.3f, set aside %.3f, floor %.3f, spindle %.4f Hz measured (%.4f commanded), "
        "%.4g s at %.0f Hz — %s\n",
        rec.file, rec.chatter ? "chatter" : "stable", rec.rpm, rec.depth_in,
        monitoring::verdict_name(r.verdict), r.chatter_hz, r.chatter_energy_fraction,
        r.forced_energy_fraction, r.ignored_energy_fraction, r.floor_energy_fraction,
        r.spindle_hz_measured, r.spindle_hz_commanded, r.duration_s, r.sample_rate_hz,
        r.reason.c_str());
    std::string ours = monitoring::verdict_name(r.verdict);
    if (r.verdict == monitoring::Verdict::chatter)
      ours.append(" ").append(sig4(r.chatter_hz)).append(" Hz");
    ours += fmt::format(" (chatter share {:.0f} %)", 100.0 * r.chatter_energy_fraction);
    test::record_check(
        kSection,
        fmt::format("Khasawneh et al. turning, 2 in stickout, {:.0f} rpm, depth {} in ({})",
                    rec.rpm, sig4(rec.depth_in), rec.file),
        rec.chatter ? "chatter verdict and frequency" : "chatter verdict", rec.chatter ? "Hz" : "",
        rec.chatter ? "chatter (label), boring-bar mode 0.9-1.0 kHz" : "stable (label)", ours,
        rec.chatter ? "same verdict; 850 … 1000 Hz" : "same verdict", verdict_ok && band_ok,
        "the dataset's own label (Khasawneh, Otto, Yesilli, \"turning dataset for chatter "
        "diagnosis\", Mendeley Data hvm4wh3jzx); accelerometer signal, 10 kHz; spindle from the "
        "file name, one insert (teeth 1); listen's defaults otherwise");
    EXPECT_TRUE(verdict_ok) << rec.file << ": label " << (rec.chatter ? "chatter" : "stable")
                            << ", listen " << monitoring::verdict_name(r.verdict) << " — "
                            << r.reason;
    if (rec.chatter) {
      EXPECT_GE(r.chatter_hz, kModeLowHz) << rec.file;
      EXPECT_LE(r.chatter_hz, kModeHighHz) << rec.file;
    }
  }
}

}  // namespace

}  // namespace test_listen_recordings_cpp
