// libFuzzer target for the recording readers of `robomill listen`
// (io/recording.hpp): sound files through libsndfile, MATLAB files through
// matio, streamed CSV, UFF58 time records.
//
// Input: one selector byte, then the file's bytes. The selector's low two
// bits pick the reader (0 sound file, 1 MAT, 2 CSV, 3 UFF); bit 2 gives a
// sample rate (1000 Hz) as a job would; bits 3-4 the channel (0 = mix, 1..3).
// The bytes are written to a temporary file (the readers take paths: the
// libraries open files themselves) and every sample is read in odd-sized
// blocks. Contract: open_recording and read() return samples or throw
// robomill::InputError; every delivered sample is finite and the count
// matches info().samples when that is known. Anything else (another
// exception, a crash, a hang, a sanitizer report, unbounded memory) is a
// finding.

#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "robomill/core/error.hpp"
#include "robomill/io/recording.hpp"

namespace {

namespace fs = std::filesystem;
using robomill::io::RecordingFormat;

const fs::path& scratch_folder() {
  static const fs::path folder = [] {
    fs::path path =
        fs::temp_directory_path() / ("robomill-fuzz-recording-" + std::to_string(getpid()));
    fs::create_directories(path);
    return path;
  }();
  return folder;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1)
    return 0;
  const std::uint8_t selector = data[0];
  static const char* const kNames[] = {"fuzz.wav", "fuzz.mat", "fuzz.csv", "fuzz.uff"};
  const fs::path file = scratch_folder() / kNames[selector & 3];
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  robomill::io::RecordingSpec spec;
  spec.file = file;
  spec.format = static_cast<RecordingFormat>(selector & 3);
  if (selector & 4)
    spec.sample_rate_hz = 1000.0;
  spec.channel = (selector >> 3) & 3;
  spec.path = "recording";
  spec.line = 1;
  try {
    auto source = robomill::io::open_recording(spec);
    std::vector<double> block(777);
    std::int64_t count = 0;
    while (const std::size_t n = source->read(block)) {
      for (std::size_t i = 0; i < n; ++i) {
        if (!std::isfinite(block[i]))
          __builtin_trap();
      }
      count += static_cast<std::int64_t>(n);
    }
    if (source->info().samples >= 0 && count != source->info().samples)
      __builtin_trap();
    if (!(source->info().sample_rate_hz > 0.0) || !std::isfinite(source->info().sample_rate_hz))
      __builtin_trap();
  } catch (const robomill::InputError&) {
    // Rejected with a message: the expected outcome for most inputs.
  }
  return 0;
}
