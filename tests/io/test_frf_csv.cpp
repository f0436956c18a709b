// FRF CSV files: the two layouts, units, round trip and rejections.

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <filesystem>
#include <numbers>

#include "robomill/core/error.hpp"
#include "robomill/io/frf_csv.hpp"

namespace test_frf_csv_cpp {

namespace {

using namespace robomill;

void expect_rejected(const std::string& text, int line, const std::string& reason) {
  try {
    io::parse_frf_csv(text, "x.csv");
    ADD_FAILURE() << "accepted; expected line " << line << ": " << reason;
  } catch (const InputError& error) {
    EXPECT_EQ(error.line(), line) << error.what();
    EXPECT_NE(std::string(error.what()).find(reason), std::string::npos) << error.what();
  }
}

TEST(FrfCsv, ReadsRealImaginaryInMillimetresPerNewton) {
  io::FrfCsvOptions options;
  options.scale_to_si = 1e-3;
  options.response_axis = 1;
  options.reference_axis = 1;
  const auto frf = io::parse_frf_csv(
      "# hammer test, mm/N\nfreq_hz,re,im\n\n10,0.5,-0.25\n20, -1e-2 ,3\n", "y.csv", options);
  EXPECT_EQ(frf.frequency_hz, (std::vector<double>{10.0, 20.0}));
  EXPECT_DOUBLE_EQ(frf.value[0].real(), 0.5e-3);
  EXPECT_DOUBLE_EQ(frf.value[1].imag(), 3e-3);
  EXPECT_EQ(frf.response_axis, 1);
  EXPECT_EQ(frf.kind, dynamics::FrfKind::receptance);
}

TEST(FrfCsv, ReadsMagnitudeAndPhaseInDegrees) {
  io::FrfCsvOptions options;
  options.kind = dynamics::FrfKind::accelerance;
  const auto frf = io::parse_frf_csv("freq_hz,mag,phase_deg\n0,2,90\n5,1,-180\n", "a.csv", options);
  EXPECT_EQ(frf.kind, dynamics::FrfKind::accelerance);
  EXPECT_NEAR(frf.value[0].real(), 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(frf.value[0].imag(), 2.0);
  EXPECT_DOUBLE_EQ(frf.value[1].real(), -1.0);
}

TEST(FrfCsv, WriteThenReadIsBitExact) {
  dynamics::Frf frf;
  for (int i = 0; i < 50; ++i) {
    frf.frequency_hz.push_back(std::pow(1.1, i) / 7.0);
    frf.value.emplace_back(std::sin(i) / 3e5, -std::cos(i * std::numbers::pi / 7) * 1e-300);
  }
  const auto file = std::filesystem::temp_directory_path() / "robomill-test-frf.csv";
  io::write_frf_csv(file, frf);
  const auto read = io::read_frf_csv(file);
  std::filesystem::remove(file);
  ASSERT_EQ(read.value.size(), frf.value.size());
  for (std::size_t i = 0; i < frf.value.size(); ++i) {
    EXPECT_EQ(read.frequency_hz[i], frf.frequency_hz[i]);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(read.value[i].real()),
              std::bit_cast<std::uint64_t>(frf.value[i].real()));
    EXPECT_EQ(read.value[i].imag(), frf.value[i].imag());
  }
  EXPECT_EQ(io::format_frf_csv(frf).rfind("# receptance, m/N\nfreq_hz,re,im\n", 0), 0u);
}

TEST(FrfCsv, RejectsBadFilesWithLineNumbers) {
  expect_rejected("# c\nfreq_hz,real,imag\n1,2,3\n", 2,
                  "expected the header 'freq_hz,re,im' or 'freq_hz,mag,phase_deg'");
  expect_rejected("freq_hz,re,im\n", 1, "no data rows");
  expect_rejected("freq_hz,re,im\n1,2,3\n\n1,2,3\n", 4, "strictly increasing");
  expect_rejected("freq_hz,re,im\n-1,2,3\n", 2, "freq_hz must be >= 0");
  expect_rejected("freq_hz,re,im\n1,2,x\n", 2, "expected a finite number");
  expect_rejected("freq_hz,re,im\n1,2,nan\n", 2, "expected a finite number");
  expect_rejected("freq_hz,re,im\n1,2\n", 2, "expected 3 values");
  expect_rejected("freq_hz,mag,phase_deg\n1,-2,3\n", 2, "mag must be >= 0");
  expect_rejected("", 0, "empty file");
  io::FrfCsvOptions huge;
  huge.scale_to_si = 1e300;
  EXPECT_THROW(io::parse_frf_csv("freq_hz,re,im\n1,1e300,0\n", "h.csv", huge), InputError);
  EXPECT_THROW(io::read_frf_csv("/nonexistent/frf.csv"), InputError);
}

}  // namespace

}  // namespace test_frf_csv_cpp
