// UFF dataset 58 writer (format_uff58, format_uff58_time_records and the
// files they write): the reader is uff58.cpp. 17 significant digits per
// value, so that the reader restores every double exactly.

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <span>
#include <stdexcept>

#include "robomill/core/text.hpp"
#include "robomill/io/output_bundle.hpp"
#include "robomill/io/uff58.hpp"
#include "uff58_units.hpp"

namespace robomill::io {
namespace {

using uff58_detail::quantity_of;

std::string sanitized(std::string_view text, std::size_t width, const char* empty) {
  std::string out(text.substr(0, width));
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 32 || c == 127)
      c = ' ';
  }
  return text::trim(out).empty() ? std::string(empty) : out;
}

// 17 significant digits in 25 columns: enough to restore every double exactly.
void append_real(std::string& out, double value) {
  char buffer[40];
  const auto result =
      std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::scientific, 16);
  const std::string_view number(buffer, static_cast<std::size_t>(result.ptr - buffer));
  out.append(number.size() < 25 ? 25 - number.size() : 1, ' ');
  for (const char c : number)
    out += c == 'e' ? 'E' : c;
}

void append_line(std::string& out, const char* format, auto... args) {
  char buffer[160];
  const int written = std::snprintf(buffer, sizeof buffer, format, args...);
  out.append(buffer, static_cast<std::size_t>(std::clamp(written, 0, 159)));
  out += '\n';
}

void append_little_endian(std::string& out, double value) {
  const auto bits = std::bit_cast<std::uint64_t>(value);
  for (int k = 0; k < 8; ++k)
    out += static_cast<char>((bits >> (8 * k)) & 0xFF);
}

// Dataset 164: the SI unit system, so that tools relying on it read SI.
void append_units_164(std::string& out) {
  out += "    -1\n   164\n";
  append_line(out, "%10d%-20s%10d", 1, "SI - m (newton)", 2);
  out += "  1.00000000000000000D+00  1.00000000000000000D+00  1.00000000000000000D+00\n";
  out += "  2.73150000000000000D+02\n    -1\n";
}

// What the writer puts into records 1-11 of a dataset 58.
struct Header58Out {
  std::string_view label;
  const std::array<std::string, 4>* id_lines = nullptr;
  int function_type = 4;
  std::size_t number = 1;  ///< record 6's function identification number
  std::string_view response_entity;
  int response_node = 1;
  int response_direction = 1;
  std::string_view reference_entity;
  int reference_node = 1;
  int reference_direction = 1;
  int data_type = 6;
  std::size_t count = 0;
  bool even = true;
  double min = 0.0;
  double increment = 0.0;
  std::size_t values = 0;  ///< data values in all (the 58b byte count / 8)
  // Records 8-11: specific data type, length/force exponents, name, unit.
  struct Axis {
    int type;
    int length_exponent;
    int force_exponent;
    const char* name;
    std::string unit;
  };
  std::array<Axis, 4> axes;
};

void append_header_58(std::string& out, const Header58Out& h, UffEncoding encoding) {
  out += "    -1\n";
  if (encoding == UffEncoding::binary)
    append_line(out, "%6d%c%6d%6d%12d%12zu%6d%6d%12d%12d", 58, 'b', 1, 2, 11, h.values * 8, 0, 0, 0,
                0);
  else
    out += "    58\n";
  append_line(out, "%s", sanitized(h.label, 80, "NONE").c_str());
  for (const std::string& id : *h.id_lines)
    append_line(out, "%s", sanitized(id, 80, "NONE").c_str());
  append_line(out, "%5d%10zu%5d%10d %-10s%10d%4d %-10s%10d%4d", h.function_type, h.number, 0, 0,
              sanitized(h.response_entity, 10, "NONE").c_str(), h.response_node,
              h.response_direction, sanitized(h.reference_entity, 10, "NONE").c_str(),
              h.reference_node, h.reference_direction);
  append_line(out, "%10d%10zu%10d", h.data_type, h.count, h.even ? 1 : 0);
  out.pop_back();
  append_real(out, h.even ? h.min : 0.0);
  append_real(out, h.even ? h.increment : 0.0);
  out += "  0.00000E+00\n";
  for (const auto& axis : h.axes)
    append_line(out, "%10d%5d%5d%5d %-20s %-20s", axis.type, axis.length_exponent,
                axis.force_exponent, 0, axis.name, sanitized(axis.unit, 20, "NONE").c_str());
}

// One point's values (ASCII: one line; binary: little-endian doubles).
void append_point(std::string& out, std::span<const double> values, UffEncoding encoding) {
  for (const double value : values) {
    if (encoding == UffEncoding::binary)
      append_little_endian(out, value);
    else
      append_real(out, value);
  }
  if (encoding == UffEncoding::ascii)
    out += '\n';
}

}  // namespace

