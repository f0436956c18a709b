#include "robomill/io/uff58.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <initializer_list>
#include <stdexcept>

#include "robomill/core/error.hpp"
#include "robomill/core/text.hpp"
#include "uff58_units.hpp"

namespace robomill::io {
namespace {

using dynamics::FrfKind;
using uff58_detail::force_unit;
using uff58_detail::is_blank_label;
using uff58_detail::kind_of_specific_type;
using uff58_detail::normalized_label;
using uff58_detail::ordinate_unit;
using uff58_detail::quantity_of;
using uff58_detail::time_unit;

// Caps what a count field may ask for, before the bytes are checked.
constexpr long long kMaxPoints = 10'000'000;
constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{1} << 30;

// Walks the bytes line by line; binary blocks are taken by count. Every '\n'
// counts as a line, inside binary blocks too, so numbers match an editor's.
class Reader {
 public:
  Reader(std::string_view bytes, std::string_view source) : bytes_(bytes), source_(source) {}

  std::optional<std::string_view> next_line() {
    if (position_ >= bytes_.size())
      return std::nullopt;
    std::size_t end = bytes_.find('\n', position_);
    const std::size_t next = end == std::string_view::npos ? bytes_.size() : end + 1;
    if (end == std::string_view::npos)
      end = bytes_.size();
    std::string_view line = bytes_.substr(position_, end - position_);
    if (!line.empty() && line.back() == '\r')
      line.remove_suffix(1);
    position_ = next;
    ++line_;
    return line;
  }

  std::string_view require_line(const std::string& what) {
    const auto line = next_line();
    if (!line)
      fail(line_ + 1, "unexpected end of file: expected " + what);
    return *line;
  }

  std::string_view take_bytes(std::size_t count) {
    const std::string_view block = bytes_.substr(position_, count);
    position_ += count;
    line_ += static_cast<int>(std::count(block.begin(), block.end(), '\n'));
    return block;
  }

  std::size_t remaining() const noexcept { return bytes_.size() - position_; }
  int line() const noexcept { return line_; }

  [[noreturn]] void fail(int line, const std::string& why) const {
    throw InputError(std::string(source_), line, why);
  }

 private:
  std::string_view bytes_;
  std::string_view source_;
  std::size_t position_ = 0;
  int line_ = 0;
};

bool is_delimiter(std::string_view line) {
  return text::trim(line) == "-1";
}

std::string shown(std::string_view text) {
  std::string out(text.substr(0, 40));
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126)
      c = '?';
  }
  return "'" + out + (text.size() > 40 ? "...'" : "'");
}

// Numeric fields separated by blanks; fixed-width fields that touch
// ("1.0E+00-2.0E+00") are split before a sign that does not follow an exponent letter.
std::vector<std::string_view> numeric_tokens(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t'))
      ++i;
    std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') {
      const char c = line[i];
      if (i > start && (c == '+' || c == '-') &&
          std::string_view("EeDd").find(line[i - 1]) == std::string_view::npos) {
        tokens.push_back(line.substr(start, i - start));
        start = i;
      }
      ++i;
    }
    if (i > start)
      tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

// A Fortran real: E or D exponent, optional leading '+'. Non-finite values are
// returned as such; the caller reports them with its context.
std::optional<double> parse_real(std::string_view token) {
  if (!token.empty() && token[0] == '+')
    token.remove_prefix(1);
  char buffer[64];
  if (token.empty() || token.size() >= sizeof buffer)
    return std::nullopt;
  for (std::size_t i = 0; i < token.size(); ++i)
    buffer[i] = (token[i] == 'D' || token[i] == 'd') ? 'E' : token[i];
  double value = 0.0;
  const auto result = std::from_chars(buffer, buffer + token.size(), value);
  if (result.ec != std::errc() || result.ptr != buffer + token.size())
    return std::nullopt;
  return value;
}

std::optional<long long> parse_integer(std::string_view token) {
  token = text::trim(token);
  if (!token.empty() && token[0] == '+')
    token.remove_prefix(1);
  long long value = 0;
  const auto result = std::from_chars(token.data(), token.data() + token.size(), value);
  if (token.empty() || result.ec != std::errc() || result.ptr != token.data() + token.size())
    return std::nullopt;
  return value;
}

std::string_view column(std::string_view line, std::size_t begin, std::size_t width) {
  if (begin >= line.size())
    return {};
  return text::trim(line.substr(begin, width));
}

long long integer_field(const Reader& reader, std::string_view line, std::size_t begin,
                        std::size_t width, const char* what) {
  const std::string_view cell = column(line, begin, width);
  const auto value = parse_integer(cell);
  // No field of ours needs more than an int; a node number beyond it is garbage.
  if (!value || *value < -2'147'483'647 || *value > 2'147'483'647)
    reader.fail(reader.line(), std::string(what) + ": expected an integer, got " + shown(cell));
  return *value;
}

