// The spindle speed from a tachometer channel (io/tachometer.hpp, issue 34):
// pulse trains written beside a signal in a WAV and a CSV, counted back at
// speeds nobody rounded, over a stretch (start, duration), with several
// pulses a revolution; flat, sparse and irregular channels refused by name;
// and a job whose spindle runs 25 % below its command judged at the
// tachometer's speed (the comb search, ±10 %, cannot reach it).

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "robomill/analysis/recording_verdicts.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/recording.hpp"
#include "robomill/io/tachometer.hpp"
#include "robomill/job/job.hpp"

namespace test_tachometer_cpp {

namespace {

namespace fs = std::filesystem;
using namespace robomill;
constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kRate = 20000.0;
constexpr double kSpindleHz = 74.853;  // 4491.2 rpm; 5955 rpm commanded below

class Tachometer : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           (std::string("robomill_tach_") + info->name() + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

/// A 6-tooth cut's forced comb at `spindle_hz` (tooth harmonics falling as
/// 1/k, a little runout) and noise.
std::vector<double> cut(std::size_t n, double spindle_hz, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.003);
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / kRate;
    double v = noise(rng);
    for (int k = 1; 6 * k * spindle_hz < 0.45 * kRate; ++k)
      v += 0.2 / k * std::sin(kTwoPi * 6 * k * spindle_hz * t + 0.7 * k);
    for (int k : {1, 2, 3})
      v += 0.01 * std::sin(kTwoPi * k * spindle_hz * t + 0.3 * k);
    x[i] = v;
  }
  return x;
}

/// Pulses of 15 % duty, `per_rev` a revolution at `spindle_hz`, 0.8 high,
/// with noise; every `drop`-th pulse missing (0: none).
std::vector<double> pulses(std::size_t n, double spindle_hz, int per_rev, int drop = 0) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double phase = per_rev * spindle_hz * static_cast<double>(i) / kRate + 0.37;
    const auto pulse = static_cast<long>(std::floor(phase));
    const bool high = phase - std::floor(phase) < 0.15 && !(drop > 0 && pulse % drop == 0);
    x[i] = (high ? 0.8 : 0.0) + noise(rng);
  }
  return x;
}

io::RecordingSpec wav_spec(const fs::path& file, const std::string& tachometer, int per_rev = 1) {
  io::RecordingSpec spec;
  spec.file = file;
  spec.format = io::RecordingFormat::sound_file;
  spec.tachometer = tachometer;
  spec.tachometer_pulses = per_rev;
  return spec;
}

TEST_F(Tachometer, APulseChannelGivesTheSpeed) {
  const auto n = static_cast<std::size_t>(4.3 * kRate);
  const fs::path file = dir_ / "cut.wav";
  io::write_wav(file, {cut(n, kSpindleHz, 1), pulses(n, kSpindleHz, 1)}, kRate, 24);
  const auto reading = io::read_tachometer(wav_spec(file, "2"));
  EXPECT_NEAR(reading.spindle_hz, kSpindleHz, 1e-5 * kSpindleHz);
  EXPECT_NEAR(static_cast<double>(reading.pulses), 4.3 * kSpindleHz, 1.0);
  EXPECT_LT(reading.period_spread, 0.01);
  // A stretch of it: the same speed from its own pulses.
  auto stretch = wav_spec(file, "2");
  stretch.start_s = 1.13;
  stretch.duration_s = 1.71;
  const auto part = io::read_tachometer(stretch);
  EXPECT_NEAR(part.spindle_hz, kSpindleHz, 1e-4 * kSpindleHz);
  EXPECT_NEAR(static_cast<double>(part.pulses), 1.71 * kSpindleHz, 1.0);
  // Three pulses a revolution.
  const fs::path three = dir_ / "three.wav";
  io::write_wav(three, {cut(n, kSpindleHz, 1), pulses(n, kSpindleHz, 3)}, kRate, 16);
  EXPECT_NEAR(io::read_tachometer(wav_spec(three, "2", 3)).spindle_hz, kSpindleHz,
              1e-5 * kSpindleHz);
}

