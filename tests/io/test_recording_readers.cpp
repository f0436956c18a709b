// The recording readers (io/recording.hpp): WAV/FLAC through libsndfile,
// MATLAB v5 and v7.3 through matio, streamed CSV and UFF58 time records,
// written here and read back exactly (within PCM quantization), in blocks of
// any size, with start/duration and channel choice; every malformed input is
// an InputError naming the file and the reason. Also the real recordings in
// ../shared/recordings (MATLAB v5, 10 kHz).

#include <gtest/gtest.h>
#include <matio.h>
#include <sndfile.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <numbers>
#include <string>
#include <vector>

#include "robomill/core/error.hpp"
#include "robomill/io/recording.hpp"
#include "robomill/io/uff58.hpp"

namespace test_recording_readers_cpp {

namespace {

namespace fs = std::filesystem;
using namespace robomill;
using io::RecordingFormat;
using io::RecordingSpec;

class RecordingReaders : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           (std::string("robomill_rec_") + info->name() + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path path(const std::string& name) const { return dir_ / name; }

  fs::path dir_;
};

std::vector<double> tone(std::size_t n, double rate, double frequency, double amplitude,
                         double phase = 0.0) {
  std::vector<double> out(n);
  for (std::size_t i = 0; i < n; ++i)
    out[i] = amplitude *
             std::sin(2.0 * std::numbers::pi * frequency * static_cast<double>(i) / rate + phase);
  return out;
}

RecordingSpec spec_for(const fs::path& file, RecordingFormat format) {
  RecordingSpec spec;
  spec.file = file;
  spec.format = format;
  spec.path = "recording";
  spec.line = 4;
  return spec;
}

std::vector<double> read_all(monitoring::SignalSource& source, std::size_t block = 1000) {
  std::vector<double> out;
  std::vector<double> buffer(block);
  while (const std::size_t n = source.read(buffer))
    out.insert(out.end(), buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(n));
  return out;
}

std::vector<double> read_spec(const RecordingSpec& spec, std::size_t block = 1000) {
  auto source = io::open_recording(spec);
  return read_all(*source, block);
}

// The InputError open_recording (or reading) raises; the field and the
// message must name what is expected.
InputError error_of(const RecordingSpec& spec) {
  try {
    auto source = io::open_recording(spec);
    read_all(*source);
  } catch (const InputError& error) {
    return error;
  }
  ADD_FAILURE() << "accepted " << spec.file;
  return InputError("", 0, "");
}

void expect_error(const RecordingSpec& spec, const std::string& field,
                  const std::vector<std::string>& fragments) {
  SCOPED_TRACE(spec.file.string());
  const InputError error = error_of(spec);
  EXPECT_EQ(error.field(), field) << error.what();
  EXPECT_EQ(error.line(), spec.line) << error.what();
  for (const std::string& fragment : fragments)
    EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos)
        << "message: " << error.what() << "\nexpected to contain: " << fragment;
}

void expect_near_all(const std::vector<double>& got, const std::vector<double>& want,
                     double tolerance) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i)
    ASSERT_NEAR(got[i], want[i], tolerance) << "sample " << i;
}

std::string write_text(const fs::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
  return file.string();
}

// A MATLAB file with one variable per entry (column-major double data).
struct MatVariable {
  std::string name;
  std::size_t rows, columns;
  std::vector<double> data;
};

void write_mat(const fs::path& file, const std::vector<MatVariable>& variables, mat_ft version) {
  mat_t* mat = Mat_CreateVer(file.c_str(), nullptr, version);
  ASSERT_NE(mat, nullptr);
  for (const MatVariable& v : variables) {
    std::size_t dims[2] = {v.rows, v.columns};
    matvar_t* var = Mat_VarCreate(v.name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims,
                                  const_cast<double*>(v.data.data()), 0);
    ASSERT_NE(var, nullptr);
    ASSERT_EQ(Mat_VarWrite(mat, var, MAT_COMPRESSION_NONE), 0);
    Mat_VarFree(var);
  }
  Mat_Close(mat);
}

MatVariable time_matrix(const std::string& name, const std::vector<double>& values, double rate,
                        double t0 = 0.0) {
  MatVariable v{name, values.size(), 2, {}};
  for (std::size_t i = 0; i < values.size(); ++i)
    v.data.push_back(t0 + static_cast<double>(i) / rate);
  v.data.insert(v.data.end(), values.begin(), values.end());
  return v;
}