void require_columns(const Reader& reader, std::string_view line, std::size_t columns,
                     const char* record) {
  if (line.size() < columns)
    reader.fail(reader.line(), std::string("wrong record length: ") + record + " needs " +
                                   std::to_string(columns) + " columns, got " +
                                   std::to_string(line.size()));
}

// Records 8-11: I10,3I5,2(1X,20A1).
struct AxisRecord {
  long long specific_type = 0;
  long long length_exponent = 0;
  long long force_exponent = 0;
  std::string units_label;
  int line = 0;
};

AxisRecord read_axis_record(Reader& reader, const char* record) {
  const std::string_view line = reader.require_line(record);
  require_columns(reader, line, 25, record);
  AxisRecord axis;
  axis.line = reader.line();
  const std::string name(record);
  axis.specific_type = integer_field(reader, line, 0, 10, (name + " specific data type").c_str());
  axis.length_exponent = integer_field(reader, line, 10, 5, (name + " length exponent").c_str());
  axis.force_exponent = integer_field(reader, line, 15, 5, (name + " force exponent").c_str());
  integer_field(reader, line, 20, 5, (name + " temperature exponent").c_str());
  axis.units_label = std::string(column(line, 47, 20));
  return axis;
}

// Dataset 164: factors that divide file units to give SI.
struct UnitFactors {
  double length = 1.0;
  double force = 1.0;
};

// The spec's Addendum A: the exponents of the file's length and force units
// are implied by the specific data type; only other types state them.
double factor_scale(const std::optional<UnitFactors>& units, const AxisRecord& axis) {
  if (!units)
    return 1.0;
  double length_exponent = static_cast<double>(axis.length_exponent);
  double force_exponent = static_cast<double>(axis.force_exponent);
  if (kind_of_specific_type(axis.specific_type)) {
    length_exponent = 1.0;
    force_exponent = 0.0;
  } else if (axis.specific_type == 9 || axis.specific_type == 13) {
    length_exponent = 0.0;
    force_exponent = 1.0;
  }
  return std::pow(units->length, -length_exponent) * std::pow(units->force, -force_exponent);
}

double ordinate_scale(const Reader& reader, const AxisRecord& numerator,
                      const AxisRecord& denominator, const std::optional<UnitFactors>& units,
                      const Uff58ReadOptions& options) {
  if (options.ordinate_scale_to_si)
    return *options.ordinate_scale_to_si;
  double scale = factor_scale(units, numerator);
  bool per_force = false;
  if (!is_blank_label(numerator.units_label)) {
    const auto unit = ordinate_unit(numerator.units_label);
    if (!unit)
      reader.fail(numerator.line,
                  "unknown ordinate unit " + shown(numerator.units_label) +
                      " (known: m, mm, um, in, m/s, m/s^2, g, optionally over N, kN, lbf, "
                      "e.g. mm/N); give the ordinate unit scale instead");
    scale = unit->scale_to_si;
    per_force = unit->per_force;
  }
  if (!per_force) {
    if (is_blank_label(denominator.units_label)) {
      scale /= factor_scale(units, denominator);
    } else if (const auto force = force_unit(normalized_label(denominator.units_label))) {
      scale /= *force;
    } else {
      reader.fail(denominator.line, "unknown force unit " + shown(denominator.units_label) +
                                        " (known: N, kN, mN, lbf)");
    }
  }
  if (!std::isfinite(scale) || !(scale > 0.0))
    reader.fail(numerator.line, "the unit exponents give no finite conversion factor to SI");
  return scale;
}

FrfKind ordinate_kind(const Reader& reader, const AxisRecord& numerator,
                      const Uff58ReadOptions& options) {
  if (options.kind)
    return *options.kind;
  const auto from_type = kind_of_specific_type(numerator.specific_type);
  std::optional<FrfKind> from_label;
  if (!is_blank_label(numerator.units_label)) {
    if (const auto unit = ordinate_unit(numerator.units_label))
      from_label = unit->kind;
  }
  if (from_type && from_label && *from_type != *from_label)
    reader.fail(numerator.line, "ordinate specific data type " +
                                    std::to_string(numerator.specific_type) + " (" +
                                    dynamics::kind_name(*from_type) + ") contradicts unit " +
                                    shown(numerator.units_label));
  if (from_type)
    return *from_type;
  if ((numerator.specific_type == 0 || numerator.specific_type == 1) && from_label)
    return *from_label;
  reader.fail(numerator.line, "ordinate specific data type " +
                                  std::to_string(numerator.specific_type) +
                                  " is not displacement (8), velocity (11) or acceleration (12)");
}

