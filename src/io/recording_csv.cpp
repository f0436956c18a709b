// CSV recordings, streamed: rows are read from the file as blocks are asked
// for, so memory stays flat however long the recording is. The time base
// comes from the first two rows of the time column (or the job's
// sample_rate); every later row's interval is checked against it, so a
// dropped or repeated sample is reported with its line instead of silently
// bending the spectrum.

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "recording_detail.hpp"
#include "robomill/core/text.hpp"
#include "robomill/io/recording.hpp"

namespace robomill::io {
namespace recording_detail {
namespace {

constexpr std::size_t kMaxLineBytes = 1 << 20;

std::string lower(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

bool is_time_name(std::string_view name) {
  const std::string key = lower(name);
  return key == "t_s" || key == "time" || key == "time_s" || key == "t";
}

// Cells of one line, split at commas and trimmed; a header name may be quoted.
void split_cells(std::string_view line, std::vector<std::string_view>& cells) {
  cells.clear();
  std::size_t begin = 0;
  while (true) {
    const std::size_t comma = line.find(',', begin);
    std::string_view cell =
        text::trim(line.substr(begin, comma == std::string_view::npos ? line.npos : comma - begin));
    if (cell.size() >= 2 && cell.front() == '"' && cell.back() == '"')
      cell = cell.substr(1, cell.size() - 2);
    cells.push_back(cell);
    if (comma == std::string_view::npos)
      return;
    begin = comma + 1;
  }
}

std::string shown_cell(std::string_view cell) {
  std::string out(cell.substr(0, 32));
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126)
      c = '?';
  }
  return "'" + out + (cell.size() > 32 ? "...'" : "'");
}

/// The data rows of a CSV file (lines that are neither empty nor '#'
/// comments, less the header) and where the last one starts.
struct CsvRows {
  std::int64_t data_rows = 0;
  std::streamoff last_row_offset = -1;  ///< -1: no data row
  int last_row_line = 0;                ///< 1-based line number
};

/// Counted in one pass over 1 MiB chunks: the detector sizes its spectra by
/// the recording's length, and the time base is the whole column's mean
/// interval (its first and last rows), both of which a streamed file
/// otherwise tells only at its end. Memory does not grow with the file.
CsvRows scan_data_rows(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::vector<char> chunk(std::size_t{1} << 20);
  std::int64_t rows = 0;
  std::streamoff chunk_start = 0, last_start = -1;
  int line = 1, last_line = 0;
  bool line_start = true;  // no character but blanks seen on this line yet
  while (in) {
    in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    const std::streamsize got = in.gcount();
    for (std::streamsize i = 0; i < got; ++i) {
      const char c = chunk[static_cast<std::size_t>(i)];
      if (c == '\n') {
        line_start = true;
        ++line;
      } else if (line_start && c != ' ' && c != '\t' && c != '\r') {
        if (c != '#') {
          ++rows;
          last_start = chunk_start + i;
          last_line = line;
        }
        line_start = false;
      }
    }
    chunk_start += got;
  }
  CsvRows result;
  result.data_rows = std::max<std::int64_t>(0, rows - 1);
  if (result.data_rows > 0) {
    result.last_row_offset = last_start;
    result.last_row_line = last_line;
  }
  return result;
}

class CsvSource final : public monitoring::SignalSource {
 public:
  explicit CsvSource(const RecordingSpec& spec)
      : spec_(spec), stream_(spec.file, std::ios::binary) {
    if (!stream_)
      fail(spec_, "file", "cannot open " + file_name(spec_));
    read_header();
    const CsvRows rows = scan_data_rows(spec_.file);
    double rate = 0.0;
    if (time_column_) {
      // The time base: the whole column's mean interval, from its first and
      // last rows (a time rounded to a few decimals moves single steps, not
      // this); every step is checked against it as it streams past.
      if (!next_row())
        fail(spec_, "file", file_name(spec_) + " has a header but no data rows");
      first_time_ = row_time_;
      previous_time_ = row_time_;
      pending_.push_back(row_value_);
      if (rows.data_rows < 2)
        fail(spec_, "file", file_name(spec_) + ": the time column needs at least 2 rows, got 1");
      const double last_time = last_row_time(rows);
      span_ = last_time - first_time_;
      steps_ = rows.data_rows - 1;
      interval_ = span_ / static_cast<double>(steps_);
      if (!(interval_ > 0.0) || !std::isfinite(interval_))
        fail(spec_, "file",
             file_name(spec_) + ": the time column must increase (from " + number(first_time_) +
                 " s on its first row to " + number(last_time) + " s on line " +
                 std::to_string(rows.last_row_line) + ")");
      rate = 1.0 / interval_;
      check_rate_agrees(spec_, rate);
      // The second row too, read and checked now: a file too short for the
      // detector to stream still has its first rows' errors named.
      if (next_row()) {
        check_interval();
        pending_.push_back(row_value_);
      }
    } else {
      if (!spec_.sample_rate_hz)
        fail(spec_, "sample_rate",
             file_name(spec_) +
                 " has no time column (t_s, time, time_s or t); give the "
                 "sample_rate");
      rate = *spec_.sample_rate_hz;
      if (!next_row())
        fail(spec_, "file", file_name(spec_) + " has a header but no data rows");
      pending_.push_back(row_value_);
    }
    // Skip the start, reading rows as we go (streamed, so nothing is held).
    const std::int64_t skip = start_index(spec_, rate);
    for (std::int64_t i = 0; i < skip; ++i) {
      if (!take_value())
        fail(spec_, "start",
             "start " + number(spec_.start_s) + " s is past the end of " + file_name(spec_) + " (" +
                 std::to_string(i) + " rows, " + seconds(static_cast<double>(i) / rate) + ")");
    }
    if (!has_value())
      fail(spec_, "start",
           "start " + number(spec_.start_s) + " s is past the end of " + file_name(spec_) + " (" +
               seconds(static_cast<double>(skip) / rate) + ")");
    remaining_ = duration_samples(spec_, rate);
    info_.sample_rate_hz = rate;
    // The samples to come: the rows after the start, at most the duration's.
    const std::int64_t left = std::max<std::int64_t>(0, rows.data_rows - skip);
    info_.samples = remaining_ >= 0 ? std::min(left, remaining_) : left;
    info_.start_s = (time_column_ ? first_time_ : 0.0) + static_cast<double>(skip) / rate;
    info_.kind = spec_.signal;
    info_.full_scale = 0.0;
    info_.description = file_name(spec_) + ", column '" + columns_[value_column_] + "' (" +
                        std::to_string(value_column_ + 1) + " of " +
                        std::to_string(columns_.size()) + "), " + number(rate) + " Hz" +
                        (time_column_ ? " (from column '" + columns_[*time_column_] + "')" : "") +
                        ", " + std::to_string(info_.samples) + " rows, streamed";
  }

