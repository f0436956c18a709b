// read_gcode against LinuxCNC's rs274ngc interpreter, move by move.
//
// For every program in tests/toolpath/gcode/ (*.ngc, *.nc; not bad/), the
// standalone interpreter `rs274` (Debian package linuxcnc-uspace) prints the
// canonical machining calls it makes; rs274_oracle.hpp replays them into
// moves and compares them with read_gcode's (how, and to what precision, is
// described there). Without rs274 on the machine the tests are skipped, not
// failed.

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"
#include "toolpath/rs274_oracle.hpp"

namespace test_gcode_oracle_cpp {

namespace {

namespace fs = std::filesystem;
using namespace robomill::test::rs274;

fs::path corpus_dir() {
  return fs::path(ROBOMILL_SOURCE_DIR) / "tests/toolpath/gcode";
}

std::vector<std::string> corpus_programs() {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(corpus_dir())) {
    const std::string ext = entry.path().extension().string();
    if (entry.is_regular_file() && (ext == ".ngc" || ext == ".nc"))
      names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

class GcodeOracle : public ::testing::TestWithParam<std::string> {};

TEST_P(GcodeOracle, MovesMatchLinuxCncRs274) {
  const std::optional<std::string> rs274 = find_rs274();
  if (!rs274)
    GTEST_SKIP() << "rs274 (Debian package linuxcnc-uspace) is not installed: the G-code oracle "
                    "is not run";
  const fs::path path = corpus_dir() / GetParam();
  const std::string text = read_text(path);
  const OracleRun oracle = run_rs274(*rs274, text, path.stem().string());
  ASSERT_EQ(oracle.status, 0) << "rs274 refused " << GetParam() << ":\n" << oracle.output;
  ASSERT_FALSE(oracle.moves.empty()) << oracle.output;

  const robomill::toolpath::Program program =
      robomill::io::read_gcode(text, oracle_options(GetParam()));

  ASSERT_EQ(program.moves.size(), oracle.moves.size()) << "rs274 output:\n" << oracle.output;
  const std::string difference = first_difference(program, oracle.moves);
  EXPECT_TRUE(difference.empty()) << difference;
}

INSTANTIATE_TEST_SUITE_P(Corpus, GcodeOracle, ::testing::ValuesIn(corpus_programs()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c)))
                               c = '_';
                           return name;
                         });

TEST(GcodeOracleCorpus, HoldsAtLeastTwentyFivePrograms) {
  EXPECT_GE(corpus_programs().size(), 25u);
}

}  // namespace

}  // namespace test_gcode_oracle_cpp
