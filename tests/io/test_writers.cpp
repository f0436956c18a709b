// CSV tables and the atomic output bundle.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "robomill/core/error.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/output_bundle.hpp"
#include "robomill/io/summary.hpp"

namespace test_writers_cpp {

namespace {

namespace fs = std::filesystem;
using namespace robomill;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("robomill-test-" + name + "-" +
                        std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  fs::remove_all(dir);
  return dir;
}

std::string read(const fs::path& file) {
  std::ifstream stream(file);
  std::stringstream buffer;
  buffer << stream.rdbuf();
  return buffer.str();
}

TEST(CsvTable, WritesHeaderAndRoundTripsNumbers) {
  io::CsvTable table({"t_s", "fx_N"});
  table.add_row({0.0, -12.5});
  table.add_row({1e-4, 123.456789012});
  const std::string text = table.to_string();
  EXPECT_EQ(text, "t_s,fx_N\n0,-12.5\n0.0001,123.456789012\n");
  const io::CsvTable back = io::parse_csv(text, "mem");
  ASSERT_EQ(back.rows(), 2u);
  EXPECT_DOUBLE_EQ(back.at(1, 1), 123.456789012);
  EXPECT_EQ(back.find("fx_N"), 1);
  EXPECT_EQ(back.find("fy_N"), -1);
}

TEST(CsvTable, RefusesNonFiniteValues) {
  io::CsvTable table({"a"});
  EXPECT_THROW(table.add_row({std::nan("")}), NumericalError);
  EXPECT_THROW(table.add_row({INFINITY}), NumericalError);
  EXPECT_THROW(table.add_row({1.0, 2.0}), std::invalid_argument);
}

// The streaming writer writes the bytes the table does, in pieces.
TEST(CsvText, WritesWhatTheTableWritesRowByRow) {
  const std::vector<double> values = {0.0, -0.0, -12.5, 1e-4, 123.456789012, 1.0 / 3.0, 6.02e23};
  io::CsvTable table({"x", "motion", "y"});
  io::CsvText text({"x", "motion", "y"});
  std::string pieces;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const std::string word = i % 2 ? "arc" : "";
    table.add_cells({values[i], word, values[values.size() - 1 - i]});
    text.number(values[i]);
    text.word(word);
    text.number(values[values.size() - 1 - i]);
    text.end_row();
    if (i == 3)
      pieces += text.take();  // the next rows follow without a header
  }
  pieces += text.take();
  EXPECT_EQ(pieces, table.to_string());
  EXPECT_EQ(text.rows(), values.size());
  EXPECT_TRUE(io::CsvText({"a"}, false).text().empty());
}

TEST(CsvText, RefusesWhatTheTableRefuses) {
  io::CsvText text({"a", "b"});
  EXPECT_THROW(text.number(std::nan("")), NumericalError);
  EXPECT_THROW(text.number(INFINITY), NumericalError);
  EXPECT_THROW(text.word("x,y"), std::invalid_argument);
  text.number(1.0);
  EXPECT_THROW(text.end_row(), std::invalid_argument);  // one cell of two
  text.number(2.0);
  EXPECT_THROW(text.number(3.0), std::invalid_argument);  // a third
}

TEST(CsvReader, NamesTheLineOfABadCell) {
  try {
    io::parse_csv("# comment\nfeed,fx\n0.1,2\n0.2,x\n", "data.csv");
    FAIL() << "bad cell accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.line(), 4);
    EXPECT_NE(std::string(error.what()).find("fx"), std::string::npos);
  }
  EXPECT_THROW(io::parse_csv("a,b\n1\n", "x.csv"), InputError);
  EXPECT_THROW(io::parse_csv("a\nnan\n", "x.csv"), InputError);
  EXPECT_THROW(io::parse_csv("", "x.csv"), InputError);
}

TEST(OutputBundle, CommitsAllFilesAndLeavesNoTemporaries) {
  const fs::path dir = scratch("bundle");
  {
    io::OutputBundle bundle(dir / "nested");
    bundle.add("a.csv", "x\n1\n");
    bundle.add("summary.json", "{}\n");
    EXPECT_FALSE(fs::exists(dir / "nested"));  // nothing before commit
    const auto written = bundle.commit();
    EXPECT_EQ(written.size(), 2u);
  }
  EXPECT_EQ(read(dir / "nested" / "a.csv"), "x\n1\n");
  int entries = 0;
  for (const auto& entry : fs::directory_iterator(dir / "nested")) {
    EXPECT_NE(entry.path().filename().string()[0], '.') << "temporary left: " << entry.path();
    ++entries;
  }
  EXPECT_EQ(entries, 2);
  fs::remove_all(dir);
}

TEST(OutputBundle, AnUncommittedBundleWritesNothing) {
  const fs::path dir = scratch("abandoned");
  {
    io::OutputBundle bundle(dir);
    bundle.add("forces.csv", "data");
  }  // e.g. an exception before commit
  EXPECT_FALSE(fs::exists(dir));
}

TEST(Summary, RefusesNonFiniteNumbers) {
  nlohmann::json summary = {{"mean_N", io::xyz(Eigen::Vector3d(1.0, 2.0, 3.0))}};
  EXPECT_NE(io::summary_text(summary).find("\"y\": 2.0"), std::string::npos);
  summary["mean_N"]["z"] = std::nan("");
  try {
    io::summary_text(summary);
    FAIL() << "NaN accepted";
  } catch (const NumericalError& error) {
    EXPECT_NE(std::string(error.what()).find("mean_N.z"), std::string::npos);
  }
}

}  // namespace

}  // namespace test_writers_cpp