// Record 6 direction → tool axis and sign (a negative direction flips the data).
int axis_of(const Reader& reader, int line, long long direction, const std::optional<int>& chosen,
            const char* what, double& sign) {
  if (direction < -6 || direction > 6)
    reader.fail(line, std::string("unknown ") + what + " direction " + std::to_string(direction));
  if (direction < 0)
    sign = -sign;
  if (chosen) {
    if (*chosen < 0 || *chosen > 2)
      throw std::invalid_argument(std::string(what) + " axis override must be 0, 1 or 2");
    return *chosen;
  }
  if (direction == 0 || std::abs(direction) > 3)
    reader.fail(line, std::string(what) + " direction " + std::to_string(direction) +
                          " is not a translation (1..3 = +x..+z, -1..-3 = -x..-z); give the " +
                          what + " axis instead");
  return static_cast<int>(std::abs(direction)) - 1;
}

// Turns the data values (x, re, im per point, or re, im with an even grid)
// into the FRF, checking each value with the line it came from.
struct Points {
  bool even = true;
  double min_hz = 0.0;
  double increment_hz = 0.0;
  double factor = 1.0;  ///< unit scale times direction sign
  dynamics::Frf* frf = nullptr;
  std::size_t index = 0;
  double abscissa_hz = 0.0;
  double real = 0.0;

  void add(const Reader& reader, int line, double value) {
    if (!std::isfinite(value))
      reader.fail(line, "non-finite value (NaN or infinity) in the data");
    const std::size_t stride = even ? 2 : 3;
    const std::size_t slot = index % stride;
    const std::size_t point = index / stride;
    ++index;
    if (!even && slot == 0) {
      abscissa_hz = value;
    } else if (slot + 2 == stride) {
      real = value;
    } else {
      if (even)
        abscissa_hz = min_hz + static_cast<double>(point) * increment_hz;
      if (!std::isfinite(abscissa_hz) || abscissa_hz < 0.0 ||
          (!frf->frequency_hz.empty() && !(abscissa_hz > frf->frequency_hz.back())))
        reader.fail(line, "frequencies must be finite, >= 0 and strictly increasing (point " +
                              std::to_string(point + 1) + ")");
      const std::complex<double> scaled = std::complex<double>(real, value) * factor;
      if (!std::isfinite(scaled.real()) || !std::isfinite(scaled.imag()))
        reader.fail(line, "value overflows after conversion to SI units");
      // A written "-0" (or a negative-zero start of an even grid) is 0 Hz: the
      // sign of a zero frequency means nothing and would not survive writing.
      frf->frequency_hz.push_back(abscissa_hz == 0.0 ? 0.0 : abscissa_hz);
      frf->value.push_back(scaled);
    }
  }
};

struct BinaryHeader {
  bool binary = false;
  long long byte_order = 1;
  long long bytes = 0;
  long long ascii_lines = 0;
  int line = 0;
};

// Where the binary values of a dataset 58b lie: bytes per slot (x, re, im)
// and in all, checked against the header's count and the bytes present.
struct BinaryLayout {
  std::size_t slot_bytes[3] = {0, 0, 0};
  std::size_t bytes = 0;
};

BinaryLayout binary_layout(const Reader& reader, const BinaryHeader& header, long long count,
                           bool even, bool is_double, bool is_complex) {
  const std::size_t slots = (even ? 0 : 1) + (is_complex ? 2 : 1);
  const auto points = static_cast<std::size_t>(count);
  const auto declared = static_cast<std::size_t>(header.bytes);
  BinaryLayout layout;
  for (std::size_t k = 0; k < slots; ++k)
    layout.slot_bytes[k] = is_double ? 8 : 4;
  // Case 6/8 of the spec keep the abscissa a single-precision REAL; most
  // writers store every value alike. The byte count tells which.
  if (!even && is_double && declared == points * (4 + 8 * (slots - 1)))
    layout.slot_bytes[0] = 4;
  for (std::size_t k = 0; k < slots; ++k)
    layout.bytes += points * layout.slot_bytes[k];
  // pyuff (<= 2.4) declares 8 bytes per point whatever the layout; the
  // delimiter expected right after the data still catches a wrong record 7.
  const bool pyuff_count = is_double && declared == points * 8;
  if (declared != layout.bytes && !pyuff_count)
    reader.fail(header.line, "binary length mismatch: the header declares " +
                                 std::to_string(declared) + " bytes, record 7 needs " +
                                 std::to_string(layout.bytes));
  if (layout.bytes > reader.remaining())
    reader.fail(header.line, "truncated binary data: " + std::to_string(layout.bytes) +
                                 " bytes needed, " + std::to_string(reader.remaining()) +
                                 " present");
  return layout;
}

