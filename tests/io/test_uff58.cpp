// UFF dataset 58 / 58b: bit-exact round trips, hand-written files in the
// classic fixed formats with non-SI units, and rejection of malformed input.

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "robomill/core/error.hpp"
#include "robomill/io/uff58.hpp"

namespace test_uff58_cpp {

namespace {

using namespace robomill;
using dynamics::FrfKind;

std::string record6(int type, int response_direction, int reference_direction) {
  char line[96];
  std::snprintf(line, sizeof line, "%5d%10d%5d%10d %-10s%10d%4d %-10s%10d%4d", type, 1, 0, 0,
                "NONE", 7, response_direction, "NONE", 3, reference_direction);
  return line;
}

// Classic layout: record 7 3I10,3E13.5, data 4E20.12 (complex double, even).
std::string classic(const std::string& record_6, const std::string& record_9_unit = "m") {
  return "    -1\n    58\nFRF tool tip x/x\nNONE\n01-Jan-25 12:00:00\nNONE\nNONE\n" + record_6 +
         "\n         6         3         1  0.00000E+00  1.00000E+01  0.00000E+00\n"
         "        18    0    0    0 Frequency            Hz\n"
         "         8    0    0    0 Displacement         " +
         record_9_unit +
         "\n"
         "        13    0    0    0 Force                N\n"
         "         0    0    0    0 NONE                 NONE\n"
         "  1.000000000000E-03 -2.000000000000E-03  3.000000000000E-03 -4.000000000000E-03\n"
         "  5.000000000000E-03 -6.000000000000E-03\n"
         "    -1\n";
}

std::string with_line(std::string text, int line, const std::string& replacement) {
  std::size_t begin = 0;
  for (int i = 1; i < line; ++i)
    begin = text.find('\n', begin) + 1;
  const std::size_t end = text.find('\n', begin);
  return text.replace(begin, end - begin, replacement);
}

void expect_rejected(const std::string& bytes, int line, const std::string& reason) {
  try {
    io::parse_uff58(bytes, "frf file x.uff");
    ADD_FAILURE() << "accepted; expected line " << line << ": " << reason;
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), "frf file x.uff");
    EXPECT_EQ(error.line(), line) << error.what();
    EXPECT_NE(std::string(error.what()).find(reason), std::string::npos) << error.what();
  }
}

bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

std::vector<io::UffFrf> sample_frfs() {
  io::UffFrf even;  // grid i·0.25 Hz is exactly min + i·increment: written evenly spaced
  even.frf.label = "tool tip x/x";
  even.frf.kind = FrfKind::receptance;
  for (int i = 0; i < 9; ++i) {
    even.frf.frequency_hz.push_back(0.25 * i);
    even.frf.value.emplace_back(1.0 / (3.0 + i), -std::sqrt(2.0 + i) * 1e-7);
  }
  even.frf.value[3] = {-0.0, 4.9e-324};  // sign of zero and a subnormal survive
  even.id_lines = {"run 7", "01-Jan-25 12:00:00", "NONE", "pose A"};
  even.response_node = 11;
  even.reference_node = 12;
  io::UffFrf uneven;  // logarithmic grid: written with every abscissa
  uneven.frf.label = "y/x";
  uneven.frf.kind = FrfKind::mobility;
  uneven.frf.response_axis = 1;
  uneven.frf.reference_axis = 0;
  for (int i = 0; i < 7; ++i) {
    uneven.frf.frequency_hz.push_back(std::pow(10.0, 0.37 * i) / 3.0);
    uneven.frf.value.emplace_back(std::sin(i + 0.1) * 1e-300, std::cos(i) * 1e300);
  }
  uneven.response_entity = "TOOL";
  io::UffFrf single;
  single.frf.kind = FrfKind::accelerance;
  single.frf.response_axis = 2;
  single.frf.reference_axis = 2;
  single.frf.frequency_hz = {1234.5678901234567};
  single.frf.value = {{-1.0 / 3.0, 2.0 / 7.0}};
  return {even, uneven, single};
}

void expect_same(const std::vector<io::UffFrf>& read, const std::vector<io::UffFrf>& written) {
  ASSERT_EQ(read.size(), written.size());
  for (std::size_t n = 0; n < read.size(); ++n) {
    const auto& a = read[n].frf;
    const auto& b = written[n].frf;
    EXPECT_EQ(a.kind, b.kind);
    EXPECT_EQ(a.response_axis, b.response_axis);
    EXPECT_EQ(a.reference_axis, b.reference_axis);
    EXPECT_EQ(a.label, b.label.empty() ? "NONE" : b.label);
    ASSERT_EQ(a.frequency_hz.size(), b.frequency_hz.size());
    for (std::size_t i = 0; i < a.frequency_hz.size(); ++i) {
      EXPECT_TRUE(same_bits(a.frequency_hz[i], b.frequency_hz[i])) << n << " " << i;
      EXPECT_TRUE(same_bits(a.value[i].real(), b.value[i].real())) << n << " " << i;
      EXPECT_TRUE(same_bits(a.value[i].imag(), b.value[i].imag())) << n << " " << i;
    }
    EXPECT_EQ(read[n].response_node, written[n].response_node);
    EXPECT_EQ(read[n].reference_node, written[n].reference_node);
    EXPECT_EQ(read[n].response_entity, written[n].response_entity);
    EXPECT_EQ(read[n].id_lines[3],
              written[n].id_lines[3].empty() ? "NONE" : written[n].id_lines[3]);
  }
}