TEST_F(Tachometer, ACsvColumnGivesTheSpeed) {
  const auto n = static_cast<std::size_t>(2.2 * kRate);
  const auto signal = cut(n, kSpindleHz, 2);
  const auto tach = pulses(n, kSpindleHz, 1);
  const fs::path file = dir_ / "cut.csv";
  {
    std::ofstream out(file);
    out << "t_s,ax,once_per_rev\n";
    out.precision(9);
    for (std::size_t i = 0; i < n; ++i)
      out << static_cast<double>(i) / kRate << ',' << signal[i] << ',' << tach[i] << '\n';
  }
  io::RecordingSpec spec;
  spec.file = file;
  spec.format = io::RecordingFormat::csv;
  spec.column = "ax";
  spec.tachometer = "once_per_rev";
  EXPECT_NEAR(io::read_tachometer(spec).spindle_hz, kSpindleHz, 1e-5 * kSpindleHz);
}

TEST_F(Tachometer, FlatSparseAndIrregularChannelsAreRefusedByName) {
  const auto n = static_cast<std::size_t>(1.5 * kRate);
  const fs::path file = dir_ / "bad.wav";
  std::vector<double> flat(n, 0.25), sparse(n, 0.0);
  for (std::size_t i = 1000; i < 1100; ++i)
    sparse[i] = 0.8;  // one pulse
  io::write_wav(file, {cut(n, kSpindleHz, 1), flat, sparse, pulses(n, kSpindleHz, 1, 3)}, kRate,
                24);
  const auto expect_refused = [&](const std::string& channel, const std::string& words) {
    try {
      io::read_tachometer(wav_spec(file, channel));
      ADD_FAILURE() << "channel " << channel << " was read";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "recording.tachometer") << e.what();
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  expect_refused("2", "flat");
  expect_refused("3", "holds 1 pulse(s)");
  expect_refused("4", "missed or doubled");
  // A channel the file does not have: the reader's own error.
  EXPECT_THROW(io::read_tachometer(wav_spec(file, "5")), InputError);
  EXPECT_THROW(io::read_tachometer(wav_spec(file, "x")), InputError);
}

// The shared "stable" milling microphone recording's case: written as
// 5955 rpm, its comb sits at 4491 rpm, beyond the ±10 % search. With a
// tachometer channel the job is judged at the speed the spindle ran.
TEST_F(Tachometer, AJobIsJudgedAtTheTachometersSpeed) {
  const auto n = static_cast<std::size_t>(3.7 * kRate);
  io::write_wav(dir_ / "cut.wav", {cut(n, kSpindleHz, 5), pulses(n, kSpindleHz, 1)}, kRate, 24);
  const std::string with = R"(recording: {file: cut.wav, spindle: 5955 rpm, tachometer: 2}
listen: {teeth: 6}
)";
  const auto judged = analysis::recording_verdicts(job::parse_job(with, dir_ / "job.yaml"), 1);
  const auto& a = judged.recordings.at(0).analysis;
  EXPECT_EQ(a.spindle_source, "tachometer");
  EXPECT_NEAR(a.spindle_hz_measured, kSpindleHz, 1e-5 * kSpindleHz);
  EXPECT_EQ(a.verdict, monitoring::Verdict::stable) << a.reason;
  EXPECT_GT(a.forced_energy_fraction, 0.9);
  ASSERT_TRUE(judged.recordings.at(0).tachometer.has_value());
  // Without it the commanded speed stands and the comb is not explained.
  const std::string without = R"(recording: {file: cut.wav, spindle: 5955 rpm}
listen: {teeth: 6}
)";
  const auto blind = analysis::recording_verdicts(job::parse_job(without, dir_ / "job.yaml"), 1);
  EXPECT_NE(blind.recordings.at(0).analysis.spindle_source, "tachometer");
  EXPECT_LT(blind.recordings.at(0).analysis.forced_energy_fraction, 0.5);
}

}  // namespace

}  // namespace test_tachometer_cpp