void skip_to_delimiter(Reader& reader, int start_line, long long dataset) {
  while (const auto line = reader.next_line()) {
    if (is_delimiter(*line))
      return;
  }
  reader.fail(start_line, "dataset " + std::to_string(dataset) + " has no end delimiter '    -1'");
}

void expect_delimiter_after_binary(Reader& reader) {
  auto line = reader.next_line();
  // Writers differ: some end the binary block with a newline, some do not.
  if (line && text::trim(*line).empty())
    line = reader.next_line();
  if (!line || !is_delimiter(*line))
    reader.fail(reader.line() + (line ? 0 : 1),
                "expected the end delimiter '    -1' after the binary data");
}

double decode(std::string_view bytes, std::size_t offset, bool is_double, bool little_endian) {
  const std::size_t size = is_double ? 8 : 4;
  std::uint64_t bits = 0;
  for (std::size_t k = 0; k < size; ++k) {
    const auto byte = static_cast<std::uint64_t>(static_cast<unsigned char>(bytes[offset + k]));
    bits |= byte << (8 * (little_endian ? k : size - 1 - k));
  }
  if (is_double)
    return std::bit_cast<double>(bits);
  return static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(bits)));
}

// Records 1-11 of a dataset 58, after its "58"/"58b" line: what every
// function type shares.
struct Header58 {
  std::string label;                    ///< record 1
  std::array<std::string, 4> id_lines;  ///< records 2..5
  int dof_line = 0;
  long long function_type = 0;
  std::string response_entity;
  int response_node = 0;
  long long response_direction = 0;
  std::string reference_entity;
  int reference_node = 0;
  long long reference_direction = 0;
  int form_line = 0;
  long long data_type = 0;
  long long count = 0;
  bool even = true;
  bool is_double = true;
  bool is_complex = true;
  double min = 0.0;        ///< record 7 abscissa minimum (even spacing)
  double increment = 0.0;  ///< record 7 abscissa increment (even spacing)
  AxisRecord abscissa, numerator, denominator;
};

Header58 read_header_58(Reader& reader) {
  Header58 h;
  h.label = std::string(text::trim(reader.require_line("record 1 (ID line 1)")));
  for (std::size_t i = 0; i < h.id_lines.size(); ++i)
    h.id_lines[i] = std::string(
        text::trim(reader.require_line("record " + std::to_string(i + 2) + " (ID line)")));

  // Record 6: 2(I5,I10),2(1X,10A1,I10,I4).
  const std::string_view dof = reader.require_line("record 6 (DOF identification)");
  h.dof_line = reader.line();
  require_columns(reader, dof, 80, "record 6");
  h.function_type = integer_field(reader, dof, 0, 5, "record 6 function type");
  h.response_entity = std::string(column(dof, 31, 10));
  h.response_node = static_cast<int>(integer_field(reader, dof, 41, 10, "record 6 response node"));
  h.response_direction = integer_field(reader, dof, 51, 4, "record 6 response direction");
  h.reference_entity = std::string(column(dof, 56, 10));
  h.reference_node =
      static_cast<int>(integer_field(reader, dof, 66, 10, "record 6 reference node"));
  h.reference_direction = integer_field(reader, dof, 76, 4, "record 6 reference direction");

  // Record 7: 3I10,3E13.5 (read as blank-separated numbers, so wider fields work).
  const std::string_view form = reader.require_line("record 7 (data form)");
  h.form_line = reader.line();
  const auto tokens = numeric_tokens(form);
  if (tokens.size() != 6)
    reader.fail(h.form_line,
                "wrong record length: record 7 needs 6 fields (3 integers, 3 reals), got " +
                    std::to_string(tokens.size()));
  const auto data_type = parse_integer(tokens[0]);
  const auto count = parse_integer(tokens[1]);
  const auto spacing = parse_integer(tokens[2]);
  const auto min = parse_real(tokens[3]);
  const auto increment = parse_real(tokens[4]);
  if (!data_type || !count || !spacing || !min || !increment || !parse_real(tokens[5]))
    reader.fail(h.form_line, "record 7: non-numeric field in " + shown(form));
  if (*count < 1 || *count > kMaxPoints)
    reader.fail(h.form_line, "record 7: number of points " + std::to_string(*count) +
                                 " outside 1.." + std::to_string(kMaxPoints));
  if (*spacing != 0 && *spacing != 1)
    reader.fail(h.form_line, "record 7: abscissa spacing must be 0 (uneven) or 1 (even), got " +
                                 std::to_string(*spacing));
  if (*data_type != 2 && *data_type != 4 && *data_type != 5 && *data_type != 6)
    reader.fail(h.form_line, "record 7: unknown ordinate data type " + std::to_string(*data_type) +
                                 " (2, 4 real; 5, 6 complex)");
  h.data_type = *data_type;
  h.count = *count;
  h.is_double = *data_type == 4 || *data_type == 6;
  h.is_complex = *data_type == 5 || *data_type == 6;
  h.even = *spacing == 1;
  h.min = *min;
  h.increment = *increment;

  h.abscissa = read_axis_record(reader, "record 8");
  h.numerator = read_axis_record(reader, "record 9");
  h.denominator = read_axis_record(reader, "record 10");
  read_axis_record(reader, "record 11");
  return h;
}