// --- sound files -----------------------------------------------------------

TEST_F(RecordingReaders, WavRoundTripsWithinQuantization) {
  const double rate = 8000.0;
  const auto left = tone(4000, rate, 440.0, 0.8);
  const auto right = tone(4000, rate, 1000.0, 0.5, 0.3);
  for (const int bits : {16, 24, 32}) {
    SCOPED_TRACE(bits);
    const fs::path file = path("tone" + std::to_string(bits) + ".wav");
    io::write_wav(file, {left, right}, rate, bits, 2.0);
    // PCM: values over the full scale, half a step; float: as written.
    const double full = bits == 32 ? 1.0 : 2.0;
    const double tolerance = bits == 32 ? 1e-7 : 0.5 * std::ldexp(1.0, 1 - bits) * 1.0001;
    RecordingSpec spec = spec_for(file, RecordingFormat::sound_file);
    spec.scale = full;  // back to the written units
    auto source = io::open_recording(spec);
    EXPECT_EQ(source->info().sample_rate_hz, rate);
    EXPECT_EQ(source->info().samples, 4000);
    EXPECT_EQ(source->info().full_scale, bits == 32 ? 0.0 : 2.0);
    EXPECT_NE(source->info().description.find("channel 1 of 2"), std::string::npos);
    EXPECT_NE(source->info().description.find(bits == 32 ? "float 32-bit"
                                                         : "PCM " + std::to_string(bits) + "-bit"),
              std::string::npos)
        << source->info().description;
    expect_near_all(read_all(*source), left, tolerance * full);
    spec.channel = 2;
    expect_near_all(read_spec(spec), right, tolerance * full);
    spec.channel = 0;
    std::vector<double> mean(left.size());
    for (std::size_t i = 0; i < mean.size(); ++i)
      mean[i] = 0.5 * (left[i] + right[i]);
    expect_near_all(read_spec(spec), mean, tolerance * full);
  }
}

TEST_F(RecordingReaders, WavDescriptionAndFullScaleValuesStayExact) {
  const fs::path file = path("kick.wav");
  // Full-scale codes: -1 maps to the lowest code and reads back exactly.
  io::write_wav(file, {{-1.0, 0.0, 0.5, 1.0}, {0.25, -0.25, 0.0, 0.0}}, 48000.0, 24);
  auto source = io::open_recording(spec_for(file, RecordingFormat::sound_file));
  EXPECT_EQ(source->info().description, "kick.wav, channel 1 of 2, 48000 Hz, PCM 24-bit, 0.00 s");
  const auto samples = read_all(*source);
  ASSERT_EQ(samples.size(), 4u);
  EXPECT_EQ(samples[0], -1.0);
  EXPECT_EQ(samples[2], 0.5);
  EXPECT_NEAR(samples[3], 1.0, std::ldexp(1.0, -23));  // clipped to the largest code
}

TEST_F(RecordingReaders, BlockSizesStartAndDurationGiveTheSameSamples) {
  const double rate = 1000.0;
  const auto signal = tone(3000, rate, 37.0, 0.9);
  const fs::path file = path("blocks.wav");
  io::write_wav(file, {signal}, rate, 32);
  RecordingSpec spec = spec_for(file, RecordingFormat::sound_file);
  const auto whole = read_spec(spec, 100000);
  for (const std::size_t block : {1u, 7u, 4096u, 5000u})
    EXPECT_EQ(read_spec(spec, block), whole) << block;
  spec.start_s = 0.5;
  spec.duration_s = 1.25;
  auto source = io::open_recording(spec);
  EXPECT_EQ(source->info().samples, 1250);
  EXPECT_DOUBLE_EQ(source->info().start_s, 0.5);
  const auto cut = read_all(*source, 333);
  ASSERT_EQ(cut.size(), 1250u);
  EXPECT_TRUE(std::equal(cut.begin(), cut.end(), whole.begin() + 500));
  // A duration past the end stops at the end.
  spec.duration_s = 100.0;
  EXPECT_EQ(read_spec(spec).size(), 2500u);
}