TEST(Uff58, AsciiAndBinaryRoundTripsAreBitExact) {
  const auto frfs = sample_frfs();
  const auto dir = std::filesystem::temp_directory_path() / "robomill-test-uff58";
  std::filesystem::create_directories(dir);
  for (const auto encoding : {io::UffEncoding::ascii, io::UffEncoding::binary}) {
    const auto file = dir / (encoding == io::UffEncoding::ascii ? "a.uff" : "b.uff");
    io::write_uff58(file, frfs, encoding);
    expect_same(io::read_uff58(file), frfs);
  }
  const std::string ascii = io::format_uff58(frfs, io::UffEncoding::ascii);
  EXPECT_NE(ascii.find("         6         9         1"), std::string::npos);  // even spacing
  EXPECT_NE(ascii.find("         6         7         0"), std::string::npos);  // uneven
  std::filesystem::remove_all(dir);
}

TEST(Uff58, ReadsBigEndianBinaryAndTolerantLineBreaks) {
  const auto frfs = sample_frfs();
  std::string bytes = io::format_uff58({frfs[1]}, io::UffEncoding::binary);
  // Swap to big-endian: flag 2 and every double's bytes reversed.
  const std::size_t header = bytes.find("58b");
  bytes[header + 3 + 5] = '2';
  std::size_t data = header;
  for (int line = 0; line < 12; ++line)
    data = bytes.find('\n', data) + 1;
  for (std::size_t i = 0; i < 7 * 3; ++i)
    std::reverse(bytes.begin() + static_cast<long>(data + 8 * i),
                 bytes.begin() + static_cast<long>(data + 8 * i + 8));
  // Some writers end the binary block with CR LF before the delimiter.
  bytes.insert(data + 7 * 3 * 8, "\r\n");
  expect_same(io::parse_uff58(bytes, "be.uff"), {frfs[1]});
  // pyuff declares 8 bytes per point whatever the layout (7 × 8 = 56).
  std::string pyuff = io::format_uff58({frfs[1]}, io::UffEncoding::binary);
  pyuff.replace(pyuff.find("         168"), 12, "          56");
  expect_same(io::parse_uff58(pyuff, "pyuff.uff"), {frfs[1]});
}

TEST(Uff58, ReadsClassicFixedFormatInMillimetresPerNewton) {
  // Negative response direction (-y): the data is negated to give +y/+x.
  std::string text = "    -1\n   151\nmodel\nNONE\n    -1\n" + classic(record6(4, -2, 1), "mm/N");
  // A coherence (function type 6) in the same file is skipped.
  text += classic(record6(6, 1, 1));
  const auto frfs = io::parse_uff58(text, "hammer.uff");
  ASSERT_EQ(frfs.size(), 1u);
  const auto& frf = frfs[0].frf;
  EXPECT_EQ(frf.kind, FrfKind::receptance);
  EXPECT_EQ(frf.response_axis, 1);
  EXPECT_EQ(frf.reference_axis, 0);
  EXPECT_EQ(frf.label, "FRF tool tip x/x");
  EXPECT_EQ(frfs[0].response_node, 7);
  ASSERT_EQ(frf.frequency_hz, (std::vector<double>{0.0, 10.0, 20.0}));
  EXPECT_DOUBLE_EQ(frf.value[1].real(), -3e-6);
  EXPECT_DOUBLE_EQ(frf.value[1].imag(), 4e-6);
}

TEST(Uff58, ReadsSinglePrecisionUnevenAccelerationInGWithTouchingFields) {
  // Case 4 of the spec (complex single, uneven, 6E13.5): negative numbers fill
  // their 13 columns, so the fields touch.
  const std::string text =
      "    -1\n    58\nNONE\nNONE\nNONE\nNONE\nNONE\n" + record6(4, 3, 3) +
      "\n         5         2         0  0.00000E+00  0.00000E+00  0.00000E+00\n"
      "        18    0    0    0 Frequency            Hz\n"
      "        12    0    0    0 Acceleration         g\n"
      "        13    0    0    0 Force                N\n"
      "         0    0    0    0 NONE                 NONE\n"
      "  1.00000E+01-2.50000E-01 5.00000E-01  2.00000E+01-1.00000E+00-2.00000E+00\n"
      "    -1\n";
  const auto frf = io::parse_uff58(text, "g.uff").at(0).frf;
  EXPECT_EQ(frf.kind, FrfKind::accelerance);
  EXPECT_EQ(frf.response_axis, 2);
  EXPECT_EQ(frf.frequency_hz, (std::vector<double>{10.0, 20.0}));
  EXPECT_DOUBLE_EQ(frf.value[0].real(), -0.25 * 9.80665);
  EXPECT_DOUBLE_EQ(frf.value[1].imag(), -2.0 * 9.80665);
}