// The data values of a dataset 58 in file order (x, then re[, im] per point;
// no x with even spacing), each handed to add(line, value) with the line it
// came from; then the end delimiter. ASCII or binary as the header says.
template <typename Add>
void read_values_58(Reader& reader, const BinaryHeader& header, const Header58& h, Add&& add) {
  const std::size_t stride = (h.even ? 0 : 1) + (h.is_complex ? 2 : 1);
  const auto expected = static_cast<std::size_t>(h.count) * stride;
  if (header.binary) {
    const BinaryLayout layout =
        binary_layout(reader, header, h.count, h.even, h.is_double, h.is_complex);
    const int data_line = reader.line() + 1;
    const std::string_view block = reader.take_bytes(layout.bytes);
    std::size_t offset = 0;
    for (std::size_t i = 0; i < expected; ++i) {
      const std::size_t size = layout.slot_bytes[i % stride];
      add(data_line, decode(block, offset, size == 8, header.byte_order == 1));
      offset += size;
    }
    expect_delimiter_after_binary(reader);
    return;
  }
  std::size_t index = 0;
  while (true) {
    const auto line = reader.next_line();
    if (!line || is_delimiter(*line)) {
      if (index < expected || !line)
        reader.fail(line ? reader.line() : reader.line() + 1,
                    "truncated data: record 7 declares " + std::to_string(h.count) + " points (" +
                        std::to_string(expected) + " values), found " + std::to_string(index) +
                        " values" + (line ? "" : " and no end delimiter"));
      return;
    }
    for (const std::string_view token : numeric_tokens(*line)) {
      if (index == expected)
        reader.fail(reader.line(), "more values than the " + std::to_string(h.count) +
                                       " points record 7 declares");
      const auto value = parse_real(token);
      if (!value)
        reader.fail(reader.line(), "non-numeric value " + shown(token));
      ++index;
      add(reader.line(), *value);
    }
  }
}

// Passes over the data of a dataset 58 of another function type.
void skip_values_58(Reader& reader, const BinaryHeader& header, const Header58& h, int start_line) {
  if (header.binary) {
    reader.take_bytes(
        binary_layout(reader, header, h.count, h.even, h.is_double, h.is_complex).bytes);
    expect_delimiter_after_binary(reader);
  } else {
    skip_to_delimiter(reader, start_line, 58);
  }
}

// The first dataset 58 of another function type than the one read: its
// record 6 line and type, for the "nothing found" message.
using SkippedDataset = std::optional<std::pair<int, long long>>;