TEST_F(RecordingReaders, FlacAndAiffThroughLibsndfile) {
  const double rate = 16000.0;
  const auto signal = tone(1600, rate, 500.0, 0.6);
  for (const auto& [name, format] : {std::pair{"tone.flac", SF_FORMAT_FLAC | SF_FORMAT_PCM_16},
                                     std::pair{"tone.aiff", SF_FORMAT_AIFF | SF_FORMAT_PCM_24}}) {
    SCOPED_TRACE(name);
    SF_INFO info{};
    info.samplerate = static_cast<int>(rate);
    info.channels = 1;
    info.format = format;
    SNDFILE* out = sf_open(path(name).c_str(), SFM_WRITE, &info);
    ASSERT_NE(out, nullptr) << sf_strerror(nullptr);
    sf_command(out, SFC_SET_CLIPPING, nullptr, SF_TRUE);
    sf_writef_double(out, signal.data(), static_cast<sf_count_t>(signal.size()));
    sf_close(out);
    const RecordingSpec spec = spec_for(path(name), RecordingFormat::sound_file);
    EXPECT_EQ(io::recording_format_from_extension(path(name), "recording.file", 4),
              RecordingFormat::sound_file);
    expect_near_all(read_spec(spec, 999), signal, 2.0 / 32768.0);
  }
}