  const monitoring::SignalInfo& info() const override { return info_; }

  std::size_t read(std::span<double> out) override {
    std::size_t filled = 0;
    while (filled < out.size() && remaining_ != 0) {
      if (!take_value(&out[filled]))
        break;
      ++filled;
      if (remaining_ > 0)
        --remaining_;
    }
    return filled;
  }

 private:
  void read_header() {
    std::string_view line;
    if (!next_line(line))
      fail(spec_, "file", file_name(spec_) + " is empty (expected a header row, then numbers)");
    split_cells(line, cells_);
    for (const std::string_view cell : cells_)
      columns_.emplace_back(cell);
    for (std::size_t c = 0; c < columns_.size(); ++c) {
      if (!time_column_ && is_time_name(columns_[c]))
        time_column_ = c;
    }
    // A header of numbers is data without names: say what is missing.
    double probe = 0.0;
    const std::string_view first = cells_.front();
    if (!first.empty() && std::from_chars(first.data(), first.data() + first.size(), probe).ptr ==
                              first.data() + first.size())
      fail(spec_, "file",
           file_name(spec_) + " line " + std::to_string(line_) +
               ": expected a header row of column names, got numbers " + shown_cell(line));
    std::optional<std::size_t> value;
    if (spec_.column.empty()) {
      for (std::size_t c = 0; c < columns_.size() && !value; ++c) {
        if (c != time_column_)
          value = c;
      }
      if (!value)
        fail(spec_, "column", file_name(spec_) + " has only a time column, no values");
    } else {
      for (std::size_t c = 0; c < columns_.size() && !value; ++c) {
        if (columns_[c] == spec_.column)
          value = c;
      }
      if (!value) {
        std::string listed;
        for (const std::string& name : columns_)
          listed += (listed.empty() ? "" : ", ") + name;
        fail(spec_, "column",
             "no column '" + spec_.column + "' in " + file_name(spec_) + " (it has: " + listed +
                 ")");
      }
      if (value == time_column_)
        fail(spec_, "column",
             file_name(spec_) + ": column '" + spec_.column + "' is the time; name a value column");
    }
    value_column_ = *value;
  }