// One dataset 58 after its "58"/"58b" line; appends it to `out` when it is an FRF.
void read_dataset_58(Reader& reader, const BinaryHeader& header, int start_line,
                     const std::optional<UnitFactors>& units, const Uff58ReadOptions& options,
                     std::vector<UffFrf>& out, SkippedDataset& skipped) {
  const Header58 h = read_header_58(reader);
  if (h.function_type != 4) {
    // Spectra, coherences, time histories: not FRFs; skipped.
    if (!skipped)
      skipped = std::make_pair(h.dof_line, h.function_type);
    skip_values_58(reader, header, h, start_line);
    return;
  }
  UffFrf result;
  result.line = start_line;
  result.frf.label = h.label;
  result.id_lines = h.id_lines;
  result.response_entity = h.response_entity;
  result.response_node = h.response_node;
  result.reference_entity = h.reference_entity;
  result.reference_node = h.reference_node;

  if (!h.is_complex)
    reader.fail(h.form_line, "record 7: an FRF needs complex ordinates (data type 5 or 6), got " +
                                 std::to_string(h.data_type));
  if (h.even && (!std::isfinite(h.min) || h.min < 0.0 || !std::isfinite(h.increment) ||
                 (h.count > 1 && !(h.increment > 0.0))))
    reader.fail(h.form_line,
                "record 7: even spacing needs a finite minimum >= 0 Hz and a positive "
                "increment");
  if (h.abscissa.specific_type != 18 && h.abscissa.specific_type != 0)
    reader.fail(h.abscissa.line, "unknown abscissa type " +
                                     std::to_string(h.abscissa.specific_type) +
                                     " (expected 18 = frequency in Hz)");
  if (h.denominator.specific_type != 13 && h.denominator.specific_type != 9 &&
      h.denominator.specific_type != 0)
    reader.fail(h.denominator.line,
                "the FRF denominator must be a force (specific data type 13), "
                "got " +
                    std::to_string(h.denominator.specific_type));
  result.frf.kind = ordinate_kind(reader, h.numerator, options);
  double sign = 1.0;
  result.frf.response_axis =
      axis_of(reader, h.dof_line, h.response_direction, options.response_axis, "response", sign);
  result.frf.reference_axis =
      axis_of(reader, h.dof_line, h.reference_direction, options.reference_axis, "reference", sign);

  Points points;
  points.even = h.even;
  points.min_hz = h.min;
  points.increment_hz = h.increment;
  points.factor = sign * ordinate_scale(reader, h.numerator, h.denominator, units, options);
  points.frf = &result.frf;
  const std::size_t stride = h.even ? 2 : 3;
  // Reserve no more than the remaining bytes could hold (a value takes >= 2).
  const std::size_t plausible =
      std::min(static_cast<std::size_t>(h.count), reader.remaining() / (2 * stride) + 1);
  result.frf.frequency_hz.reserve(plausible);
  result.frf.value.reserve(plausible);
  read_values_58(reader, header, h,
                 [&](int line, double value) { points.add(reader, line, value); });
  try {
    dynamics::validate(result.frf);
  } catch (const std::invalid_argument& error) {
    reader.fail(start_line, error.what());
  }
  out.push_back(std::move(result));
}

// One dataset 58 after its "58"/"58b" line; appends it to `out` when it is a
// time response (function type 1).
void read_time_dataset_58(Reader& reader, const BinaryHeader& header, int start_line,
                          const std::optional<UnitFactors>& units, std::vector<UffTimeRecord>& out,
                          SkippedDataset& skipped) {
  const Header58 h = read_header_58(reader);
  if (h.function_type != 1) {
    if (!skipped)
      skipped = std::make_pair(h.dof_line, h.function_type);
    skip_values_58(reader, header, h, start_line);
    return;
  }
  if (h.is_complex)
    reader.fail(h.form_line,
                "record 7: a time record needs real ordinates (data type 2 or 4), got " +
                    std::to_string(h.data_type));
  if (h.abscissa.specific_type != 17 && h.abscissa.specific_type != 0)
    reader.fail(h.abscissa.line, "unknown abscissa type " +
                                     std::to_string(h.abscissa.specific_type) +
                                     " for a time record (expected 17 = time in s)");
  double time_scale = 1.0;
  const std::string abscissa_unit = normalized_label(h.abscissa.units_label);
  if (abscissa_unit == "ms")
    time_scale = 1e-3;
  else if (!is_blank_label(abscissa_unit) && abscissa_unit != "s" && abscissa_unit != "sec")
    reader.fail(h.abscissa.line,
                "unknown time unit " + shown(h.abscissa.units_label) + " (known: s, ms)");
  if (h.even &&
      (!std::isfinite(h.min) || !std::isfinite(h.increment) || !(h.increment * time_scale > 0.0)))
    reader.fail(h.form_line,
                "record 7: a time record needs a finite start and a positive time increment");
  if (!h.even && h.count < 2)
    reader.fail(h.form_line, "record 7: an unevenly spaced time record needs 2 points or more");

  UffTimeRecord record;
  record.label = h.label;
  record.id_lines = h.id_lines;
  record.response_entity = h.response_entity;
  record.response_node = h.response_node;
  record.response_direction = static_cast<int>(h.response_direction);
  record.specific_type = static_cast<int>(h.numerator.specific_type);
  record.line = start_line;
  double factor = 1.0;
  if (is_blank_label(h.numerator.units_label)) {
    factor = factor_scale(units, h.numerator);
    record.unit = quantity_of(h.numerator.specific_type).si_unit;
  } else if (const auto unit = time_unit(h.numerator.units_label)) {
    factor = unit->scale_to_si;
    record.unit = unit->si;
  } else {
    // Volts, counts: no SI conversion is known; the values stay as written
    // and the caller's scale (the sensor's sensitivity) converts them.
    record.unit = std::string(text::trim(h.numerator.units_label));
    record.unit_is_si = false;
  }
  if (!std::isfinite(factor) || !(factor > 0.0))
    reader.fail(h.numerator.line, "the unit exponents give no finite conversion factor to SI");

  std::vector<double> time;
  const std::size_t plausible =
      std::min(static_cast<std::size_t>(h.count), reader.remaining() / 2 + 1);
  record.value.reserve(plausible);
  if (!h.even)
    time.reserve(plausible);
  int first_bad_line = 0;
  std::size_t index = 0;
  read_values_58(reader, header, h, [&](int line, double value) {
    if (!std::isfinite(value))
      reader.fail(line, "non-finite value (NaN or infinity) in the data");
    const bool is_time = !h.even && index % 2 == 0;
    ++index;
    if (is_time) {
      time.push_back(value * time_scale);
      if (time.size() >= 3 && first_bad_line == 0) {
        // Uniform within 1e-3 of the first interval, so that a sample rate exists.
        const double first = time[1] - time[0];
        const double step = time.back() - time[time.size() - 2];
        if (!(first > 0.0) || !(std::abs(step - first) <= 1e-3 * first))
          first_bad_line = line;
      } else if (time.size() == 2 && !(time[1] > time[0])) {
        first_bad_line = line;
      }
      return;
    }
    const double scaled = value * factor;
    if (!std::isfinite(scaled))
      reader.fail(line, "value overflows after conversion to SI units");
    record.value.push_back(scaled);
  });
  if (first_bad_line != 0)
    reader.fail(first_bad_line,
                "the abscissa is not uniformly spaced time (within 0.1 % of the first interval)");
  if (h.even) {
    record.start_s = h.min * time_scale;
    record.dt_s = h.increment * time_scale;
  } else {
    record.start_s = time.front();
    record.dt_s = (time.back() - time.front()) / static_cast<double>(time.size() - 1);
  }
  out.push_back(std::move(record));
}

