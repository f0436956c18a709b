#pragma once
// CSV tables: a header row whose column names carry units
// (`spindle_rpm,depth_limit_mm`), then numbers. Written with enough digits to
// round-trip a double; read with the line of every bad cell in the message.

#include <filesystem>
#include <string>
#include <vector>

namespace robomill::io {

class CsvTable {
 public:
  explicit CsvTable(std::vector<std::string> columns);

  /// Appends a row; throws std::invalid_argument if its size differs from the
  /// header's, and robomill::NumericalError if a value is NaN or infinite
  /// (robomill never writes a non-finite result).
  void add_row(const std::vector<double>& values);

  const std::vector<std::string>& columns() const noexcept { return columns_; }
  std::size_t rows() const noexcept { return values_.size() / columns_.size(); }
  double at(std::size_t row, std::size_t column) const {
    return values_[row * columns_.size() + column];
  }
  /// Index of a column, or -1.
  int find(const std::string& column) const noexcept;

  /// Serialized with '\n' line ends and 12 significant digits.
  std::string to_string() const;

 private:
  std::vector<std::string> columns_;
  std::vector<double> values_;
};

/// Reads a numeric CSV with a header row. Blank lines and lines starting with
/// '#' are skipped. Throws InputError("<file> line N", ...) for ragged rows or
/// cells that are not finite numbers.
CsvTable read_csv(const std::filesystem::path& file);
CsvTable parse_csv(const std::string& text, const std::string& source_name);

}  // namespace robomill::io