  // The time on the file's last data row (scan_data_rows found where it starts).
  double last_row_time(const CsvRows& rows) {
    std::ifstream in(spec_.file, std::ios::binary);
    in.seekg(rows.last_row_offset);
    std::string text;
    if (!std::getline(in, text))
      fail(spec_, "file", "cannot read " + file_name(spec_) + " (I/O error)");
    std::vector<std::string_view> cells;
    split_cells(text::trim(text), cells);
    const std::string where = file_name(spec_) + " line " + std::to_string(rows.last_row_line);
    if (cells.size() != columns_.size())
      fail(spec_, "file",
           where + ": " + std::to_string(cells.size()) + " cells, the header has " +
               std::to_string(columns_.size()));
    std::string_view cell = cells[*time_column_];
    if (!cell.empty() && cell.front() == '+')
      cell.remove_prefix(1);
    double time = 0.0;
    const auto result = std::from_chars(cell.data(), cell.data() + cell.size(), time);
    if (cell.empty() || result.ec != std::errc() || result.ptr != cell.data() + cell.size() ||
        !std::isfinite(time))
      fail(spec_, "file",
           where + ", column '" + columns_[*time_column_] + "': expected a finite time, got " +
               shown_cell(cells[*time_column_]));
    return time;
  }

  // The next line that is neither blank nor a '#' comment.
  bool next_line(std::string_view& line) {
    while (true) {
      if (!std::getline(stream_, buffer_)) {
        if (stream_.bad())
          fail(spec_, "file", "cannot read " + file_name(spec_) + " (I/O error)");
        return false;
      }
      ++line_;
      if (buffer_.size() > kMaxLineBytes)
        fail(spec_, "file",
             file_name(spec_) + " line " + std::to_string(line_) +
                 ": line longer than 1 MiB (not a CSV recording?)");
      line = text::trim(buffer_);
      if (!line.empty() && line.front() != '#')
        return true;
    }
  }

  double cell_number(std::size_t column) {
    std::string_view cell = cells_[column];
    if (!cell.empty() && cell.front() == '+')
      cell.remove_prefix(1);
    double value = 0.0;
    const auto result = std::from_chars(cell.data(), cell.data() + cell.size(), value);
    const std::string where =
        file_name(spec_) + " line " + std::to_string(line_) + ", column '" + columns_[column] + "'";
    if (cell.empty() || result.ec != std::errc() || result.ptr != cell.data() + cell.size())
      fail(spec_, "file", where + ": expected a number, got " + shown_cell(cells_[column]));
    if (!std::isfinite(value))
      fail(spec_, "file", where + ": " + shown_cell(cells_[column]) + " is not a finite number");
    return value;
  }

  // Parses the next data row into row_time_/row_value_; false at the end.
  bool next_row() {
    std::string_view line;
    if (!next_line(line))
      return false;
    split_cells(line, cells_);
    if (cells_.size() != columns_.size())
      fail(spec_, "file",
           file_name(spec_) + " line " + std::to_string(line_) + ": " +
               std::to_string(cells_.size()) + " cells, the header has " +
               std::to_string(columns_.size()));
    row_value_ = cell_number(value_column_) * spec_.scale;
    if (!std::isfinite(row_value_))
      fail(spec_, "file",
           file_name(spec_) + " line " + std::to_string(line_) +
               ": the value overflows after scaling");
    if (time_column_)
      row_time_ = cell_number(*time_column_);
    return true;
  }

  bool has_value() {
    if (pending_.empty() && !finished_) {
      if (next_row()) {
        check_interval();
        pending_.push_back(row_value_);
      } else {
        finished_ = true;
      }
    }
    return !pending_.empty();
  }

  bool take_value(double* out = nullptr) {
    if (!has_value())
      return false;
    if (out)
      *out = pending_.front();
    pending_.erase(pending_.begin());
    return true;
  }

  void check_interval() {
    if (!time_column_)
      return;
    if (const std::string problem =
            irregular_time_step(row_time_, row_time_ - previous_time_, span_, steps_);
        !problem.empty())
      fail(spec_, "file", file_name(spec_) + " line " + std::to_string(line_) + ": " + problem);
    previous_time_ = row_time_;
  }

  RecordingSpec spec_;
  std::ifstream stream_;
  std::string buffer_;
  std::vector<std::string_view> cells_;
  std::vector<std::string> columns_;
  std::optional<std::size_t> time_column_;
  std::size_t value_column_ = 0;
  int line_ = 0;
  double row_time_ = 0.0;
  double row_value_ = 0.0;
  double first_time_ = 0.0;
  double previous_time_ = 0.0;
  double interval_ = 0.0;
  double span_ = 0.0;            // last time less the first
  std::int64_t steps_ = 1;       // data rows less one
  std::vector<double> pending_;  // at most 2 values read ahead (the time base)
  bool finished_ = false;
  std::int64_t remaining_ = -1;  // -1: to the end
  monitoring::SignalInfo info_;
};

}  // namespace

std::unique_ptr<monitoring::SignalSource> open_csv(const RecordingSpec& spec) {
  return std::make_unique<CsvSource>(spec);
}

}  // namespace recording_detail
}  // namespace robomill::io