std::optional<UnitFactors> read_dataset_164(Reader& reader, int start_line) {
  reader.require_line("dataset 164 record 1 (units code)");
  const std::string_view factors_line = reader.require_line("dataset 164 record 2 (unit factors)");
  const auto tokens = numeric_tokens(factors_line);
  std::optional<double> length, force;
  if (tokens.size() >= 2) {
    length = parse_real(tokens[0]);
    force = parse_real(tokens[1]);
  }
  if (!length || !force || !std::isfinite(*length) || !std::isfinite(*force) || !(*length > 0.0) ||
      !(*force > 0.0))
    reader.fail(
        reader.line(),
        "dataset 164: expected positive length and force unit factors, got " + shown(factors_line));
  skip_to_delimiter(reader, start_line, 164);
  return UnitFactors{*length, *force};
}

BinaryHeader parse_dataset_line(const Reader& reader, std::string_view line, long long& number) {
  line = text::trim(line);
  std::size_t digits = 0;
  while (digits < line.size() && line[digits] >= '0' && line[digits] <= '9')
    ++digits;
  const auto parsed = parse_integer(line.substr(0, digits));
  if (!parsed)
    reader.fail(reader.line(), "expected a dataset number after '    -1', got " + shown(line));
  number = *parsed;
  BinaryHeader header;
  header.line = reader.line();
  const std::string_view rest = line.substr(digits);
  if (rest.empty())
    return header;
  if (rest[0] != 'b' && rest[0] != 'B')
    reader.fail(reader.line(), "unexpected text after the dataset number: " + shown(line));
  header.binary = true;
  const auto fields = numeric_tokens(rest.substr(1));
  std::vector<long long> values;
  for (const std::string_view field : fields) {
    const auto value = parse_integer(field);
    if (!value)
      reader.fail(reader.line(), "binary header: non-numeric field " + shown(field));
    values.push_back(*value);
  }
  if (values.size() < 4)
    reader.fail(reader.line(),
                "wrong record length: the binary header needs byte order, "
                "floating-point format, ASCII line count and byte count");
  if (values[0] != 1 && values[0] != 2)
    reader.fail(reader.line(),
                "binary header: byte order must be 1 (little endian) or 2 (big "
                "endian), got " +
                    std::to_string(values[0]));
  if (values[1] != 2)
    reader.fail(reader.line(), "binary header: floating-point format " + std::to_string(values[1]) +
                                   " is not 2 (IEEE 754)");
  if (number == 58 && values[2] != 11)
    reader.fail(reader.line(), "binary header: dataset 58b has 11 ASCII lines, header says " +
                                   std::to_string(values[2]));
  if (values[3] < 0)
    reader.fail(reader.line(), "binary header: negative byte count");
  header.byte_order = values[0];
  header.bytes = values[3];
  header.ascii_lines = values[2];
  return header;
}

