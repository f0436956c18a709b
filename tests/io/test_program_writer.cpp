// Programs written back with robomill's spindle and feed changes
// (io/program_writer.hpp): the statements land before the named lines in the
// dialect's own syntax (or a line's own F word is rescaled), the rest of the
// text is kept byte for byte, and the result reads back through the reader it
// came from with the new speeds and feeds in force.

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

// The feed of every move as a reader gives it (mm/min), by move.
std::vector<double> feeds_mm_min(const toolpath::Program& program) {
  std::vector<double> feeds;
  for (const toolpath::Move& move : program.moves)
    feeds.push_back(move.feed_m_s * 6e4);
  return feeds;
}

TEST(ProgramWriter, GcodeFeedsRescaledInTheLineOrBeforeItAndRestored) {
  // Line 7 carries its own F (rescaled in place); line 8 runs on the modal F
  // (a block before it); line 9 is unchanged and gets the F in force back.
  const std::string text =
      "%\nG90 G21 G17\nT1 M6\nS8000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F300 (plunge)\nG1 X50 F800\n"
      "G1 Y20\nG1 X0\nG0 Z5\nM30\n%\n";
  const std::string written = write_program_edits(text, ToolpathSettings::Format::gcode, {},
                                                  {{7, 0.5, 0.0, "robomill: feed (force)"},
                                                   {8, 0.25, 0.0, "robomill: slower"},
                                                   {9, 1.0, 0.0, "back"}});
  EXPECT_NE(written.find("G1 X50 F400 (robomill: feed [force])\nF200 (robomill: slower)\nG1 "
                         "Y20\nF800\nG1 X0\n"),
            std::string::npos)
      << written;
  const std::vector<double> before = feeds_mm_min(read_gcode(text, {}));
  const std::vector<double> after = feeds_mm_min(read_gcode(written, {}));
  ASSERT_EQ(before.size(), after.size());
  // Moves: G0, G1 Z-1 (300), G1 X50, G1 Y20, G1 X0, G0.
  EXPECT_NEAR(after[1], 300.0, 1e-9);
  EXPECT_NEAR(after[2], 400.0, 1e-9);
  EXPECT_NEAR(after[3], 200.0, 1e-9);
  EXPECT_NEAR(after[4], 800.0, 1e-9);
}

TEST(ProgramWriter, GcodeInchAndPerRevolutionFeedsKeepTheirUnits) {
  // G20: F in inch/min; G95: F per revolution. The rescaled word stays in
  // the mode the program wrote, so the reader gives exactly scale × feed.
  const std::string inch = "G20 G90 G94\nS1000 M3\nG1 X1 F10.0\nG1 X2\nM30\n";
  const std::string per_rev = "G21 G90 G95\nS1000 M3\nG1 X1 F0.2\nG1 X2\nM30\n";
  for (const std::string& text : {inch, per_rev}) {
    const std::string written =
        write_program_edits(text, ToolpathSettings::Format::gcode, {}, {{4, 0.37, 0.0, "slower"}});
    const std::vector<double> before = feeds_mm_min(read_gcode(text, {}));
    const std::vector<double> after = feeds_mm_min(read_gcode(written, {}));
    ASSERT_EQ(before.size(), after.size()) << written;
    EXPECT_NEAR(after[0], before[0], 1e-9);
    EXPECT_NEAR(after[1], 0.37 * before[1], 1e-9 * before[1]) << written;
  }
}

TEST(ProgramWriter, GcodeFeedAsAnExpressionIsRefusedWithItsLine) {
  try {
    (void)write_program_edits("G1 X1 F[100*2]\nG1 X2\n", ToolpathSettings::Format::gcode, {},
                              {{2, 0.5, 0.0, "x"}});
    FAIL() << "expected an InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("program line 2"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("expression"), std::string::npos);
  }
}

TEST(ProgramWriter, AptFedratInForceRescaledInEitherOrderAndRestoredAsWritten) {
  for (const std::string fedrat : {"FEDRAT/MMPM,250", "FEDRAT/250.0,MMPM", "FEDRAT/ 250"}) {
    const std::string text = "UNITS/MM\nLOADTL/1\nSPINDL/RPM,3000,CLW\n" + fedrat +
                             "\nGOTO/0,0,5\nGOTO/0,0,-1\nGOTO/40,0,-1\nGOTO/40,20,-1\nFINI\n";
    const std::string written =
        write_program_edits(text, ToolpathSettings::Format::apt, {},
                            {{7, 0.5, 0.0, "robomill: slower"}, {8, 1.0, 0.0, "robomill: back"}});
    EXPECT_NE(written.find("$$ robomill: slower\nFEDRAT/"), std::string::npos) << written;
    EXPECT_NE(written.find("$$ robomill: back\n" + fedrat + "\nGOTO/40,20,-1"), std::string::npos)
        << written;
    // The first GOTO places the tool; the moves are the three after it.
    const std::vector<double> after = feeds_mm_min(read_apt(written, {}));
    ASSERT_EQ(after.size(), 3u) << written;
    EXPECT_NEAR(after[0], 250.0, 1e-9) << fedrat;
    EXPECT_NEAR(after[1], 125.0, 1e-9) << fedrat;
    EXPECT_NEAR(after[2], 250.0, 1e-9) << fedrat;
  }
}

TEST(ProgramWriter, KrlPathSpeedSetBeforeTheMotionAndRestored) {
  const std::string text =
      "DEF p()\n$VEL.CP=0.02\nLIN {X 0, Y 0, Z 5, A 0, B 0, C 0}\n"
      "LIN {X 0, Y 0, Z -1, A 0, B 0, C 0}\nLIN {X 40, Y 0, Z -1, A 0, B 0, C 0}\n"
      "LIN {X 40, Y 20, Z -1, A 0, B 0, C 0}\nEND\n";
  const std::string written =
      write_program_edits(text, ToolpathSettings::Format::krl, {},
                          {{5, 0.5, 0.02, "robomill: slower"}, {6, 1.0, 0.02, "back"}});
  EXPECT_NE(written.find("$VEL.CP=0.01 ; robomill: slower\nLIN {X 40, Y 0"), std::string::npos)
      << written;
  KrlOptions options;
  const std::vector<double> before = feeds_mm_min(read_krl(text, options));
  const std::vector<double> after = feeds_mm_min(read_krl(written, options));
  ASSERT_EQ(before.size(), after.size());
  ASSERT_GE(after.size(), 3u);
  EXPECT_NEAR(after[after.size() - 2], 0.5 * before[before.size() - 2], 1e-9);
  EXPECT_NEAR(after.back(), before.back(), 1e-9);
}

}  // namespace
}  // namespace robomill::io
