// Programs written back with robomill's spindle changes (io/program_writer.hpp):
// the statements land before the named lines in the dialect's own syntax, the
// rest of the text is kept byte for byte, and the result reads back through
// the reader it came from with the new speeds in force.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/io/program_writer.hpp"

namespace robomill::io {
namespace {

constexpr double kRadSPerRpm = 2.0 * std::numbers::pi / 60.0;

TEST(ProgramWriter, GcodeGetsAnSBlockWithItsCommentAndReadsBack) {
  const std::string text =
      "%\nO1 (T)\nG90 G21 G17\nT1 M6\nS8000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F300\nG1 X50\nG0 Z5\nM30\n%\n";
  const std::string written =
      write_spindle_edits(text, ToolpathSettings::Format::gcode,
                          {{8, 9500 * kRadSPerRpm, "robomill: S8000 -> S9500 (margin)"},
                           {9, 8000 * kRadSPerRpm, "robomill: back"}});
  EXPECT_NE(written.find("S9500 (robomill: S8000 -> S9500 [margin])\nG1 X50\n"), std::string::npos)
      << written;
  EXPECT_NE(written.find("G1 X50\nS8000 (robomill: back)\nG0 Z5\n"), std::string::npos);
  // Everything else is the original text.
  std::string stripped = written;
  const std::vector<std::string> inserted = {"S9500 (robomill: S8000 -> S9500 [margin])\n",
                                             "S8000 (robomill: back)\n"};
  for (const std::string& line : inserted)
    stripped.erase(stripped.find(line), line.size());
  EXPECT_EQ(stripped, text);
  const toolpath::Program before = read_gcode(text, {});
  const toolpath::Program after = read_gcode(written, {});
  ASSERT_EQ(before.moves.size(), after.moves.size());
  for (std::size_t m = 0; m < after.moves.size(); ++m) {
    // Lines move down by the inserted blocks; the cutting move of line 8
    // (X0 → X50 at Z−1) is the only one at the new speed.
    const bool is_x50 = std::abs(after.moves[m].end_m.x() - 0.05) < 1e-12 &&
                        after.moves[m].kind == toolpath::MotionKind::linear &&
                        std::abs(after.moves[m].start_m.x()) < 1e-12;
    EXPECT_NEAR(after.moves[m].spindle_rad_s, (is_x50 ? 9500.0 : 8000.0) * kRadSPerRpm, 1e-9)
        << "move " << m;
  }
}

TEST(ProgramWriter, AptGetsSpindlWithDirectionAndKeepsCrLf) {
  const std::string text =
      "UNITS/MM\r\nLOADTL/1\r\nSPINDL/RPM,3000,CCLW\r\nFEDRAT/MMPM,200\r\nGOTO/0,0,5\r\n"
      "GOTO/0,0,-1\r\nGOTO/40,0,-1\r\nFINI\r\n";
  const std::string written = write_spindle_edits(text, ToolpathSettings::Format::apt,
                                                  {{7, -4200 * kRadSPerRpm, "robomill: faster"}});
  EXPECT_NE(written.find("$$ robomill: faster\r\nSPINDL/RPM,4200,CCLW\r\nGOTO/40,0,-1\r\n"),
            std::string::npos)
      << written;
  const toolpath::Program after = read_apt(written, {});
  ASSERT_FALSE(after.moves.empty());
  EXPECT_NEAR(after.moves.back().spindle_rad_s, -4200 * kRadSPerRpm, 1e-9);
}

TEST(ProgramWriter, EditsAtTheEndAndWithoutAFinalLineEnd) {
  EXPECT_EQ(write_spindle_edits("G0 X0", ToolpathSettings::Format::gcode,
                                {{2, 1000 * kRadSPerRpm, "end"}}),
            "G0 X0\nS1000 (end)\n");
}

TEST(ProgramWriter, KrlIsRefusedByName) {
  try {
    (void)write_spindle_edits("LIN P1\n", ToolpathSettings::Format::krl, {{1, 100.0, "x"}});
    FAIL() << "expected an InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("toolpath.format"), std::string::npos);
  }
}

}  // namespace
}  // namespace robomill::io