// Walks every dataset of a UFF file: dataset 164 sets the unit factors,
// each dataset 58 goes to on58(reader, header, start line, units), every
// other dataset (ASCII or binary) is skipped. Returns whether any 58 was seen.
template <typename On58>
bool walk_datasets(std::string_view bytes, std::string_view source_name, On58&& on58) {
  Reader reader(bytes, source_name);
  std::optional<UnitFactors> units;
  bool any_58 = false;
  while (const auto line = reader.next_line()) {
    if (text::trim(*line).empty())
      continue;
    if (!is_delimiter(*line))
      reader.fail(reader.line(), "expected the dataset delimiter '    -1', got " + shown(*line));
    const int start_line = reader.line();
    long long number = 0;
    const BinaryHeader header =
        parse_dataset_line(reader, reader.require_line("a dataset number"), number);
    if (number == 58) {
      any_58 = true;
      on58(reader, header, start_line, units);
    } else if (number == 164 && !header.binary) {
      units = read_dataset_164(reader, start_line);
    } else if (header.binary) {
      // Another binary dataset: its ASCII lines, its bytes, the delimiter.
      for (long long i = 0; i < header.ascii_lines; ++i)
        reader.require_line("dataset " + std::to_string(number) + " ASCII line");
      if (header.bytes > static_cast<long long>(reader.remaining()))
        reader.fail(header.line, "truncated binary data");
      reader.take_bytes(static_cast<std::size_t>(header.bytes));
      expect_delimiter_after_binary(reader);
    } else {
      skip_to_delimiter(reader, start_line, number);
    }
  }
  return any_58;
}

// When a file holds none of the functions asked for: what it holds instead.
[[noreturn]] void fail_nothing_found(std::string_view source_name, bool any_58,
                                     const SkippedDataset& skipped, const char* wanted_type,
                                     const char* wanted) {
  const Reader reader({}, source_name);
  if (skipped)
    reader.fail(skipped->first, std::string("no ") + wanted + " in the file: function type " +
                                    std::to_string(skipped->second) + " is not " + wanted_type);
  reader.fail(0, any_58 ? std::string("no ") + wanted + " in the file"
                        : "no dataset 58 (function at nodal DOF) in the file");
}

std::string read_file_bytes(const std::filesystem::path& file) {
  std::error_code error;
  const auto size = std::filesystem::file_size(file, error);
  if (!error && size > kMaxFileBytes)
    throw InputError(file.string(), 0, "file larger than 1 GiB");
  std::ifstream stream(file, std::ios::binary);
  if (!stream || error)
    throw InputError(file.string(), 0, "cannot open file");
  std::string bytes(static_cast<std::size_t>(size), '\0');
  stream.read(bytes.data(), static_cast<std::streamsize>(size));
  bytes.resize(static_cast<std::size_t>(stream.gcount()));
  return bytes;
}

}  // namespace

std::vector<UffFrf> parse_uff58(std::string_view bytes, std::string_view source_name,
                                const Uff58ReadOptions& options) {
  if (options.ordinate_scale_to_si &&
      (!std::isfinite(*options.ordinate_scale_to_si) || !(*options.ordinate_scale_to_si > 0.0)))
    throw std::invalid_argument("UFF ordinate scale to SI must be positive and finite");
  std::vector<UffFrf> frfs;
  SkippedDataset skipped;  // first non-FRF dataset 58
  const bool any_58 =
      walk_datasets(bytes, source_name,
                    [&](Reader& reader, const BinaryHeader& header, int start_line,
                        const std::optional<UnitFactors>& units) {
                      read_dataset_58(reader, header, start_line, units, options, frfs, skipped);
                    });
  if (frfs.empty())
    fail_nothing_found(source_name, any_58, skipped, "4 (FRF)", "frequency response function");
  return frfs;
}

std::vector<UffFrf> read_uff58(const std::filesystem::path& file, const Uff58ReadOptions& options) {
  return parse_uff58(read_file_bytes(file), file.string(), options);
}

std::vector<UffTimeRecord> parse_uff58_time_records(std::string_view bytes,
                                                    std::string_view source_name) {
  std::vector<UffTimeRecord> records;
  SkippedDataset skipped;  // first dataset 58 of another function type
  const bool any_58 =
      walk_datasets(bytes, source_name,
                    [&](Reader& reader, const BinaryHeader& header, int start_line,
                        const std::optional<UnitFactors>& units) {
                      read_time_dataset_58(reader, header, start_line, units, records, skipped);
                    });
  if (records.empty())
    fail_nothing_found(source_name, any_58, skipped, "1 (time response)", "time record");
  return records;
}

std::vector<UffTimeRecord> read_uff58_time_records(const std::filesystem::path& file) {
  return parse_uff58_time_records(read_file_bytes(file), file.string());
}

}  // namespace robomill::io
