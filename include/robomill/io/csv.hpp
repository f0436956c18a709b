#pragma once
// CSV tables: a header row whose column names carry units
// (`spindle_rpm,depth_limit_mm`), then numbers. Written with enough digits to
// round-trip a double; read with the line of every bad cell in the message.

#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace robomill::io {

class CsvTable {
 public:
  /// A cell: a number, or a word such as "hopf" (text cells must not contain
  /// commas, quotes or line breaks).
  using Cell = std::variant<double, std::string>;

  explicit CsvTable(std::vector<std::string> columns);

  /// Appends a row; throws std::invalid_argument if its size differs from the
  /// header's, and robomill::NumericalError if a value is NaN or infinite
  /// (robomill never writes a non-finite result).
  void add_row(const std::vector<double>& values);
  void add_cells(const std::vector<Cell>& cells);

  const std::vector<std::string>& columns() const noexcept { return columns_; }
  std::size_t rows() const noexcept { return cells_.size() / columns_.size(); }
  /// The number in a cell (throws std::bad_variant_access for a text cell).
  double at(std::size_t row, std::size_t column) const {
    return std::get<double>(cells_[row * columns_.size() + column]);
  }
  /// A cell, number or text (row-major, as added).
  const Cell& cell(std::size_t row, std::size_t column) const {
    return cells_[row * columns_.size() + column];
  }
  /// Index of a column, or -1.
  int find(const std::string& column) const noexcept;

  /// Serialized with '\n' line ends and 12 significant digits.
  std::string to_string() const;

 private:
  std::vector<std::string> columns_;
  std::vector<Cell> cells_;
};

/// A CSV table written row by row straight into text: the bytes
/// CsvTable::to_string writes for the same cells (the same checks, 12
/// significant digits, no "-0"), without keeping the cells. For tables too
/// long to hold as cells (a program's samples and moves): take() the text
/// written so far and go on.
class CsvText {
 public:
  /// Writes the header row first unless `header` is false.
  explicit CsvText(std::vector<std::string> columns, bool header = true);

  /// The next cell of the row: a number (robomill::NumericalError if it is
  /// not finite), a word (std::invalid_argument if it holds a separator), or
  /// nothing.
  void number(double value);
  void word(std::string_view text);
  void blank() { word({}); }
  /// Ends the row; std::invalid_argument if it has another number of cells
  /// than the header.
  void end_row();

  std::size_t rows() const noexcept { return rows_; }
  const std::string& text() const noexcept { return text_; }
  /// The text so far, leaving this empty (the next rows follow it).
  std::string take() { return std::exchange(text_, std::string()); }

 private:
  void separate();
  std::vector<std::string> columns_;
  std::string text_;
  std::size_t cell_ = 0, rows_ = 0;
};

/// Reads a numeric CSV with a header row. Blank lines and lines starting with
/// '#' are skipped. Throws InputError("<file> line N", ...) for ragged rows or
/// cells that are not finite numbers.
CsvTable read_csv(const std::filesystem::path& file);
CsvTable parse_csv(const std::string& text, const std::string& source_name);

}  // namespace robomill::io