std::string format_uff58(const std::vector<UffFrf>& frfs, UffEncoding encoding) {
  static constexpr const char* kOrdinate[][2] = {
      {"Displacement", "m"}, {"Velocity", "m/s"}, {"Acceleration", "m/s^2"}};
  static constexpr int kOrdinateType[] = {8, 11, 12};
  std::string out;
  append_units_164(out);
  for (std::size_t n = 0; n < frfs.size(); ++n) {
    const UffFrf& uff = frfs[n];
    const dynamics::Frf& frf = uff.frf;
    dynamics::validate(frf);
    if (uff.response_node < -999'999'999 || uff.reference_node < -999'999'999)
      throw std::invalid_argument("UFF node numbers must fit 10 columns");
    const std::size_t count = frf.frequency_hz.size();
    // Even spacing only where the reader's min + i·increment restores each frequency exactly.
    const double min_hz = frf.frequency_hz.front();
    const double increment_hz = count > 1 ? frf.frequency_hz[1] - min_hz : 0.0;
    bool even = count > 1;
    for (std::size_t i = 0; even && i < count; ++i)
      even = min_hz + static_cast<double>(i) * increment_hz == frf.frequency_hz[i];
    const auto kind = static_cast<std::size_t>(frf.kind);
    Header58Out h{.label = frf.label,
                  .id_lines = &uff.id_lines,
                  .function_type = 4,
                  .number = n + 1,
                  .response_entity = uff.response_entity,
                  .response_node = uff.response_node,
                  .response_direction = frf.response_axis + 1,
                  .reference_entity = uff.reference_entity,
                  .reference_node = uff.reference_node,
                  .reference_direction = frf.reference_axis + 1,
                  .data_type = 6,
                  .count = count,
                  .even = even,
                  .min = min_hz,
                  .increment = increment_hz,
                  .values = count * (even ? 2 : 3),
                  .axes = {{{18, 0, 0, "Frequency", "Hz"},
                            {kOrdinateType[kind], 1, 0, kOrdinate[kind][0], kOrdinate[kind][1]},
                            {13, 0, 1, "Force", "N"},
                            {0, 0, 0, "NONE", "NONE"}}}};
    append_header_58(out, h, encoding);
    for (std::size_t i = 0; i < count; ++i) {
      const double point[3] = {frf.frequency_hz[i], frf.value[i].real(), frf.value[i].imag()};
      append_point(out, std::span<const double>(point).subspan(even ? 1 : 0), encoding);
    }
    // After binary data the spec wants the delimiter with no line break between.
    out += "    -1\n";
  }
  return out;
}

void write_uff58(const std::filesystem::path& file, const std::vector<UffFrf>& frfs,
                 UffEncoding encoding) {
  write_file_atomically(file, format_uff58(frfs, encoding));
}

std::string format_uff58_time_records(const std::vector<UffTimeRecord>& records,
                                      UffEncoding encoding) {
  std::string out;
  append_units_164(out);
  for (std::size_t n = 0; n < records.size(); ++n) {
    const UffTimeRecord& record = records[n];
    if (record.value.empty() || !std::isfinite(record.dt_s) || !(record.dt_s > 0.0) ||
        !std::isfinite(record.start_s))
      throw std::invalid_argument("UFF time record: needs samples, a positive dt and a start");
    for (const double value : record.value) {
      if (!std::isfinite(value))
        throw std::invalid_argument("UFF time record: non-finite sample");
    }
    if (record.response_node < -999'999'999 || record.response_direction < -999 ||
        record.response_direction > 9999)
      throw std::invalid_argument("UFF time record: node and direction must fit their columns");
    Header58Out h{
        .label = record.label,
        .id_lines = &record.id_lines,
        .function_type = 1,
        .number = n + 1,
        .response_entity = record.response_entity,
        .response_node = record.response_node,
        .response_direction = record.response_direction,
        .reference_entity = "NONE",
        .reference_node = 0,
        .reference_direction = 0,
        .data_type = 4,
        .count = record.value.size(),
        .even = true,
        .min = record.start_s,
        .increment = record.dt_s,
        .values = record.value.size(),
        .axes = {{{17, 0, 0, "Time", "s"},
                  {record.specific_type, 0, 0, quantity_of(record.specific_type).name, record.unit},
                  {0, 0, 0, "NONE", "NONE"},
                  {0, 0, 0, "NONE", "NONE"}}}};
    append_header_58(out, h, encoding);
    for (const double value : record.value)
      append_point(out, std::span<const double>(&value, 1), encoding);
    out += "    -1\n";
  }
  return out;
}

void write_uff58_time_records(const std::filesystem::path& file,
                              const std::vector<UffTimeRecord>& records, UffEncoding encoding) {
  write_file_atomically(file, format_uff58_time_records(records, encoding));
}

}  // namespace robomill::io
