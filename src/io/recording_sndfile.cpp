// Sound files through libsndfile (WAV, FLAC, AIFF, ...): read in blocks with
// sf_readf_double and deinterleaved, so memory stays flat however long the
// recording is; and write_wav, the synthetic examples' and tests' writer.

#include <sndfile.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <system_error>

#include "recording_detail.hpp"
#include "robomill/io/recording.hpp"

namespace robomill::io {
namespace recording_detail {
namespace {

// Frames per sf_readf_double call: bounds the interleaved buffer whatever
// block size the caller asks for.
constexpr std::size_t kChunkFrames = 4096;

struct SndfileCloser {
  void operator()(SNDFILE* file) const noexcept { sf_close(file); }
};
using SndfileHandle = std::unique_ptr<SNDFILE, SndfileCloser>;

// "PCM 24-bit", "float 32-bit", ...; integer encodings are read as ±1 full
// scale by libsndfile (SFC_SET_NORM_DOUBLE is on by default).
struct Encoding {
  const char* name;
  bool integer;
};

Encoding encoding_of(int format) {
  switch (format & SF_FORMAT_SUBMASK) {
    case SF_FORMAT_PCM_S8:
    case SF_FORMAT_PCM_U8:
      return {"PCM 8-bit", true};
    case SF_FORMAT_PCM_16:
      return {"PCM 16-bit", true};
    case SF_FORMAT_PCM_24:
      return {"PCM 24-bit", true};
    case SF_FORMAT_PCM_32:
      return {"PCM 32-bit", true};
    case SF_FORMAT_FLOAT:
      return {"float 32-bit", false};
    case SF_FORMAT_DOUBLE:
      return {"float 64-bit", false};
    case SF_FORMAT_ULAW:
      return {"u-law", true};
    case SF_FORMAT_ALAW:
      return {"A-law", true};
    case SF_FORMAT_VORBIS:
      return {"Vorbis", false};
    default:
      return {"compressed", true};
  }
}

class SoundFileSource final : public monitoring::SignalSource {
 public:
  SoundFileSource(const RecordingSpec& spec, SndfileHandle file, int channels, std::int64_t frames,
                  monitoring::SignalInfo info)
      : spec_(spec),
        file_(std::move(file)),
        channels_(channels),
        remaining_(frames),
        expected_(frames),
        info_(std::move(info)) {}

  const monitoring::SignalInfo& info() const override { return info_; }

  std::size_t read(std::span<double> out) override {
    std::size_t filled = 0;
    const auto channels = static_cast<std::size_t>(channels_);
    while (filled < out.size() && remaining_ > 0) {
      const std::size_t want =
          std::min({out.size() - filled, kChunkFrames, static_cast<std::size_t>(remaining_)});
      buffer_.resize(want * channels);
      const sf_count_t got =
          sf_readf_double(file_.get(), buffer_.data(), static_cast<sf_count_t>(want));
      if (got <= 0) {
        // The header promised more frames than the file holds (a cut data
        // chunk, a read error): say so rather than deliver a short signal.
        const std::int64_t delivered = expected_ - remaining_;
        const char* why = sf_strerror(file_.get());
        fail(spec_, "file",
             file_name(spec_) + " ends after " + std::to_string(delivered) + " of the " +
                 std::to_string(expected_) + " samples its header declares (truncated file" +
                 (sf_error(file_.get()) != SF_ERR_NO_ERROR ? std::string(": ") + why : "") + ")");
      }
      const auto frames = static_cast<std::size_t>(got);
      for (std::size_t f = 0; f < frames; ++f) {
        const double* frame = buffer_.data() + f * channels;
        double value = 0.0;
        if (spec_.channel == 0) {
          for (std::size_t c = 0; c < channels; ++c)
            value += frame[c];
          value /= static_cast<double>(channels);
        } else {
          value = frame[spec_.channel - 1];
        }
        value *= spec_.scale;
        if (!std::isfinite(value))
          fail(spec_, "file",
               file_name(spec_) + ": sample " +
                   std::to_string(expected_ - remaining_ + static_cast<std::int64_t>(f) + 1) +
                   " is not a finite number");
        out[filled + f] = value;
      }
      filled += frames;
      remaining_ -= got;
    }
    if (remaining_ == 0)
      buffer_ = {};
    return filled;
  }

