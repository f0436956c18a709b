#pragma once
// The streaming half of the recording analysis (recording_analysis.cpp):
// Welch's averaged periodogram and a capped spectrogram, accumulated segment
// by segment while the signal is read, so that memory does not grow with the
// recording's length. Private to src/monitoring.

#include <fftw3.h>

#include <cstddef>
#include <vector>

namespace robomill::monitoring::detail {

/// One FFTW real-to-complex plan and its aligned buffers, created once (under
/// the planner mutex) and executed many times without allocating.
class FftWorkspace {
 public:
  explicit FftWorkspace(std::size_t length);
  ~FftWorkspace();
  FftWorkspace(const FftWorkspace&) = delete;
  FftWorkspace& operator=(const FftWorkspace&) = delete;
  double* input() { return input_; }
  const fftw_complex* output() const { return output_; }
  void execute() { fftw_execute(plan_); }

 private:
  double* input_ = nullptr;
  fftw_complex* output_ = nullptr;
  fftw_plan plan_ = nullptr;
};

/// Hann segments of `length` samples at 50 % overlap: the sum of their
/// periodograms (|X_k|², mean removed per segment) and, per spectrogram
/// column, the sum over the consecutive segments the column holds. When the
/// columns reach `max_columns`, neighbours are merged pairwise and each
/// later column holds twice as many segments: at most `max_columns` × bins
/// values, whatever the length.
class WelchStream {
 public:
  WelchStream(std::size_t length, std::size_t max_columns, std::size_t block);
  /// Appends samples; processes every segment that is complete.
  void push(const double* samples, std::size_t count);
  /// Closes the last, partial spectrogram column.
  void finish();

  std::size_t length() const { return length_; }
  std::size_t bins() const { return length_ / 2 + 1; }
  std::size_t segments() const { return segments_; }
  double window_power() const { return window_power_; }  ///< Σ w²
  const std::vector<double>& periodogram_sum() const { return sum_; }
  std::size_t columns() const { return column_count_; }
  /// Column c's periodogram sum (bins() values) and its segment count.
  const double* column(std::size_t c) const { return columns_.data() + c * bins(); }
  std::size_t column_segments(std::size_t c) const { return column_segments_[c]; }
  /// Index of the first sample of column c's first segment.
  std::size_t column_first_sample(std::size_t c) const { return column_first_[c]; }

 private:
  void process_segment(const double* samples);
  void close_column();

  std::size_t length_, hop_, max_columns_;
  std::vector<double> window_;
  double window_power_ = 0.0;
  FftWorkspace fft_;
  std::vector<double> pending_;                       ///< samples not yet consumed by a segment
  std::size_t pending_size_ = 0, pending_first_ = 0;  ///< count, index of pending_[0]
  std::vector<double> sum_, current_;
  std::size_t segments_ = 0, in_current_ = 0, per_column_ = 1, current_first_ = 0;
  std::vector<double> columns_;
  std::vector<std::size_t> column_segments_, column_first_;
  std::size_t column_count_ = 0;
};

}  // namespace robomill::monitoring::detail