TEST_F(RecordingReaders, BadSoundFilesAreInputErrors) {
  io::write_wav(path("stereo.wav"), {{0.1, 0.2}, {0.3, 0.4}}, 8000.0, 16);
  RecordingSpec spec = spec_for(path("stereo.wav"), RecordingFormat::sound_file);
  spec.channel = 3;
  expect_error(spec, "recording.channel", {"stereo.wav has 2 channels, got channel 3"});
  spec.channel = 1;
  spec.start_s = 5.0;
  expect_error(spec, "recording.start", {"past the end of stereo.wav"});
  spec.start_s = 0.0;
  spec.sample_rate_hz = 44100.0;
  expect_error(spec, "recording.sample_rate", {"stereo.wav is sampled at 8000 Hz"});

  write_text(path("empty.wav"), "");
  expect_error(spec_for(path("empty.wav"), RecordingFormat::sound_file), "recording.file",
               {"empty.wav", "as a sound file"});
  write_text(path("notes.wav"), "these are my notes, not audio\n");
  expect_error(spec_for(path("notes.wav"), RecordingFormat::sound_file), "recording.file",
               {"notes.wav", "as a sound file"});
  expect_error(spec_for(path("missing.wav"), RecordingFormat::sound_file), "recording.file",
               {"no such file", "missing.wav"});

  // A WAV whose header declares no frames.
  io::write_wav(path("full.wav"), {tone(2000, 8000.0, 300.0, 0.5)}, 8000.0, 16);
  std::string bytes;
  {
    std::ifstream in(path("full.wav"), std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  write_text(path("header_only.wav"), bytes.substr(0, 44));
  expect_error(spec_for(path("header_only.wav"), RecordingFormat::sound_file), "recording.file",
               {"header_only.wav"});
  // Cut the data chunk: the header still claims 2000 frames. libsndfile
  // either reports the frames present or the read stops early; never a crash.
  write_text(path("cut.wav"), bytes.substr(0, 44 + 1000));
  RecordingSpec cut = spec_for(path("cut.wav"), RecordingFormat::sound_file);
  try {
    auto source = io::open_recording(cut);
    const auto samples = read_all(*source);
    EXPECT_LE(samples.size(), 500u);
    EXPECT_EQ(static_cast<std::int64_t>(samples.size()), source->info().samples);
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("cut.wav"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("truncated"), std::string::npos) << error.what();
  }
}

// --- MATLAB ------------------------------------------------------------------

TEST_F(RecordingReaders, MatV5AndV73MatricesAndVectors) {
  const double rate = 2000.0;
  const auto values = tone(1000, rate, 120.0, 3.0);
  for (const mat_ft version : {MAT_FT_MAT5, MAT_FT_MAT73}) {
    SCOPED_TRACE(version == MAT_FT_MAT5 ? "v5" : "v7.3");
    const fs::path file = path(version == MAT_FT_MAT5 ? "v5.mat" : "v73.mat");
    MatVariable vector{"v", 1, values.size(), values};
    MatVariable three = time_matrix("ts", values, rate, 2.5);
    for (const double x : values)
      three.data.push_back(-x);
    three.columns = 3;
    write_mat(file, {three, vector}, version);
    {
      mat_t* mat = Mat_Open(file.c_str(), MAT_ACC_RDONLY);
      ASSERT_NE(mat, nullptr);
      EXPECT_EQ(Mat_GetVersion(mat), version);
      Mat_Close(mat);
    }
    RecordingSpec spec = spec_for(file, RecordingFormat::mat);
    spec.variable = "ts";
    spec.scale = 2.0;
    auto source = io::open_recording(spec);
    EXPECT_NEAR(source->info().sample_rate_hz, rate, 1e-9);
    EXPECT_EQ(source->info().samples, 1000);
    EXPECT_DOUBLE_EQ(source->info().start_s, 2.5);
    EXPECT_NE(source->info().description.find("column 2 of 3"), std::string::npos)
        << source->info().description;
    auto got = read_all(*source, 77);
    for (double& x : got)
      x /= 2.0;
    EXPECT_EQ(got, values);
    spec.column = "3";
    spec.scale = 1.0;
    spec.start_s = 0.1;
    spec.duration_s = 0.2;
    got = read_spec(spec);
    ASSERT_EQ(got.size(), 400u);
    EXPECT_EQ(got[0], -values[200]);

    RecordingSpec vec = spec_for(file, RecordingFormat::mat);
    vec.variable = "v";
    expect_error(vec, "recording.sample_rate", {"'v' is a vector", "sample_rate"});
    vec.sample_rate_hz = rate;
    EXPECT_EQ(read_spec(vec, 3), values);

    RecordingSpec none = spec_for(file, RecordingFormat::mat);
    expect_error(none, "recording.variable", {"2 numeric variables", "it holds: ts, v"});
    none.variable = "x";
    expect_error(none, "recording.variable",
                 {"no variable 'x' in " + file.filename().string() + " (it holds: ts, v)"});
    spec.column = "4";
    expect_error(spec, "recording.column", {"3 columns, got column 4"});
    spec.column = "1";
    expect_error(spec, "recording.column", {"column 1 is the time"});
  }
}

TEST_F(RecordingReaders, MatTimeColumnMustBeUniform) {
  MatVariable v = time_matrix("tsDS", tone(100, 1000.0, 50.0, 1.0), 1000.0);
  v.data[40] += 0.7e-3;  // row 41 0.7 of a step late: more than rounding or jitter
  write_mat(path("jitter.mat"), {v}, MAT_FT_MAT5);
  expect_error(spec_for(path("jitter.mat"), RecordingFormat::mat), "recording.variable",
               {"jitter.mat", "row 41", "uniform"});
  // Rounded to 4 decimals at 3 kHz (steps of 0.3 or 0.4 ms): uniform.
  MatVariable rounded = time_matrix("tsDS", tone(100, 3000.0, 50.0, 1.0), 3000.0);
  for (int r = 0; r < 100; ++r)
    rounded.data[static_cast<std::size_t>(r)] =
        std::round(rounded.data[static_cast<std::size_t>(r)] * 1e4) / 1e4;
  write_mat(path("rounded.mat"), {rounded}, MAT_FT_MAT5);
  EXPECT_NEAR(io::open_recording(spec_for(path("rounded.mat"), RecordingFormat::mat))
                  ->info()
                  .sample_rate_hz,
              3000.0, 3000.0 * 2.0 * 0.5e-4 / 0.033);  // two roundings over 33 ms
  MatVariable nan = time_matrix("tsDS", tone(100, 1000.0, 50.0, 1.0), 1000.0);
  nan.data[100 + 7] = std::nan("");
  write_mat(path("nan.mat"), {nan}, MAT_FT_MAT5);
  expect_error(spec_for(path("nan.mat"), RecordingFormat::mat), "recording.variable",
               {"nan.mat", "row 8", "not a finite number"});
  write_text(path("text.mat"), "not a mat file at all, just text that is long enough .......\n");
  expect_error(spec_for(path("text.mat"), RecordingFormat::mat), "recording.file",
               {"text.mat", "MATLAB"});
  write_text(path("empty.mat"), "");
  expect_error(spec_for(path("empty.mat"), RecordingFormat::mat), "recording.file", {"empty.mat"});
}

// Fuzz findings: matio allocates what a corrupt header declares, so the
// reader checks the v5 structure first and refuses headerless (v4) files.
TEST_F(RecordingReaders, CorruptMatHeadersAreRefusedBeforeMatioAllocates) {
  write_mat(path("good.mat"), {time_matrix("tsDS", tone(64, 1000.0, 50.0, 1.0), 1000.0)},
            MAT_FT_MAT5);
  std::string bytes;
  {
    std::ifstream in(path("good.mat"), std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  ASSERT_GT(bytes.size(), 160u);
  // Header 128 bytes, miMATRIX tag 8, array flags 16: the dimensions' tag.
  std::string huge_dims = bytes;
  const unsigned char size[4] = {0x00, 0x08, 0x00, 0xF0};  // 0xF0000800 bytes
  std::memcpy(huge_dims.data() + 152 + 4, size, 4);
  write_text(path("huge_dims.mat"), huge_dims);
  expect_error(spec_for(path("huge_dims.mat"), RecordingFormat::mat), "recording.file",
               {"huge_dims.mat", "corrupt"});
  // A miMATRIX of 4 bytes, shorter than its array flags: matio read on into
  // the next tags and asked for 3.3 GB (fuzz_recording_readers, oom-9079ac8d).
  std::string short_matrix = bytes;
  const unsigned char four[4] = {0x04, 0x00, 0x00, 0x00};
  std::memcpy(short_matrix.data() + 128 + 4, four, 4);
  write_text(path("short_matrix.mat"), short_matrix);
  expect_error(spec_for(path("short_matrix.mat"), RecordingFormat::mat), "recording.file",
               {"short_matrix.mat", "shorter than its array flags"});
  write_text(path("v4.mat"),
             std::string("\0\0\0\0\x01\0\0\0\x01\0\0\0\0\0\0\0\xff\xff\xff\x7f", 20) + "abcd");
  expect_error(spec_for(path("v4.mat"), RecordingFormat::mat), "recording.file",
               {"v4.mat", "MATLAB file"});
}

TEST_F(RecordingReaders, RealTurningRecordingsAre10kHz) {
  const fs::path folder = fs::path(ROBOMILL_SOURCE_DIR) / ".." / "shared" / "recordings";
  if (!fs::exists(folder / "khasawneh_turning_2in_s_425_015.mat"))
    GTEST_SKIP() << "no " << folder;
  const std::pair<const char*, double> files[] = {{"khasawneh_turning_2in_s_425_015.mat", 12.5},
                                                  {"khasawneh_turning_2in_c_425_025.mat", 11.25},
                                                  {"khasawneh_turning_2in_s_320_050.mat", 12.5},
                                                  {"khasawneh_turning_2in_c_770_005.mat", 22.5}};
  for (const auto& [name, duration] : files) {
    SCOPED_TRACE(name);
    RecordingSpec spec = spec_for(folder / name, RecordingFormat::mat);
    spec.signal = monitoring::SignalKind::acceleration;
    auto source = io::open_recording(spec);  // the only numeric variable: tsDS
    EXPECT_NEAR(source->info().sample_rate_hz, 10000.0, 1e-6);
    EXPECT_NEAR(static_cast<double>(source->info().samples), duration * 10000.0, 2.0);
    const auto samples = read_all(*source, 8192);
    EXPECT_EQ(static_cast<std::int64_t>(samples.size()), source->info().samples);
    double energy = 0.0;
    for (const double x : samples)
      energy += x * x;
    EXPECT_GT(energy, 0.0);
  }
}

// --- CSV -------------------------------------------------------------------------

TEST_F(RecordingReaders, CsvStreamsWithTimeColumnOrSampleRate) {
  std::string text = "# accelerometer, 500 Hz\nt_s,ax_g,ay_g\n";
  std::vector<double> ax, ay;
  for (int i = 0; i < 600; ++i) {
    char row[96];
    ax.push_back(std::sin(0.1 * i));
    ay.push_back(std::cos(0.05 * i));
    std::snprintf(row, sizeof row, "%.17g,%.17g,%.17g\n", 1.0 + i * 0.002, ax.back(), ay.back());
    text += row;
    if (i == 300)
      text += "# a comment in the middle\n\n";
  }
  write_text(path("acc.csv"), text);
  RecordingSpec spec = spec_for(path("acc.csv"), RecordingFormat::csv);
  auto source = io::open_recording(spec);
  EXPECT_NEAR(source->info().sample_rate_hz, 500.0, 1e-6);
  // Counted up front (a comment and a blank line in the middle do not count),
  // so the detector can size its spectra.
  EXPECT_EQ(source->info().samples, static_cast<std::int64_t>(ax.size()));
  EXPECT_DOUBLE_EQ(source->info().start_s, 1.0);
  EXPECT_NE(source->info().description.find("column 'ax_g'"), std::string::npos);
  EXPECT_EQ(read_all(*source, 13), ax);
  spec.column = "ay_g";
  spec.scale = 9.80665;
  spec.start_s = 0.1;
  spec.duration_s = 0.5;
  const auto got = read_spec(spec, 64);
  ASSERT_EQ(got.size(), 250u);
  EXPECT_DOUBLE_EQ(got[0], ay[50] * 9.80665);
  EXPECT_DOUBLE_EQ(got[249], ay[299] * 9.80665);

  write_text(path("rate.csv"), "mic_Pa\n0.5\n-0.25\n1e-3\n");
  RecordingSpec rate = spec_for(path("rate.csv"), RecordingFormat::csv);
  expect_error(rate, "recording.sample_rate", {"rate.csv has no time column", "sample_rate"});
  rate.sample_rate_hz = 48000.0;
  EXPECT_EQ(read_spec(rate, 2), (std::vector<double>{0.5, -0.25, 1e-3}));
  rate.column = "p";
  expect_error(rate, "recording.column", {"no column 'p' in rate.csv (it has: mic_Pa)"});
}

// Issue 34: a DAQ export writes the time to 7 decimals (0.1 us), so at
// 44.1 kHz (22.6757... us) single steps are 22.6 or 22.7 us, 0.3 % off; clock
// jitter moves them further. Neither is a gap: the rate is the whole column's
// mean interval. A dropped block, or a repeated row, is refused by its line.
TEST_F(RecordingReaders, CsvTimeRoundedOrJitteredIsUniformAndAGapIsNot) {
  const double rate = 44100.0, t0 = 0.0123457;
  const int n = 3000;
  std::vector<double> values;
  const auto write = [&](const std::string& name, const std::function<bool(int)>& keep,
                         double jitter_fraction) {
    std::string text = "time,accel_ms2\n";
    values.clear();
    for (int i = 0; i < n; ++i) {
      if (!keep(i))
        continue;
      // A jitter of +-jitter_fraction of a step that nobody chose (a fixed LCG).
      const double u = std::fmod(0.6180339887 * (i + 1) * (i + 7), 1.0) * 2.0 - 1.0;
      const double t = t0 + (i + jitter_fraction * u) / rate;
      values.push_back(std::sin(0.37 * i) + 0.01 * i);
      char row[80];
      std::snprintf(row, sizeof row, "%.7f,%.17g\n", t, values.back());
      text += row;
    }
    write_text(path(name), text);
  };
  write(
      "rounded.csv", [](int) { return true; }, 0.0);
  auto source = io::open_recording(spec_for(path("rounded.csv"), RecordingFormat::csv));
  // (last - first) / (n - 1): two roundings of at most 0.05 us over 68 ms.
  EXPECT_NEAR(source->info().sample_rate_hz, rate, rate * 2.0 * 0.05e-6 / 0.068);
  EXPECT_NEAR(source->info().start_s, t0, 0.05e-6);
  EXPECT_EQ(read_all(*source, 257), values);
  write(
      "jitter.csv", [](int) { return true; }, 0.2);
  EXPECT_EQ(read_spec(spec_for(path("jitter.csv"), RecordingFormat::csv), 64), values);
  // Rows 1200 … 1299 dropped: line 1202 (header on line 1) follows row 1199.
  write(
      "dropped.csv", [](int i) { return i < 1200 || i >= 1300; }, 0.0);
  expect_error(spec_for(path("dropped.csv"), RecordingFormat::csv), "recording.file",
               {"dropped.csv line 1202", "gap", "about 100 sample(s) missing"});
  write(
      "repeat.csv", [](int) { return true; }, 0.0);
  std::string text;
  {
    std::ifstream in(path("repeat.csv"));
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::size_t line_700 = [&] {  // the start of data row 699 (line 701)
    std::size_t at = 0;
    for (int l = 0; l < 700; ++l)
      at = text.find('\n', at) + 1;
    return at;
  }();
  const std::size_t line_end = text.find('\n', line_700) + 1;
  text.insert(line_end, text.substr(line_700, line_end - line_700));  // line 701 twice
  write_text(path("repeat.csv"), text);
  expect_error(spec_for(path("repeat.csv"), RecordingFormat::csv), "recording.file",
               {"repeat.csv line 702", "repeats or goes back"});
}

TEST_F(RecordingReaders, BadCsvNamesTheLineAndColumn) {
  write_text(path("nan.csv"), "time,x\n0,1\n0.001,2\n0.002,nan\n0.003,4\n");
  expect_error(spec_for(path("nan.csv"), RecordingFormat::csv), "recording.file",
               {"nan.csv line 4, column 'x'", "not a finite number"});
  write_text(path("word.csv"), "time,x\n0,1\n0.001,2\n0.002,3\n0.003,four\n");
  expect_error(spec_for(path("word.csv"), RecordingFormat::csv), "recording.file",
               {"word.csv line 5, column 'x'", "expected a number, got 'four'"});
  write_text(path("gap.csv"), "t,x\n0,1\n0.001,2\n0.002,3\n0.004,4\n0.005,5\n");
  expect_error(spec_for(path("gap.csv"), RecordingFormat::csv), "recording.file",
               {"gap.csv line 5", "uniform"});
  write_text(path("ragged.csv"), "t,x\n0,1\n0.001\n");
  expect_error(spec_for(path("ragged.csv"), RecordingFormat::csv), "recording.file",
               {"ragged.csv line 3", "1 cells, the header has 2"});
  write_text(path("empty.csv"), "");
  expect_error(spec_for(path("empty.csv"), RecordingFormat::csv), "recording.file",
               {"empty.csv is empty"});
  write_text(path("header.csv"), "t,x\n");
  expect_error(spec_for(path("header.csv"), RecordingFormat::csv), "recording.file",
               {"header.csv has a header but no data rows"});
  RecordingSpec late = spec_for(path("gap.csv"), RecordingFormat::csv);
  late.start_s = 10.0;
  expect_error(late, "recording.file", {"gap.csv line 5"});
  write_text(path("short.csv"), "t,x\n0,1\n0.001,2\n0.002,3\n");
  RecordingSpec past = spec_for(path("short.csv"), RecordingFormat::csv);
  past.start_s = 1.0;
  expect_error(past, "recording.start", {"past the end of short.csv"});
}

// --- UFF58 time records ----------------------------------------------------------

TEST_F(RecordingReaders, UffTimeRecordsRoundTripAndSelectByChannel) {
  io::UffTimeRecord a;
  a.value = tone(512, 1024.0, 100.0, 2.0);
  a.dt_s = 1.0 / 1024.0;
  a.start_s = 0.25;
  a.unit = "m/s^2";
  a.specific_type = 12;
  a.label = "accelerometer x";
  a.response_direction = 1;
  io::UffTimeRecord b = a;
  b.value = tone(512, 1024.0, 200.0, 1.0);
  b.label = "accelerometer y";
  b.response_direction = 2;
  for (const auto encoding : {io::UffEncoding::ascii, io::UffEncoding::binary}) {
    SCOPED_TRACE(encoding == io::UffEncoding::ascii ? "ascii" : "binary");
    const fs::path file = path("time.uff");
    io::write_uff58_time_records(file, {a, b}, encoding);
    const auto records = io::read_uff58_time_records(file);
    ASSERT_EQ(records.size(), 2u);
    EXPECT_EQ(records[0].value, a.value);
    EXPECT_EQ(records[1].value, b.value);
    EXPECT_EQ(records[0].dt_s, a.dt_s);
    EXPECT_EQ(records[0].start_s, a.start_s);
    EXPECT_EQ(records[1].label, "accelerometer y");
    EXPECT_EQ(records[0].unit, "m/s^2");
    EXPECT_TRUE(records[0].unit_is_si);

    RecordingSpec spec = spec_for(file, RecordingFormat::uff);
    spec.channel = 2;
    auto source = io::open_recording(spec);
    EXPECT_EQ(source->info().sample_rate_hz, 1024.0);
    EXPECT_EQ(source->info().samples, 512);
    EXPECT_DOUBLE_EQ(source->info().start_s, 0.25);
    EXPECT_NE(source->info().description.find("record 2 of 2 ('accelerometer y')"),
              std::string::npos)
        << source->info().description;
    EXPECT_EQ(read_all(*source, 100), b.value);
    spec.channel = 0;
    const auto mean = read_spec(spec);
    ASSERT_EQ(mean.size(), 512u);
    EXPECT_NEAR(mean[7], 0.5 * (a.value[7] + b.value[7]), 1e-15);
    spec.channel = 3;
    expect_error(spec, "recording.channel", {"time.uff has 2 time records, got channel 3"});
  }
  // An FRF file holds no time record: said with the line of the FRF's record 6.
  io::UffFrf frf;
  frf.frf.frequency_hz = {10.0, 20.0};
  frf.frf.value = {{1e-6, 0.0}, {2e-6, -1e-6}};
  io::write_uff58(path("frf.uff"), {frf}, io::UffEncoding::ascii);
  expect_error(spec_for(path("frf.uff"), RecordingFormat::uff), "recording.file",
               {"frf.uff line", "no time record", "function type 4 is not 1"});
}

TEST_F(RecordingReaders, UffTimeRecordInGAndFrfReaderStillSkipsIt) {
  // Hand-written classic record: acceleration in g, abscissa in ms.
  const std::string text =
      "    -1\n    58\nhammer tap\nNONE\nNONE\nNONE\nNONE\n"
      "    1         1    0         0 NONE               1   3 NONE               0   0\n"
      "         2         4         1  0.00000E+00  5.00000E-01  0.00000E+00\n"
      "        17    0    0    0 Time                 ms\n"
      "        12    0    0    0 Acceleration         g\n"
      "         0    0    0    0 NONE                 NONE\n"
      "         0    0    0    0 NONE                 NONE\n"
      "  1.00000E+00  2.00000E+00 -1.00000E+00  5.00000E-01\n"
      "    -1\n";
  const auto records = io::parse_uff58_time_records(text, "tap.uff");
  ASSERT_EQ(records.size(), 1u);
  EXPECT_DOUBLE_EQ(records[0].dt_s, 0.5e-3);
  EXPECT_EQ(records[0].unit, "m/s^2");
  EXPECT_DOUBLE_EQ(records[0].value[1], 2.0 * 9.80665);
  try {
    io::parse_uff58(text, "tap.uff");
    ADD_FAILURE() << "an FRF read from a time record";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("function type 1 is not 4"), std::string::npos);
  }
}

// --- formats and arguments -------------------------------------------------------

TEST_F(RecordingReaders, FormatFromExtension) {
  EXPECT_EQ(io::recording_format_from_extension("a/B.WAV", "recording.file", 3),
            RecordingFormat::sound_file);
  EXPECT_EQ(io::recording_format_from_extension("x.mat", "recording.file", 3),
            RecordingFormat::mat);
  EXPECT_EQ(io::recording_format_from_extension("x.csv", "recording.file", 3),
            RecordingFormat::csv);
  EXPECT_EQ(io::recording_format_from_extension("x.unv", "recording.file", 3),
            RecordingFormat::uff);
  try {
    io::recording_format_from_extension("x.mp4", "recording.file", 3);
    ADD_FAILURE();
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), "recording.file");
    EXPECT_EQ(error.line(), 3);
    EXPECT_NE(std::string(error.what()).find("x.mp4"), std::string::npos);
  }
}

TEST_F(RecordingReaders, WriteWavLeavesNoTemporaryFiles) {
  io::write_wav(path("out.wav"), {{0.0, 0.5}}, 1000.0);
  EXPECT_THROW(io::write_wav(path("bad.wav"), {{0.0}, {}}, 1000.0), std::invalid_argument);
  EXPECT_THROW(io::write_wav(path("missing_dir/x.wav"), {{0.0}}, 1000.0), Error);
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 1u);
}

}  // namespace

}  // namespace test_recording_readers_cpp