TEST(Uff58, UnitsFromDataset164AndCallerOverrides) {
  // "NONE" labels: the unit system of dataset 164 (mm, N) applies.
  const std::string units =
      "    -1\n   164\n         5mm (newton)                 2\n"
      "  1.00000000000000000D+03  1.00000000000000000D+00  1.00000000000000000D+00\n"
      "  2.73150000000000000D+02\n    -1\n";
  const auto frf = io::parse_uff58(units + classic(record6(4, 1, 1), "NONE"), "u.uff").at(0).frf;
  EXPECT_DOUBLE_EQ(frf.value[0].real(), 1e-6);
  // The caller's scale and kind win; direction 0 (scalar) needs the caller's axis.
  io::Uff58ReadOptions options;
  options.ordinate_scale_to_si = 2.0;
  options.kind = FrfKind::mobility;
  options.response_axis = 1;
  options.reference_axis = 1;
  const auto scaled = io::parse_uff58(classic(record6(4, 0, -1), "furlong"), "o.uff", options);
  EXPECT_EQ(scaled.at(0).frf.kind, FrfKind::mobility);
  EXPECT_EQ(scaled[0].frf.response_axis, 1);
  EXPECT_DOUBLE_EQ(scaled[0].frf.value[0].real(), -2e-3);  // reference -y flips the sign
}

TEST(Uff58, RejectsMalformedInputWithLineAndReason) {
  const std::string good = classic(record6(4, 1, 1));
  ASSERT_NO_THROW(io::parse_uff58(good, "frf file x.uff"));
  expect_rejected(with_line(good, 8, record6(4, 1, 1).substr(0, 50)), 8, "wrong record length");
  expect_rejected(with_line(good, 15, "    -1"), 15, "truncated data");
  expect_rejected(good.substr(0, good.size() - 7), 16, "truncated data");
  expect_rejected(with_line(good, 10, "        17    0    0    0 Time                 s"), 10,
                  "unknown abscissa type 17");
  expect_rejected(with_line(good, 15, "  5.000000000000E-03 -6.0000000000O0E-03"), 15,
                  "non-numeric value");
  expect_rejected(with_line(good, 8, record6(4, 1, 1).replace(0, 5, "  4x ")), 8,
                  "function type: expected an integer");
  expect_rejected(with_line(good, 9, "         6        -3         1  0.0E+00  1.0E+01  0.0E+00"),
                  9, "number of points -3");
  expect_rejected(with_line(good, 9, "         6 999999999999   1  0.0E+00  1.0E+01  0.0E+00"), 9,
                  "number of points");
  expect_rejected(with_line(good, 9, "         6         3         1  0.0E+00  1.0E+01"), 9,
                  "record 7 needs 6 fields");
  expect_rejected(with_line(good, 15, "  5.000000000000E-03                 nan"), 15,
                  "non-finite");
  expect_rejected(with_line(good, 15, "  5.0E-03 -6.0E-03  7.0E-03"), 15, "more values");
  expect_rejected(with_line(good, 8, record6(1, 1, 1)), 8, "function type 1 is not 4");
  expect_rejected(with_line(good, 8, record6(4, 0, 1)), 8, "not a translation");
  expect_rejected(with_line(good, 11, "         8    0    0    0 Displacement         furlong"), 11,
                  "unknown ordinate unit 'furlong'");
  expect_rejected(with_line(good, 11, "        12    0    0    0 Acceleration         mm"), 11,
                  "contradicts");
  expect_rejected(with_line(good, 9, "         4         3         1  0.0E+00  1.0E+01  0.0E+00"),
                  9, "complex ordinates");
  expect_rejected(with_line(good, 9, "         6         3         1  0.0E+00 -1.0E+01  0.0E+00"),
                  9, "positive increment");
  expect_rejected("    58\n", 1, "delimiter");
  expect_rejected("", 0, "no dataset 58");

  // Binary: the declared byte count must match record 7 and the bytes present.
  const std::string binary = io::format_uff58({sample_frfs()[0]}, io::UffEncoding::binary);
  const std::size_t count_at = binary.find("         144");  // 9 points × 2 × 8 bytes
  ASSERT_NE(count_at, std::string::npos);
  expect_rejected(std::string(binary).replace(count_at, 12, "         152"), 8,
                  "binary length mismatch");
  expect_rejected(binary.substr(0, binary.size() - 60), 8, "truncated binary data");
  expect_rejected(std::string(binary).replace(binary.find("58b") + 8, 1, "3"), 8,
                  "byte order must be 1");
  std::string garbage_after = binary;
  garbage_after.insert(garbage_after.size() - 7, "xx");
  EXPECT_THROW(io::parse_uff58(garbage_after, "g"), InputError);
}

}  // namespace

}  // namespace test_uff58_cpp
