// Streaming Welch accumulation and the capped spectrogram (welch_stream.hpp).

#include "welch_stream.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <new>
#include <numbers>

#include "robomill/monitoring/spectrum.hpp"

namespace robomill::monitoring::detail {

FftWorkspace::FftWorkspace(std::size_t length) {
  input_ = fftw_alloc_real(length);
  output_ = fftw_alloc_complex(length / 2 + 1);
  if (!input_ || !output_) {
    fftw_free(input_);
    fftw_free(output_);
    throw std::bad_alloc();
  }
  const std::lock_guard lock(fftw_planner_mutex());
  plan_ = fftw_plan_dft_r2c_1d(static_cast<int>(length), input_, output_, FFTW_ESTIMATE);
}

FftWorkspace::~FftWorkspace() {
  {
    const std::lock_guard lock(fftw_planner_mutex());
    fftw_destroy_plan(plan_);
  }
  fftw_free(input_);
  fftw_free(output_);
}

WelchStream::WelchStream(std::size_t length, std::size_t max_columns, std::size_t block)
    : length_(length),
      hop_(length / 2),
      max_columns_(std::max<std::size_t>(2, max_columns & ~std::size_t{1})),
      window_(length),
      fft_(length),
      pending_(length + block),
      sum_(length / 2 + 1, 0.0),
      current_(length / 2 + 1, 0.0),
      columns_(max_columns_ * (length / 2 + 1), 0.0),
      column_segments_(max_columns_, 0),
      column_first_(max_columns_, 0) {
  // Periodic Hann window (as amplitude_spectrum): 50 % overlapped copies sum
  // to a constant, so every sample weighs the same in the average.
  for (std::size_t i = 0; i < length; ++i) {
    window_[i] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) /
                                      static_cast<double>(length));
    window_power_ += window_[i] * window_[i];
  }
}

void WelchStream::push(const double* samples, std::size_t count) {
  while (count > 0) {
    const std::size_t take = std::min(count, pending_.size() - pending_size_);
    std::memcpy(pending_.data() + pending_size_, samples, take * sizeof(double));
    pending_size_ += take;
    samples += take;
    count -= take;
    std::size_t offset = 0;
    while (offset + length_ <= pending_size_) {
      process_segment(pending_.data() + offset);
      offset += hop_;
    }
    if (offset > 0) {
      std::memmove(pending_.data(), pending_.data() + offset,
                   (pending_size_ - offset) * sizeof(double));
      pending_size_ -= offset;
      pending_first_ += offset;
    }
  }
}

void WelchStream::process_segment(const double* samples) {
  // The segment's mean is removed (a DC offset or a slow drift would leak
  // into the lowest bins through the window's side lobes).
  double mean = 0.0;
  for (std::size_t i = 0; i < length_; ++i)
    mean += samples[i];
  mean /= static_cast<double>(length_);
  double* in = fft_.input();
  for (std::size_t i = 0; i < length_; ++i)
    in[i] = (samples[i] - mean) * window_[i];
  fft_.execute();
  const fftw_complex* out = fft_.output();
  const std::size_t n = bins();
  if (in_current_ == 0)
    current_first_ = pending_first_ + static_cast<std::size_t>(samples - pending_.data());
  for (std::size_t k = 0; k < n; ++k) {
    const double power = out[k][0] * out[k][0] + out[k][1] * out[k][1];
    sum_[k] += power;
    current_[k] += power;
  }
  ++segments_;
  if (++in_current_ == per_column_)
    close_column();
}

void WelchStream::close_column() {
  const std::size_t n = bins();
  std::copy(current_.begin(), current_.end(), columns_.begin() + column_count_ * n);
  std::fill(current_.begin(), current_.end(), 0.0);
  column_segments_[column_count_] = in_current_;
  column_first_[column_count_] = current_first_;
  ++column_count_;
  in_current_ = 0;
  if (column_count_ < max_columns_)
    return;
  // Full: merge neighbours pairwise; later columns hold twice the segments.
  for (std::size_t c = 0; c < column_count_ / 2; ++c) {
    const double* a = columns_.data() + 2 * c * n;
    const double* b = a + n;
    double* to = columns_.data() + c * n;
    for (std::size_t k = 0; k < n; ++k)
      to[k] = a[k] + b[k];
    column_segments_[c] = column_segments_[2 * c] + column_segments_[2 * c + 1];
    column_first_[c] = column_first_[2 * c];
  }
  column_count_ /= 2;
  per_column_ *= 2;
}

void WelchStream::finish() {
  if (in_current_ > 0 && column_count_ < max_columns_)
    close_column();
}

}  // namespace robomill::monitoring::detail