 private:
  RecordingSpec spec_;
  SndfileHandle file_;
  int channels_;
  std::int64_t remaining_;
  std::int64_t expected_;
  std::vector<double> buffer_;
  monitoring::SignalInfo info_;
};

}  // namespace

std::unique_ptr<monitoring::SignalSource> open_sound_file(const RecordingSpec& spec) {
  SF_INFO sf_info{};
  SndfileHandle file(sf_open(spec.file.c_str(), SFM_READ, &sf_info));
  if (!file)
    fail(spec, "file",
         "cannot read " + file_name(spec) +
             " as a sound file (WAV, FLAC, AIFF): " + sf_strerror(nullptr));
  const int channels = sf_info.channels;
  if (channels < 1 || sf_info.samplerate <= 0)
    fail(spec, "file",
         file_name(spec) + ": the header declares " + std::to_string(channels) + " channels at " +
             std::to_string(sf_info.samplerate) + " Hz");
  if (sf_info.frames <= 0)
    fail(spec, "file", file_name(spec) + " holds no samples (an empty recording)");
  if (spec.channel > channels)
    fail(spec, "channel",
         file_name(spec) + " has " + std::to_string(channels) + " channel" +
             (channels == 1 ? "" : "s") + ", got channel " + std::to_string(spec.channel));
  const auto rate = static_cast<double>(sf_info.samplerate);
  check_rate_agrees(spec, rate);
  const Window cut = window(spec, sf_info.frames, rate);
  if (cut.first > 0 && sf_seek(file.get(), cut.first, SEEK_SET) != cut.first)
    fail(spec, "start",
         "cannot seek to " + number(spec.start_s) + " s in " + file_name(spec) + ": " +
             sf_strerror(file.get()));
  const Encoding encoding = encoding_of(sf_info.format);
  monitoring::SignalInfo info;
  info.sample_rate_hz = rate;
  info.samples = cut.count;
  info.start_s = static_cast<double>(cut.first) / rate;
  info.kind = spec.signal;
  // Integer encodings read as ±1 full scale; a float file has no full scale.
  info.full_scale = encoding.integer ? std::abs(spec.scale) : 0.0;
  info.description = file_name(spec) + ", " +
                     (spec.channel == 0 ? "mean of " + std::to_string(channels) + " channels"
                                        : "channel " + std::to_string(spec.channel) + " of " +
                                              std::to_string(channels)) +
                     ", " + number(rate) + " Hz, " + encoding.name + ", " +
                     seconds(static_cast<double>(cut.count) / rate);
  return std::make_unique<SoundFileSource>(spec, std::move(file), channels, cut.count,
                                           std::move(info));
}

}  // namespace recording_detail

using recording_detail::kChunkFrames;
using recording_detail::SndfileHandle;

void write_wav(const std::filesystem::path& file, const std::vector<std::vector<double>>& channels,
               double sample_rate_hz, int bits, double full_scale) {
  if (channels.empty() || channels.front().empty())
    throw std::invalid_argument("write_wav: no samples");
  for (const auto& channel : channels) {
    if (channel.size() != channels.front().size())
      throw std::invalid_argument("write_wav: channels of different lengths");
  }
  if (!(sample_rate_hz >= 1.0) || sample_rate_hz > 1e7 ||
      sample_rate_hz != std::round(sample_rate_hz))
    throw std::invalid_argument("write_wav: the sample rate must be a whole number of Hz");
  if (bits != 16 && bits != 24 && bits != 32)
    throw std::invalid_argument("write_wav: bits must be 16, 24 or 32");
  if (!std::isfinite(full_scale) || !(full_scale > 0.0))
    throw std::invalid_argument("write_wav: full scale must be positive");

  SF_INFO sf_info{};
  sf_info.samplerate = static_cast<int>(sample_rate_hz);
  sf_info.channels = static_cast<int>(channels.size());
  sf_info.format = SF_FORMAT_WAV | (bits == 16   ? SF_FORMAT_PCM_16
                                    : bits == 24 ? SF_FORMAT_PCM_24
                                                 : SF_FORMAT_FLOAT);
  // A temporary name in the same folder, renamed when complete: no reader
  // ever sees a half-written file (DESIGN.md §4).
  const std::filesystem::path folder =
      file.parent_path().empty() ? std::filesystem::path(".") : file.parent_path();
  std::random_device random;
  std::string name = file.filename().string();
  name.insert(0, 1, '.');  // (built in place: GCC 12 warns falsely on "." + name)
  name += ".tmp";
  name += std::to_string(random());
  const std::filesystem::path temporary = folder / name;
  SndfileHandle out(sf_open(temporary.c_str(), SFM_WRITE, &sf_info));
  if (!out)
    throw Error("cannot write " + file.string() + ": " + sf_strerror(nullptr));

  const std::size_t count = channels.front().size();
  const std::size_t width = channels.size();
  bool ok = true;
  if (bits == 32) {
    std::vector<double> frames(std::min(count, kChunkFrames) * width);
    for (std::size_t start = 0; start < count && ok; start += kChunkFrames) {
      const std::size_t n = std::min(kChunkFrames, count - start);
      for (std::size_t f = 0; f < n; ++f)
        for (std::size_t c = 0; c < width; ++c)
          frames[f * width + c] = channels[c][start + f];
      ok = sf_writef_double(out.get(), frames.data(), static_cast<sf_count_t>(n)) ==
           static_cast<sf_count_t>(n);
    }
  } else {
    // Integers left-justified in 32 bits, quantized here: libsndfile reads
    // PCM back as code / 2^(bits-1), so x → round(x·2^(bits-1)) round-trips
    // within half a step (its own double writer scales by 2^(bits-1) − 1).
    const double steps = std::ldexp(1.0, bits - 1);
    const int shift = 32 - bits;
    std::vector<int> frames(std::min(count, kChunkFrames) * width);
    for (std::size_t start = 0; start < count && ok; start += kChunkFrames) {
      const std::size_t n = std::min(kChunkFrames, count - start);
      for (std::size_t f = 0; f < n; ++f) {
        for (std::size_t c = 0; c < width; ++c) {
          const double x = channels[c][start + f] / full_scale;
          const double code =
              std::isnan(x) ? 0.0 : std::clamp(std::round(x * steps), -steps, steps - 1.0);
          frames[f * width + c] =
              static_cast<int>(static_cast<std::int64_t>(code) * (1LL << shift));
        }
      }
      ok = sf_writef_int(out.get(), frames.data(), static_cast<sf_count_t>(n)) ==
           static_cast<sf_count_t>(n);
    }
  }
  const std::string why = ok ? "" : sf_strerror(out.get());
  out.reset();  // sf_close writes the final header sizes
  std::error_code error;
  if (ok)
    std::filesystem::rename(temporary, file, error);
  if (!ok || error) {
    std::filesystem::remove(temporary, error);
    throw Error("cannot write " + file.string() + ": " + (ok ? "rename failed" : why));
  }
}

}  // namespace robomill::io
