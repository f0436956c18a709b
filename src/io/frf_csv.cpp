#include "robomill/io/frf_csv.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "robomill/core/error.hpp"
#include "robomill/core/text.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/output_bundle.hpp"

namespace robomill::io {
namespace {

// parse_csv forgets line numbers; the lines it reads (not blank, not '#')
// are found again here, header first, so each row's errors name its line.
std::vector<int> content_lines(const std::string& text) {
  std::vector<int> lines;
  std::stringstream stream(text);
  std::string line;
  int number = 0;
  while (std::getline(stream, line)) {
    ++number;
    const std::string_view content = text::trim(line);
    if (!content.empty() && content[0] != '#')
      lines.push_back(number);
  }
  return lines;
}

const char* si_unit(dynamics::FrfKind kind) {
  switch (kind) {
    case dynamics::FrfKind::receptance:
      return "m/N";
    case dynamics::FrfKind::mobility:
      return "m/(s N)";
    case dynamics::FrfKind::accelerance:
      return "m/(s^2 N)";
  }
  return "";
}

void append_number(std::string& out, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

}  // namespace

dynamics::Frf parse_frf_csv(const std::string& text, const std::string& source_name,
                            const FrfCsvOptions& options) {
  if (!std::isfinite(options.scale_to_si) || !(options.scale_to_si > 0.0))
    throw std::invalid_argument("FRF CSV scale to SI must be positive and finite");
  if (options.response_axis < 0 || options.response_axis > 2 || options.reference_axis < 0 ||
      options.reference_axis > 2)
    throw std::invalid_argument("FRF CSV axes must be 0, 1 or 2");
  const CsvTable table = parse_csv(text, source_name);
  const std::vector<int> lines = content_lines(text);
  const std::vector<std::string>& columns = table.columns();
  const bool cartesian = columns == std::vector<std::string>{"freq_hz", "re", "im"};
  const bool polar = columns == std::vector<std::string>{"freq_hz", "mag", "phase_deg"};
  if (!cartesian && !polar) {
    std::string header;
    for (const std::string& column : columns)
      header += (header.empty() ? "" : ",") + column;
    throw InputError(
        source_name, lines.empty() ? 0 : lines.front(),
        "expected the header 'freq_hz,re,im' or 'freq_hz,mag,phase_deg', got '" + header + "'");
  }
  if (table.rows() == 0)
    throw InputError(source_name, lines.front(), "no data rows after the header");
  dynamics::Frf frf;
  frf.kind = options.kind;
  frf.response_axis = options.response_axis;
  frf.reference_axis = options.reference_axis;
  frf.label = source_name;
  frf.frequency_hz.reserve(table.rows());
  frf.value.reserve(table.rows());
  for (std::size_t row = 0; row < table.rows(); ++row) {
    const int line = row + 1 < lines.size() ? lines[row + 1] : 0;
    const double frequency_hz = table.at(row, 0);
    if (frequency_hz < 0.0)
      throw InputError(source_name, line,
                       "freq_hz must be >= 0, got " + std::to_string(frequency_hz));
    if (!frf.frequency_hz.empty() && !(frequency_hz > frf.frequency_hz.back()))
      throw InputError(source_name, line, "freq_hz must be strictly increasing");
    std::complex<double> value;
    if (cartesian) {
      value = {table.at(row, 1), table.at(row, 2)};
    } else {
      if (table.at(row, 1) < 0.0)
        throw InputError(source_name, line, "mag must be >= 0");
      value = std::polar(table.at(row, 1), table.at(row, 2) * std::numbers::pi / 180.0);
    }
    value *= options.scale_to_si;
    if (!std::isfinite(value.real()) || !std::isfinite(value.imag()))
      throw InputError(source_name, line, "value overflows after conversion to SI units");
    frf.frequency_hz.push_back(frequency_hz);
    frf.value.push_back(value);
  }
  return frf;
}

dynamics::Frf read_frf_csv(const std::filesystem::path& file, const FrfCsvOptions& options) {
  std::ifstream stream(file, std::ios::binary);
  if (!stream)
    throw InputError(file.string(), 0, "cannot open file");
  std::stringstream buffer;
  buffer << stream.rdbuf();
  return parse_frf_csv(buffer.str(), file.string(), options);
}

std::string format_frf_csv(const dynamics::Frf& frf) {
  dynamics::validate(frf);
  std::string out = std::string("# ") + dynamics::kind_name(frf.kind) + ", " + si_unit(frf.kind) +
                    "\nfreq_hz,re,im\n";
  for (std::size_t i = 0; i < frf.frequency_hz.size(); ++i) {
    append_number(out, frf.frequency_hz[i]);
    out += ',';
    append_number(out, frf.value[i].real());
    out += ',';
    append_number(out, frf.value[i].imag());
    out += '\n';
  }
  return out;
}

void write_frf_csv(const std::filesystem::path& file, const dynamics::Frf& frf) {
  write_file_atomically(file, format_frf_csv(frf));
}

}  // namespace robomill::io
