// Programs written back with robomill's spindle and feed changes
// (io/program_writer.hpp): the statements land before the named lines in the
// dialect's own syntax (or a line's own F word is rescaled), the rest of the
// text is kept byte for byte, and the result reads back through the reader it
// came from with the new speeds and feeds in force.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>

#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/io/program_writer.hpp"
#include "robomill/job/job.hpp"
#include "robomill/robot_path/deflection_compensation.hpp"

namespace robomill::io {
namespace test_program_writer_cpp {
namespace {

constexpr double kRadSPerRpm = 2.0 * std::numbers::pi / 60.0;

TEST(ProgramWriter, GcodeGetsAnSBlockWithItsCommentAndReadsBack) {
  const std::string text =
      "%\nO1 (T)\nG90 G21 G17\nT1 M6\nS8000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F300\nG1 X50\nG0 Z5\nM30\n%\n";
  const std::string written =
      write_spindle_edits(text, job::ToolpathSettings::Format::gcode,
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
  const std::string written = write_spindle_edits(text, job::ToolpathSettings::Format::apt,
                                                  {{7, -4200 * kRadSPerRpm, "robomill: faster"}});
  EXPECT_NE(written.find("$$ robomill: faster\r\nSPINDL/RPM,4200,CCLW\r\nGOTO/40,0,-1\r\n"),
            std::string::npos)
      << written;
  const toolpath::Program after = read_apt(written, {});
  ASSERT_FALSE(after.moves.empty());
  EXPECT_NEAR(after.moves.back().spindle_rad_s, -4200 * kRadSPerRpm, 1e-9);
}

TEST(ProgramWriter, EditsAtTheEndAndWithoutAFinalLineEnd) {
  EXPECT_EQ(write_spindle_edits("G0 X0", job::ToolpathSettings::Format::gcode,
                                {{2, 1000 * kRadSPerRpm, "end"}}),
            "G0 X0\nS1000 (end)\n");
}

TEST(ProgramWriter, KrlIsRefusedByName) {
  try {
    (void)write_spindle_edits("LIN P1\n", job::ToolpathSettings::Format::krl, {{1, 100.0, "x"}});
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
  const std::string written = write_program_edits(text, job::ToolpathSettings::Format::gcode, {},
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
    const std::string written = write_program_edits(text, job::ToolpathSettings::Format::gcode, {},
                                                    {{4, 0.37, 0.0, "slower"}});
    const std::vector<double> before = feeds_mm_min(read_gcode(text, {}));
    const std::vector<double> after = feeds_mm_min(read_gcode(written, {}));
    ASSERT_EQ(before.size(), after.size()) << written;
    EXPECT_NEAR(after[0], before[0], 1e-9);
    EXPECT_NEAR(after[1], 0.37 * before[1], 1e-9 * before[1]) << written;
  }
}

TEST(ProgramWriter, GcodeFeedAsAnExpressionIsRefusedWithItsLine) {
  try {
    (void)write_program_edits("G1 X1 F[100*2]\nG1 X2\n", job::ToolpathSettings::Format::gcode, {},
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
        write_program_edits(text, job::ToolpathSettings::Format::apt, {},
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
      write_program_edits(text, job::ToolpathSettings::Format::krl, {},
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
}  // namespace test_program_writer_cpp
}  // namespace robomill::io

namespace robomill::io {
namespace test_program_writer_cpp {
namespace {

// Every program of the readers' corpus (tests/toolpath/gcode, apt, krl: what
// CAM posts write — modal F, inch units, G95, drilling cycles, FEDRAT forms,
// FOR loops, inline forms), every other feed line slowed or sped up, the
// restores placed by with_feed_restores: the written program reads back with
// each move's feed exactly the scaled one (to the 6 digits written) and
// everything else as before.
namespace corpus {

namespace fs = std::filesystem;

std::string text_of(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

struct Checked {
  int programs = 0, edited_lines = 0, refused = 0;
};

// The program as its reader takes it; nullopt for one the reader refuses on
// purpose (its own tests say why).
std::optional<toolpath::Program> readable(
    const std::function<toolpath::Program(const std::string&)>& read, const std::string& text) {
  try {
    return read(text);
  } catch (const InputError&) {
    return std::nullopt;
  }
}

// How many moves each program line makes.
std::map<int, int> moves_per_line(const toolpath::Program& program) {
  std::map<int, int> count;
  for (const toolpath::Move& move : program.moves)
    ++count[move.line];
  return count;
}

void check(const std::string& name, const std::string& text, job::ToolpathSettings::Format format,
           const std::function<toolpath::Program(const std::string&)>& read, Checked& checked) {
  std::optional<toolpath::Program> program = readable(read, text);
  if (!program)
    return;
  toolpath::Program& before = *program;
  // Feeds are set per statement (an APT record's first line).
  const std::vector<int> starts = statement_starts(text, format);
  for (toolpath::Move& move : before.moves)
    if (move.line > 0 && static_cast<std::size_t>(move.line) < starts.size())
      move.line = starts[static_cast<std::size_t>(move.line)];
  std::map<int, double> scale;
  int k = 0;
  for (const toolpath::Move& move : before.moves)
    if ((move.kind == toolpath::MotionKind::linear || move.kind == toolpath::MotionKind::arc) &&
        move.feed_m_s > 0.0 && !scale.count(move.line))
      scale[move.line] = (k++ % 2 == 0) ? (k % 4 == 1 ? 0.5 : 1.7) : 1.0;
  std::vector<FeedEdit> changed;
  for (const auto& [line, s] : scale)
    if (s != 1.0) {
      double programmed = 0.0;
      for (const toolpath::Move& move : before.moves)
        if (move.line == line && move.feed_m_s > 0.0)
          programmed = programmed == 0.0 ? move.feed_m_s : std::min(programmed, move.feed_m_s);
      changed.push_back({line, s, programmed, "robomill: test"});
    }
  if (changed.empty())
    return;
  std::string written;
  try {
    written = write_program_edits(text, format, {}, with_feed_restores(before, changed));
  } catch (const InputError& error) {
    // The one refusal the corpus holds: a drilling cycle's own feed.
    const std::string why = error.what();
    if (why.find("sets its own feed") != std::string::npos) {
      ++checked.refused;
      return;
    }
    ADD_FAILURE() << name << ": " << why;
    return;
  }
  toolpath::Program after;
  try {
    after = read(written);
  } catch (const InputError& error) {
    ADD_FAILURE() << name << ": the written program does not read back: " << error.what() << "\n"
                  << written;
    return;
  }
  ASSERT_EQ(after.moves.size(), before.moves.size()) << name << "\n" << written;
  for (std::size_t m = 0; m < after.moves.size(); ++m) {
    const toolpath::Move& was = before.moves[m];
    const toolpath::Move& now = after.moves[m];
    const auto it = scale.find(was.line);
    const bool feeds =
        (was.kind == toolpath::MotionKind::linear || was.kind == toolpath::MotionKind::arc) &&
        was.feed_m_s > 0.0;
    const double expected = feeds && it != scale.end() ? was.feed_m_s * it->second : was.feed_m_s;
    EXPECT_NEAR(now.feed_m_s, expected, 1e-5 * expected + 1e-15)
        << name << ": move " << m << " (line " << was.line << ")\n"
        << written;
    EXPECT_EQ(now.spindle_rad_s, was.spindle_rad_s) << name << ": move " << m;
    EXPECT_LT((now.end_m - was.end_m).norm(), 1e-12) << name << ": move " << m;
  }
  ++checked.programs;
  checked.edited_lines += static_cast<int>(changed.size());
}

// Every G-code (.nc, .ngc) and APT program of the readers' corpus, with
// its name, text, format and reader.
using Reader = std::function<toolpath::Program(const std::string&)>;
void for_each_gcode_and_apt(
    const std::function<void(const std::string&, const std::string&, job::ToolpathSettings::Format,
                             const Reader&, bool gcode)>& visit) {
  const fs::path root = fs::path(ROBOMILL_SOURCE_DIR) / "tests" / "toolpath";
  const Reader gcode = [](const std::string& t) { return read_gcode(t, {}); };
  const Reader apt = [](const std::string& t) { return read_apt(t, {}); };
  for (const auto& entry : fs::directory_iterator(root / "gcode")) {
    const std::string ext = entry.path().extension().string();
    if (entry.is_regular_file() && (ext == ".nc" || ext == ".ngc"))
      visit(entry.path().filename().string(), text_of(entry.path()),
            job::ToolpathSettings::Format::gcode, gcode, true);
  }
  for (const auto& entry : fs::directory_iterator(root / "apt"))
    if (entry.is_regular_file())
      visit(entry.path().filename().string(), text_of(entry.path()),
            job::ToolpathSettings::Format::apt, apt, false);
}

}  // namespace corpus

TEST(ProgramWriter, FeedsOfTheReaderCorpusRoundTrip) {
  const corpus::fs::path root = corpus::fs::path(ROBOMILL_SOURCE_DIR) / "tests" / "toolpath";
  corpus::Checked gcode, apt, krl;
  corpus::for_each_gcode_and_apt(
      [&](const std::string& name, const std::string& text, job::ToolpathSettings::Format format,
          const corpus::Reader& read,
          bool is_gcode) { corpus::check(name, text, format, read, is_gcode ? gcode : apt); });
  for (const auto& entry : corpus::fs::directory_iterator(root / "krl")) {
    if (!entry.is_regular_file() || entry.path().extension() != ".src")
      continue;
    KrlOptions options;
    options.dat_name = entry.path().stem().string() + ".dat";
    options.dat_text = corpus::text_of(corpus::fs::path(entry.path()).replace_extension(".dat"));
    corpus::check(
        entry.path().filename().string(), corpus::text_of(entry.path()),
        job::ToolpathSettings::Format::krl,
        [&](const std::string& t) { return read_krl(t, options); }, krl);
  }
  // The corpus as it stands: most G-code programs read with default
  // options; every APT and KRL program does.
  EXPECT_GE(gcode.programs, 20) << gcode.edited_lines;
  EXPECT_GE(apt.programs, 5);
  EXPECT_EQ(apt.refused, 1);  // mastercam_drill.apt: CYCLE/DRILL with its own feed
  EXPECT_GE(krl.programs, 3);
  std::cout << "feed round trips: " << gcode.programs << " G-code programs (" << gcode.edited_lines
            << " lines), " << apt.programs << " APT (" << apt.edited_lines << "), " << krl.programs
            << " KRL (" << krl.edited_lines << ")\n";
}

// The written program through its reader; a failure names the program.
std::optional<toolpath::Program> written_reads_back(
    const std::string& name, const std::string& text,
    const std::function<toolpath::Program(const std::string&)>& read) {
  try {
    return read(text);
  } catch (const InputError& error) {
    ADD_FAILURE() << name << ": the written program does not read back: " << error.what() << "\n"
                  << text;
    return std::nullopt;
  }
}

// The deflection compensation's moved points (write_point_edits) on the
// same corpus: every other line that programs one straight feed move (not
// followed by an arc, whose centre is relative to its start) moved by
// (+30, −20, +10) µm. Read back: the edited moves end exactly there (to the
// 0.1 µm written), every other move ends where it did (the modal axes an
// edit changed are put back on the next line that moves), nothing else
// changes; lines the writer skips are named with a reason and unchanged.
namespace points {

struct Checked {
  int programs = 0, edited = 0, skipped = 0, added = 0;
};

void check(const std::string& name, const std::string& text, job::ToolpathSettings::Format format,
           const std::function<toolpath::Program(const std::string&)>& read, Checked& checked) {
  const std::optional<toolpath::Program> program = corpus::readable(read, text);
  if (!program)
    return;
  const toolpath::Program& before = *program;
  std::map<int, int> moves_on_line = corpus::moves_per_line(before);
  const Eigen::Vector3d offset(30e-6, -20e-6, 10e-6);
  std::vector<PointEdit> edits;
  std::vector<robot_path::LineCorrection> corrections;
  int k = 0;
  for (std::size_t m = 0; m < before.moves.size(); ++m) {
    const toolpath::Move& move = before.moves[m];
    const bool before_arc =
        m + 1 < before.moves.size() && before.moves[m + 1].kind == toolpath::MotionKind::arc;
    if (move.kind != toolpath::MotionKind::linear || moves_on_line[move.line] != 1 || before_arc ||
        k++ % 2 != 0)
      continue;
    PointEdit edit{move.line, offset, {}, "robomill: test", std::nullopt};
    robot_path::LineCorrection correction{m, move.line, offset, {}, std::nullopt};
    if (k % 4 == 1) {  // every other edit adds two points inside its line
      edit.points = {{0.25, Eigen::Vector3d(-15e-6, 5e-6, 0.0)}, {0.6, offset}};
      correction.points = {{0.25, edit.points[0].offset_m}, {0.6, offset}};
    }
    edits.push_back(edit);
    corrections.push_back(correction);
  }
  if (edits.empty())
    return;
  const PointEditResult written = write_point_edits(text, format, edits);
  for (const auto& skipped : written.skipped) {
    EXPECT_FALSE(skipped.reason.empty());
    std::erase_if(corrections,
                  [&](const robot_path::LineCorrection& c) { return c.line == skipped.line; });
  }
  const std::optional<toolpath::Program> read_back = written_reads_back(name, written.text, read);
  if (!read_back)
    return;
  const toolpath::Program& after = *read_back;
  // Every written move ends where the corrected path does (the added points,
  // then the moved end; every other move where it was).
  const std::vector<Eigen::Vector3d> expected = robot_path::corrected_ends(before, corrections);
  ASSERT_EQ(after.moves.size(), expected.size()) << name << "\n" << written.text;
  for (std::size_t m = 0; m < after.moves.size(); ++m)
    EXPECT_LT((after.moves[m].end_m - expected[m]).norm(), 1e-6)
        << name << ": written move " << m << " (line " << after.moves[m].line << ") ends at "
        << after.moves[m].end_m.transpose() * 1e3 << " mm, expected "
        << expected[m].transpose() * 1e3 << "\n"
        << written.text;
  ++checked.programs;
  checked.skipped += static_cast<int>(written.skipped.size());
  checked.edited += static_cast<int>(corrections.size());
  checked.added += static_cast<int>(after.moves.size() - before.moves.size());
}

}  // namespace points

TEST(ProgramWriter, MovedPointsOfTheReaderCorpusRoundTrip) {
  points::Checked gcode, apt;
  corpus::for_each_gcode_and_apt(
      [&](const std::string& name, const std::string& text, job::ToolpathSettings::Format format,
          const corpus::Reader& read,
          bool is_gcode) { points::check(name, text, format, read, is_gcode ? gcode : apt); });
  EXPECT_GE(gcode.programs, 20);
  EXPECT_GE(apt.programs, 4);
  EXPECT_GT(gcode.edited, 10 * gcode.skipped) << gcode.skipped;
  EXPECT_GT(gcode.added, 10);
  EXPECT_GT(apt.added, 0);
  std::cout << "moved points: " << gcode.programs << " G-code programs (" << gcode.edited
            << " lines moved, " << gcode.added << " points added, " << gcode.skipped
            << " skipped), " << apt.programs << " APT (" << apt.edited << ", " << apt.added
            << " added, " << apt.skipped << " skipped)\n";
  // KRL is refused by name.
  try {
    (void)write_point_edits("DEF t( )\nEND\n", job::ToolpathSettings::Format::krl,
                            {{1, {}, {}, "", std::nullopt}});
    ADD_FAILURE() << "KRL point edits must be refused";
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), "toolpath.format");
  }
}

}  // namespace
}  // namespace test_program_writer_cpp
}  // namespace robomill::io

namespace robomill::io {
namespace test_program_writer_cpp {
namespace {

// An arc's compensation written (PointEdit::arc) on the same corpus: for
// every other arc alone on its line after a straight feed line alone on its
// (and not followed by another arc), the circle's centre moved by
// (12, −8, 5) µm projected on its plane and its radius grown by 25 µm, the
// line before ending on the moved circle (Δc + δ r̂ at the start). Read back:
// every move ends where the corrected path does, every arc's centre lies
// where it was meant to (moved, or as programmed), to the 0.1 µm written.
// Pairs the writer skips (named with a reason) are dropped and the rest
// written again, as the command does.
namespace arcs {

struct Checked {
  int programs = 0, arcs = 0, skipped = 0;
};

void check(const std::string& name, const std::string& text, job::ToolpathSettings::Format format,
           const std::function<toolpath::Program(const std::string&)>& read, Checked& checked) {
  const std::optional<toolpath::Program> program = corpus::readable(read, text);
  if (!program)
    return;
  const toolpath::Program& before = *program;
  std::map<int, int> moves_on_line = corpus::moves_per_line(before);
  auto alone = [&](std::size_t m) { return moves_on_line[before.moves[m].line] == 1; };
  struct Pair {
    robot_path::LineCorrection line, arc;
  };
  std::vector<Pair> pairs;
  int k = 0;
  for (std::size_t m = 1; m + 1 <= before.moves.size(); ++m) {
    const toolpath::Move& arc = before.moves[m];
    const toolpath::Move& line = before.moves[m - 1];
    const bool next_arc =
        m + 1 < before.moves.size() && before.moves[m + 1].kind == toolpath::MotionKind::arc;
    if (arc.kind != toolpath::MotionKind::arc || line.kind != toolpath::MotionKind::linear ||
        !alone(m) || !alone(m - 1) || next_arc || k++ % 2 != 0)
      continue;
    Eigen::Vector3d centre_offset(12e-6, -8e-6, 5e-6);
    centre_offset -= centre_offset.dot(arc.normal) * arc.normal;
    const double radius_change = 25e-6;
    auto radial = [&](const Eigen::Vector3d& p) {
      Eigen::Vector3d r = p - arc.centre_m;
      return Eigen::Vector3d(r - r.dot(arc.normal) * arc.normal).normalized();
    };
    Pair pair;
    pair.line = {m - 1, line.line, centre_offset + radius_change * radial(arc.start_m), {}, {}};
    pair.arc = {m,
                arc.line,
                centre_offset + radius_change * radial(arc.end_m),
                {},
                robot_path::ArcCorrection{centre_offset, radius_change, 0.0}};
    pairs.push_back(pair);
  }
  if (pairs.empty())
    return;
  PointEditResult written;
  for (;;) {
    std::vector<PointEdit> edits;
    for (const Pair& p : pairs) {
      edits.push_back({p.line.line, p.line.offset_m, {}, "robomill: test", std::nullopt});
      edits.push_back({p.arc.line,
                       p.arc.offset_m,
                       {},
                       "robomill: test arc",
                       PointEdit::Arc{p.arc.arc->centre_offset_m, p.arc.arc->radius_change_m}});
    }
    written = write_point_edits(text, format, edits);
    if (written.skipped.empty())
      break;
    for (const auto& skipped : written.skipped) {
      EXPECT_FALSE(skipped.reason.empty());
      ++checked.skipped;
      std::erase_if(pairs, [&](const Pair& p) {
        return p.line.line == skipped.line || p.arc.line == skipped.line;
      });
    }
  }
  if (pairs.empty())
    return;
  std::vector<robot_path::LineCorrection> corrections;
  std::map<std::size_t, Eigen::Vector3d> centre_offset;  // by move
  for (const Pair& p : pairs) {
    corrections.push_back(p.line);
    corrections.push_back(p.arc);
    centre_offset[p.arc.move] = p.arc.arc->centre_offset_m;
  }
  const std::optional<toolpath::Program> read_back = written_reads_back(name, written.text, read);
  if (!read_back)
    return;
  const toolpath::Program& after = *read_back;
  const std::vector<Eigen::Vector3d> expected = robot_path::corrected_ends(before, corrections);
  ASSERT_EQ(after.moves.size(), expected.size()) << name << "\n" << written.text;
  for (std::size_t m = 0; m < after.moves.size(); ++m) {
    EXPECT_LT((after.moves[m].end_m - expected[m]).norm(), 1e-6)
        << name << ": written move " << m << " (line " << after.moves[m].line << ")";
    const toolpath::Move& was = before.moves[m];
    if (was.kind != toolpath::MotionKind::arc)
      continue;
    ASSERT_EQ(after.moves[m].kind, toolpath::MotionKind::arc) << name << " move " << m;
    const auto it = centre_offset.find(m);
    Eigen::Vector3d miss =
        after.moves[m].centre_m - was.centre_m -
        (it == centre_offset.end() ? Eigen::Vector3d(Eigen::Vector3d::Zero()) : it->second);
    miss -= miss.dot(was.normal) * was.normal;
    EXPECT_LT(miss.norm(), 1e-6) << name << ": arc on line " << was.line << "\n" << written.text;
    EXPECT_NEAR(after.moves[m].sweep_rad, was.sweep_rad, 1e-3) << name << " line " << was.line;
  }
  ++checked.programs;
  checked.arcs += static_cast<int>(pairs.size());
}

}  // namespace arcs

TEST(ProgramWriter, MovedArcsOfTheReaderCorpusRoundTrip) {
  arcs::Checked gcode, apt;
  corpus::for_each_gcode_and_apt(
      [&](const std::string& name, const std::string& text, job::ToolpathSettings::Format format,
          const corpus::Reader& read,
          bool is_gcode) { arcs::check(name, text, format, read, is_gcode ? gcode : apt); });
  std::cout << "moved arcs: " << gcode.programs << " G-code programs (" << gcode.arcs << " arcs, "
            << gcode.skipped << " skipped), " << apt.programs << " APT (" << apt.arcs << ", "
            << apt.skipped << " skipped)\n";
  EXPECT_GE(gcode.programs, 5);
  EXPECT_GT(gcode.arcs, 5 * gcode.skipped);
  EXPECT_GE(apt.programs, 1);
}

}  // namespace
}  // namespace test_program_writer_cpp
}  // namespace robomill::io
