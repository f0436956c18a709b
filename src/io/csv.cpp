#include "robomill/io/csv.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "robomill/core/error.hpp"
#include "robomill/core/text.hpp"

namespace robomill::io {
namespace {

std::string trim(const std::string& line) {
  return std::string(text::trim(line));
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream stream(line);
  std::string cell;
  while (std::getline(stream, cell, ','))
    cells.push_back(trim(cell));
  if (!line.empty() && line.back() == ',')
    cells.emplace_back();
  return cells;
}

}  // namespace

CsvTable::CsvTable(std::vector<std::string> columns) : columns_(std::move(columns)) {
  if (columns_.empty())
    throw std::invalid_argument("a CSV table needs at least one column");
}

void CsvTable::add_row(const std::vector<double>& values) {
  add_cells(std::vector<Cell>(values.begin(), values.end()));
}

void CsvTable::add_cells(const std::vector<Cell>& cells) {
  if (cells.size() != columns_.size()) {
    throw std::invalid_argument("CSV row has " + std::to_string(cells.size()) + " values for " +
                                std::to_string(columns_.size()) + " columns");
  }
  for (std::size_t c = 0; c < cells.size(); ++c) {
    if (const double* value = std::get_if<double>(&cells[c]); value && !std::isfinite(*value)) {
      throw NumericalError("non-finite value in column '" + columns_[c] + "' (row " +
                           std::to_string(rows() + 1) + "); refusing to write it");
    }
    if (const std::string* text = std::get_if<std::string>(&cells[c]);
        text && text->find_first_of(",\"\n\r") != std::string::npos) {
      throw std::invalid_argument("CSV text cell must not contain separators: '" + *text + "'");
    }
  }
  cells_.insert(cells_.end(), cells.begin(), cells.end());
}

int CsvTable::find(const std::string& column) const noexcept {
  for (std::size_t c = 0; c < columns_.size(); ++c) {
    if (columns_[c] == column)
      return static_cast<int>(c);
  }
  return -1;
}

std::string CsvTable::to_string() const {
  std::string text;
  text.reserve(cells_.size() * 14 + 64);
  for (std::size_t c = 0; c < columns_.size(); ++c) {
    if (c)
      text += ',';
    text += columns_[c];
  }
  text += '\n';
  char buffer[64];
  for (std::size_t r = 0; r < rows(); ++r) {
    for (std::size_t c = 0; c < columns_.size(); ++c) {
      if (c)
        text += ',';
      const Cell& cell = cells_[r * columns_.size() + c];
      if (const std::string* word = std::get_if<std::string>(&cell)) {
        text += *word;
        continue;
      }
      double value = std::get<double>(cell);
      if (value == 0.0)
        value = 0.0;  // no "-0"
      const auto result =
          std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general, 12);
      text.append(buffer, result.ptr);
    }
    text += '\n';
  }
  return text;
}

CsvText::CsvText(std::vector<std::string> columns, bool header) : columns_(std::move(columns)) {
  if (columns_.empty())
    throw std::invalid_argument("a CSV table needs at least one column");
  if (!header)
    return;
  for (std::size_t c = 0; c < columns_.size(); ++c) {
    if (c)
      text_ += ',';
    text_ += columns_[c];
  }
  text_ += '\n';
}

void CsvText::separate() {
  if (cell_ >= columns_.size())
    throw std::invalid_argument("CSV row has more than " + std::to_string(columns_.size()) +
                                " values");
  if (cell_)
    text_ += ',';
  ++cell_;
}

void CsvText::number(double value) {
  if (!std::isfinite(value)) {
    throw NumericalError("non-finite value in column '" +
                         columns_[std::min(cell_, columns_.size() - 1)] + "' (row " +
                         std::to_string(rows_ + 1) + "); refusing to write it");
  }
  separate();
  if (value == 0.0)
    value = 0.0;  // no "-0"
  char buffer[64];
  const auto result =
      std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general, 12);
  text_.append(buffer, result.ptr);
}

void CsvText::word(std::string_view text) {
  if (text.find_first_of(",\"\n\r") != std::string_view::npos)
    throw std::invalid_argument("CSV text cell must not contain separators: '" + std::string(text) +
                                "'");
  separate();
  text_ += text;
}

void CsvText::end_row() {
  if (cell_ != columns_.size()) {
    throw std::invalid_argument("CSV row has " + std::to_string(cell_) + " values for " +
                                std::to_string(columns_.size()) + " columns");
  }
  text_ += '\n';
  cell_ = 0;
  ++rows_;
}

CsvTable parse_csv(const std::string& text, const std::string& source_name) {
  std::stringstream stream(text);
  std::string line;
  int line_number = 0;
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  while (std::getline(stream, line)) {
    ++line_number;
    const std::string content = trim(line);
    if (content.empty() || content[0] == '#')
      continue;
    std::vector<std::string> cells = split(content);
    if (header.empty()) {
      for (const std::string& cell : cells) {
        if (cell.empty())
          throw InputError(source_name, line_number, "empty column name in header");
      }
      header = std::move(cells);
      continue;
    }
    if (cells.size() != header.size()) {
      throw InputError(source_name, line_number,
                       "expected " + std::to_string(header.size()) + " values (" +
                           std::to_string(header.size()) + " columns), got " +
                           std::to_string(cells.size()));
    }
    std::vector<double> values;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      double value = 0.0;
      const char* begin = cells[c].data();
      const char* end = begin + cells[c].size();
      const auto result = std::from_chars(begin, end, value);
      if (cells[c].empty() || result.ec != std::errc() || result.ptr != end ||
          !std::isfinite(value)) {
        throw InputError(
            source_name, line_number,
            "column '" + header[c] + "': expected a finite number, got '" + cells[c] + "'");
      }
      values.push_back(value);
    }
    rows.push_back(std::move(values));
  }
  if (header.empty())
    throw InputError(source_name, 0, "empty file: expected a header row");
  CsvTable table(header);
  for (const auto& row : rows)
    table.add_row(row);
  return table;
}

CsvTable read_csv(const std::filesystem::path& file) {
  std::ifstream stream(file, std::ios::binary);
  if (!stream)
    throw InputError(file.string(), 0, "cannot open file");
  std::stringstream buffer;
  buffer << stream.rdbuf();
  return parse_csv(buffer.str(), file.string());
}

}  // namespace robomill::io
