// read_gcode: units, arcs, helices, cycles, modal behaviour, offsets, tool
// changes, notes and refusals. Expected values are worked out by hand from
// the programs here (the move-by-move comparison with LinuxCNC is
// test_gcode_oracle.cpp).

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"

namespace test_gcode_reader_cpp {

namespace {

using robomill::InputError;
using robomill::io::GcodeOptions;
using robomill::io::read_gcode;
using robomill::toolpath::MotionKind;
using robomill::toolpath::Move;
using robomill::toolpath::Program;

constexpr double kPi = std::numbers::pi;
constexpr double kTol = 1e-12;

Program read(const std::string& text, GcodeOptions options = {}) {
  return read_gcode(text, options);
}

Eigen::Vector3d mm(double x, double y, double z) {
  return Eigen::Vector3d(x, y, z) * 1e-3;
}

bool has_note(const Program& program, int line, const std::string& part) {
  for (const auto& note : program.notes)
    if (note.line == line && note.text.find(part) != std::string::npos)
      return true;
  return false;
}

/// The InputError read_gcode throws for `text` (fails the test if none).
InputError refusal(const std::string& text, const std::string& name = "test.nc") {
  GcodeOptions options;
  options.source_name = name;
  try {
    read_gcode(text, options);
  } catch (const InputError& error) {
    return error;
  }
  ADD_FAILURE() << "no InputError for:\n" << text;
  return InputError("", 0, "");
}

void expect_point(const Eigen::Vector3d& actual, const Eigen::Vector3d& expected,
                  double tolerance = 1e-12) {
  EXPECT_LE((actual - expected).norm(), tolerance)
      << "actual " << actual.transpose() << ", expected " << expected.transpose();
}

// ------------------------------------------------------------- units ------

TEST(GcodeReader, MillimetresAndInchesBecomeMetres) {
  const Program p = read("G21 G90\nG0 X10 Y-2.5 Z3\nG20\nG0 X1 Y.5 Z-.25\n");
  ASSERT_EQ(p.moves.size(), 2u);
  expect_point(p.moves[0].end_m, {0.010, -0.0025, 0.003});
  expect_point(p.moves[1].end_m, {0.0254, 0.0127, -0.00635});
  expect_point(p.moves[1].start_m, p.moves[0].end_m);
  EXPECT_EQ(p.dialect, "gcode");
}

TEST(GcodeReader, FeedIsUnitsPerMinuteInSi) {
  const Program p = read("G21 G94\nG0 X0 Y0 Z0\nG1 X10 F600\nG20 G1 X1 F10\n");
  ASSERT_EQ(p.moves.size(), 2u);
  EXPECT_NEAR(p.moves[0].feed_m_s, 0.6 / 60.0, kTol);          // 600 mm/min = 10 mm/s
  EXPECT_NEAR(p.moves[1].feed_m_s, 10 * 0.0254 / 60.0, kTol);  // 10 in/min
  EXPECT_EQ(p.moves[0].kind, MotionKind::linear);
}

TEST(GcodeReader, FeedPerRevolutionUsesTheSpindleSpeed) {
  // G95 F0.1 mm/rev at 3000 rpm = 300 mm/min = 5 mm/s.
  const Program p = read("G21 S3000 M3\nG0 X0 Y0 Z0\nG95 G1 X10 F0.1\n");
  ASSERT_EQ(p.moves.size(), 1u);
  EXPECT_NEAR(p.moves[0].feed_m_s, 0.005, kTol);
}

TEST(GcodeReader, SpindleIsSignedRadiansPerSecond) {
  const Program p =
      read("G21 G0 X0 Y0 Z0\nS6000 M3\nG0 X1\nM4\nG0 X2\nM5\nG0 X3\nS1200 M3 G0 X4\n");
  ASSERT_EQ(p.moves.size(), 4u);
  EXPECT_NEAR(p.moves[0].spindle_rad_s, 6000 * 2 * kPi / 60, 1e-9);  // 628.3 rad/s
  EXPECT_NEAR(p.moves[1].spindle_rad_s, -6000 * 2 * kPi / 60, 1e-9);
  EXPECT_EQ(p.moves[2].spindle_rad_s, 0.0);
  EXPECT_NEAR(p.moves[3].spindle_rad_s, 1200 * 2 * kPi / 60, 1e-9);
}

// -------------------------------------------------------------- arcs ------

TEST(GcodeReader, QuarterArcClockwiseWithIncrementalCentre) {
  // From (10, 0) about (0, 0) clockwise to (0, -10): a quarter turn, −π/2
  // about +Z.
  const Program p = read("G21 G17 G0 X10 Y0 Z0\nG2 X0 Y-10 I-10 J0 F100\n");
  ASSERT_EQ(p.moves.size(), 2u);
  const Move& arc = p.moves[1];
  EXPECT_EQ(arc.kind, MotionKind::arc);
  expect_point(arc.centre_m, mm(0, 0, 0));
  expect_point(arc.end_m, mm(0, -10, 0));
  expect_point(arc.normal, Eigen::Vector3d::UnitZ());
  EXPECT_NEAR(arc.sweep_rad, -kPi / 2, 1e-12);
}

TEST(GcodeReader, AbsoluteCentresWithG901) {
  const Program p = read("G21 G0 X10 Y0 Z0\nG90.1 G3 X0 Y10 I0 J0 F100\n");
  expect_point(p.moves[1].centre_m, mm(0, 0, 0));
  EXPECT_NEAR(p.moves[1].sweep_rad, kPi / 2, 1e-12);
}

TEST(GcodeReader, FullCircleAndHelixWithTurns) {
  // Start = end in the plane: one full turn; P3 = three turns while Z falls
  // by 6 mm.
  const Program p = read("G21 G0 X5 Y0 Z0\nG3 X5 Y0 I-5 J0 F100\nG3 X5 Y0 Z-6 I-5 J0 P3\nG2 I-5\n");
  ASSERT_EQ(p.moves.size(), 4u);
  EXPECT_NEAR(p.moves[1].sweep_rad, 2 * kPi, 1e-12);
  EXPECT_NEAR(p.moves[2].sweep_rad, 6 * kPi, 1e-12);
  expect_point(p.moves[2].end_m, mm(5, 0, -6));
  EXPECT_NEAR(p.moves[3].sweep_rad, -2 * kPi, 1e-12);  // G2 I-5 alone: a full circle
  // The helix is 3 turns of a 5 mm circle climbing 6 mm.
  EXPECT_NEAR(robomill::toolpath::path_length_m(p.moves[2]), std::hypot(6 * kPi * 5e-3, 6e-3),
              1e-12);
}

TEST(GcodeReader, RadiusArcsTakeTheShortOrTheLongWay) {
  // Chord 10 mm, R 10 mm: the short way sweeps 2·asin(5/10) = 60°, the long
  // way (R negative) 300°.
  // (The first G0 moves nothing from the start at the origin: no move.)
  const Program p = read("G21 G0 X0 Y0 Z0\nG3 X10 Y0 R10 F100\nG3 X0 Y0 R-10\n");
  ASSERT_EQ(p.moves.size(), 2u);
  EXPECT_NEAR(p.moves[0].sweep_rad, kPi / 3, 1e-9);
  EXPECT_NEAR(p.moves[1].sweep_rad, 5 * kPi / 3, 1e-9);
  // Counter-clockwise along +X the short way: the centre is on the left, +Y.
  expect_point(p.moves[0].centre_m, mm(5, 10 * std::sqrt(0.75), 0), 1e-12);
}

TEST(GcodeReader, PlanesG18AndG19TurnAboutYAndX) {
  const Program xz = read("G21 G0 X0 Y0 Z0\nG18 G2 X10 Z0 I5 K0 F100\n");
  ASSERT_EQ(xz.moves.size(), 1u);
  expect_point(xz.moves[0].normal, Eigen::Vector3d::UnitY());
  EXPECT_NEAR(xz.moves[0].sweep_rad, -kPi, 1e-12);
  // Counter-clockwise about +Y turns Z towards X; clockwise from the −X side
  // of the centre (5,0,0) therefore passes below it, at Z = −5 mm.
  expect_point(robomill::toolpath::position_at(xz.moves[0], 0.5), mm(5, 0, -5), 1e-12);
  const Program yz = read("G21 G0 X0 Y0 Z0\nG19 G3 Y10 Z0 J5 K0 F100\n");
  ASSERT_EQ(yz.moves.size(), 1u);
  expect_point(yz.moves[0].normal, Eigen::Vector3d::UnitX());
  EXPECT_NEAR(yz.moves[0].sweep_rad, kPi, 1e-12);
  // Counter-clockwise about +X turns Y towards Z; from the −Y side of (0,5,0)
  // it passes below, at Z = −5 mm.
  expect_point(robomill::toolpath::position_at(yz.moves[0], 0.5), mm(0, 5, -5), 1e-12);
}

TEST(GcodeReader, ArcWhoseEndIsOffTheCircleNamesBothRadii) {
  const InputError error = refusal("G21 G0 X0 Y0 Z0\nG2 X10 Y0 I4 J0 F100\n");
  EXPECT_EQ(error.line(), 2);
  const std::string what = error.what();
  EXPECT_NE(what.find("G2"), std::string::npos) << what;
  EXPECT_NE(what.find("radius 4 mm at the start and 6 mm at the end"), std::string::npos) << what;
}

// ------------------------------------------------------------ cycles ------

TEST(GcodeReader, G81WithG98ReturnsToTheInitialHeight) {
  const Program p = read("G21 G0 X0 Y0 Z10\nG98 G81 X5 Y5 Z-3 R2 F120\nX15\nG80\n");
  // Hole 1: rapid XY at Z10, rapid to R2, feed to −3, rapid to 10; hole 2 the
  // same at X15.
  const std::vector<std::pair<MotionKind, Eigen::Vector3d>> expected{
      {MotionKind::rapid, mm(0, 0, 10)}, {MotionKind::rapid, mm(5, 5, 10)},
      {MotionKind::rapid, mm(5, 5, 2)},  {MotionKind::linear, mm(5, 5, -3)},
      {MotionKind::rapid, mm(5, 5, 10)}, {MotionKind::rapid, mm(15, 5, 10)},
      {MotionKind::rapid, mm(15, 5, 2)}, {MotionKind::linear, mm(15, 5, -3)},
      {MotionKind::rapid, mm(15, 5, 10)}};
  ASSERT_EQ(p.moves.size(), expected.size());
  for (std::size_t n = 0; n < expected.size(); ++n) {
    EXPECT_EQ(p.moves[n].kind, expected[n].first) << n;
    expect_point(p.moves[n].end_m, expected[n].second);
  }
  EXPECT_EQ(p.moves[4].line, 2);
  EXPECT_EQ(p.moves[5].line, 3);
  EXPECT_NEAR(p.moves[3].feed_m_s, 0.002, kTol);
}

TEST(GcodeReader, G83PecksRetractToRAndComeBackAboveTheLastDepth) {
  // R1, Z-7, Q3: pecks to −2, −5, then the bottom −7; between pecks a rapid
  // to R and back down to 0.254 mm above the last depth; G99 ends at R.
  const Program p = read("G21 G0 X0 Y0 Z5\nG99 G83 Z-7 R1 Q3 F100\n");
  const std::vector<double> z_mm{5, 1, -2, 1, -2 + 0.254, -5, 1, -5 + 0.254, -7, 1};
  ASSERT_EQ(p.moves.size(), z_mm.size());
  for (std::size_t n = 0; n < z_mm.size(); ++n)
    EXPECT_NEAR(p.moves[n].end_m.z(), z_mm[n] * 1e-3, 1e-12) << n;
  EXPECT_EQ(p.moves[2].kind, MotionKind::linear);
  EXPECT_EQ(p.moves[3].kind, MotionKind::rapid);
}

TEST(GcodeReader, G82DwellsAtTheBottom) {
  const Program p = read("G21 G0 X0 Y0 Z5\nG98 G82 Z-2 R1 P0.4 F100\n");
  ASSERT_EQ(p.moves.size(), 5u);  // Z5 rapid, R, feed, dwell, retract
  EXPECT_EQ(p.moves[3].kind, MotionKind::dwell);
  EXPECT_DOUBLE_EQ(p.moves[3].dwell_s, 0.4);
  expect_point(p.moves[3].end_m, mm(0, 0, -2));
  expect_point(p.moves[4].end_m, mm(0, 0, 5));
}

TEST(GcodeReader, CycleWithoutRetractModeNotesG98) {
  const Program p = read("G21 G0 X0 Y0 Z5\nG81 Z-2 R1 F100\n");
  EXPECT_TRUE(has_note(p, 2, "G98"));
  expect_point(p.moves.back().end_m, mm(0, 0, 5));
}

// ------------------------------------------------------------- modal ------

TEST(GcodeReader, AxisWordsContinueTheModalMotion) {
  const Program p = read("G21 G0 X0 Y0 Z1\nG1 X10 F100\nY10\nG0 Z5\nX0\n");
  ASSERT_EQ(p.moves.size(), 5u);
  EXPECT_EQ(p.moves[2].kind, MotionKind::linear);
  expect_point(p.moves[2].end_m, mm(10, 10, 1));
  EXPECT_EQ(p.moves[4].kind, MotionKind::rapid);
  EXPECT_EQ(p.moves[2].line, 3);
}

TEST(GcodeReader, AxisWordsWithoutAMotionModeAreRefused) {
  const InputError start = refusal("G21\nX10\n");
  EXPECT_EQ(start.line(), 2);
  EXPECT_NE(std::string(start.what()).find("X10: no motion mode"), std::string::npos);
  const InputError after_g80 = refusal("G21 G0 X0 Y0 Z5\nG98 G81 Z-1 R1 F50\nG80\nX10\n");
  EXPECT_EQ(after_g80.line(), 4);
}

TEST(GcodeReader, IncrementalSection) {
  const Program p = read("G21 G90 G0 X10 Y10 Z0\nG91 G1 X5 F100\nY-3\nG90 X0\n");
  expect_point(p.moves[1].end_m, mm(15, 10, 0));
  expect_point(p.moves[2].end_m, mm(15, 7, 0));
  expect_point(p.moves[3].end_m, mm(0, 7, 0));
}

TEST(GcodeReader, FanucPreambleWithG0AndG80IsAccepted) {
  const Program p = read("N100 G21\nN102 G0 G17 G40 G49 G80 G90\nN104 X1 Y2 Z3\n");
  ASSERT_EQ(p.moves.size(), 1u);
  EXPECT_EQ(p.moves[0].kind, MotionKind::rapid);
  EXPECT_EQ(p.moves[0].line, 3);
}

TEST(GcodeReader, TwoCodesOfOneModalGroupAreRefused) {
  const InputError error = refusal("G21\nG0 G1 X10 F100\n");
  EXPECT_EQ(error.line(), 2);
  EXPECT_NE(std::string(error.what()).find("G0 and G1"), std::string::npos);
  EXPECT_EQ(refusal("G20 G21\n").line(), 1);
  EXPECT_EQ(refusal("G21 G0 X0\nG1 X1 X2 F1\n").line(), 2);  // a word twice
}

TEST(GcodeReader, WorkOffsetsShiftIntoTheProgramFrame) {
  GcodeOptions options;
  options.work_offsets_m[2] = mm(100, 50, -10);
  const Program p = read("G21 G54 G0 X1 Y1 Z1\nG55 G0 X1 Y1 Z1\nG56 G0 X1 Y1 Z1\n", options);
  expect_point(p.moves[0].end_m, mm(1, 1, 1));
  expect_point(p.moves[1].end_m, mm(101, 51, -9));
  expect_point(p.moves[2].end_m, mm(1, 1, 1));  // G56 not given: zero, with a note
  EXPECT_TRUE(has_note(p, 3, "G56"));
}

TEST(GcodeReader, ToolChangesAndToolCalls) {
  const Program p =
      read("G21\nT1 M6\nT2\nG0 X0 Y0 Z1\nG0 X1\nT2 M6\nG0 X2\nT7 (PRESELECT)\nG0 X3\n");
  ASSERT_EQ(p.tool_calls.size(), 2u);
  EXPECT_EQ(p.tool_calls[0].tool, 1);
  EXPECT_EQ(p.tool_calls[0].line, 2);
  EXPECT_EQ(p.tool_calls[1].tool, 2);
  EXPECT_EQ(p.tool_calls[1].line, 6);
  EXPECT_EQ(p.moves[0].tool, 1);  // T2 is only selected until M6
  EXPECT_EQ(p.moves[2].tool, 2);
  EXPECT_EQ(p.moves[3].tool, 2);  // T7 selected, never loaded
}

TEST(GcodeReader, DwellInSeconds) {
  const Program p = read("G21 G0 X1 Y2 Z3\nG4 P0.5\n");
  ASSERT_EQ(p.moves.size(), 2u);
  EXPECT_EQ(p.moves[1].kind, MotionKind::dwell);
  EXPECT_DOUBLE_EQ(p.moves[1].dwell_s, 0.5);
  expect_point(p.moves[1].start_m, mm(1, 2, 3));
  // An integer P of 10 or more is probably Fanuc milliseconds: a note.
  EXPECT_TRUE(has_note(read("G21\nG4 P500\n"), 2, "milliseconds"));
}

// --------------------------------------------------------- the text -------

TEST(GcodeReader, CommentsLowerCaseSpacesCrlfAndNumberForms) {
  const std::string text =
      "%\r\nO1234 (NAME)\r\n; comment\r\n(G1 X99)\r\ng21 g90\r\nG 0 X 1 0 (mid) Y+1 Z.5\r\n"
      "g1 x-.5 y10. f 1 2 0 ; trailing\r\nN50 X+2\r\n%\r\n";
  const Program p = read(text);
  ASSERT_EQ(p.moves.size(), 3u);
  expect_point(p.moves[0].end_m, mm(10, 1, 0.5));
  expect_point(p.moves[1].end_m, mm(-0.5, 10, 0.5));
  expect_point(p.moves[2].end_m, mm(2, 10, 0.5));
  EXPECT_EQ(p.moves[0].line, 6);
  EXPECT_EQ(p.moves[2].line, 8);
  EXPECT_NEAR(p.moves[1].feed_m_s, 0.002, kTol);
  EXPECT_EQ(p.line_count, 9u);
}

TEST(GcodeReader, EndOfProgramStopsReadingWithANote) {
  const Program p = read("G21 G0 X0 Y0 Z1\nM30\nG1 X1000\n@@@ not g-code\n");
  EXPECT_EQ(p.moves.size(), 1u);
  EXPECT_TRUE(has_note(p, 2, "line 3"));
}

TEST(GcodeReader, BlockDeleteExecutesTheBlockWithANote) {
  const Program p = read("G21 G0 X0 Y0 Z1\n/G0 X5\n");
  ASSERT_EQ(p.moves.size(), 2u);
  EXPECT_TRUE(has_note(p, 2, "block delete"));
}

TEST(GcodeReader, NotesForStopsUnitsAndToolLength) {
  const Program p = read("G0 X0 Y0 Z0\nM0\nG43 H1 Z5\n");
  EXPECT_TRUE(has_note(p, 1, "millimetres assumed"));
  EXPECT_TRUE(has_note(p, 2, "M0"));
  EXPECT_TRUE(has_note(p, 3, "tool tip"));
}

TEST(GcodeReader, HomeReturnIsARapidToHomeZWhenKnown) {
  const std::string text = "G21 G0 X10 Y10 Z5\nG28 G91 Z0.\nG90\nG53 G0 Z0.\n";
  GcodeOptions options;
  options.home_z_m = 0.4;
  const Program known = read(text, options);
  ASSERT_EQ(known.moves.size(), 2u);
  EXPECT_EQ(known.moves[1].kind, MotionKind::rapid);
  expect_point(known.moves[1].end_m, {0.010, 0.010, 0.4});
  const Program unknown = read(text);
  EXPECT_EQ(unknown.moves.size(), 1u);
  EXPECT_TRUE(has_note(unknown, 2, "home Z is not known"));
  EXPECT_TRUE(has_note(unknown, 4, "home Z is not known"));
  EXPECT_EQ(refusal("G21 G0 X0\nG53 G0 Z-50.\n").line(), 2);
}

TEST(GcodeReader, HaasSmoothingAndLookAheadAreNotedNoOps) {
  // G187 (P level and/or E tolerance) and G103 change how the machine follows
  // the path, not the path: the moves are those of the program without them.
  const std::string plain = "G21 G90 G94\nG0 X0 Y0 Z5\nG1 Z-1 F300\nG1 X10 Y5\nM30\n";
  const Program expected = read(plain);
  const Program p = read(
      "G21 G90 G94\nG187 P2\nG0 X0 Y0 Z5\nG187 E0.01\nG1 Z-1 F300\nG103 P1\n"
      "G187 P1 E.005 X10 Y5\nG187\nM30\n");
  ASSERT_EQ(p.moves.size(), expected.moves.size());
  for (std::size_t n = 0; n < p.moves.size(); ++n) {
    expect_point(p.moves[n].end_m, expected.moves[n].end_m);
    EXPECT_EQ(p.moves[n].kind, expected.moves[n].kind);
    EXPECT_NEAR(p.moves[n].feed_m_s, expected.moves[n].feed_m_s, kTol);
  }
  EXPECT_EQ(p.moves[2].line, 7);  // the axis words beside G187 still move (modal G1)
  EXPECT_TRUE(has_note(p, 2, "G187: machine smoothing"));
  EXPECT_TRUE(has_note(p, 6, "G103: look-ahead limit"));

  // E belongs to G187 only; P and E are checked; P is not shared with G4.
  EXPECT_NE(std::string(refusal("G21 G0 X0\nG1 X1 E5 F1\n").what()).find("E5: unknown word"),
            std::string::npos);
  EXPECT_EQ(refusal("G21\nG187 P4\n").line(), 2);
  EXPECT_EQ(refusal("G21\nG187 E-1\n").line(), 2);
  EXPECT_EQ(refusal("G21\nG103 P16\n").line(), 2);
  EXPECT_NE(std::string(refusal("G21\nG4 G187 P2\n").what()).find("G187 with P2"),
            std::string::npos);
  EXPECT_EQ(refusal("G21\nG187 G103 P1\n").line(), 2);
}

TEST(GcodeReader, CancelsOfRefusedModesAreNoOps) {
  const Program p = read("G21 G90 G92.1 G69 G50 G15\nG92.2\nG0 X1 Y2 Z3\nM30\n");
  ASSERT_EQ(p.moves.size(), 1u);
  expect_point(p.moves[0].end_m, mm(1, 2, 3));
  EXPECT_EQ(refusal("G21\nG92.3\n").line(), 2);  // restores unknown G92 offsets
  EXPECT_EQ(refusal("G21\nG92 X0\n").line(), 2);
  // G97 S8000 M3, as Fanuc-style mill posts write it: S is rpm either way; G96
  // (constant surface speed) is not modelled.
  const Program rpm = read("G21 G90 G94\nG97 S8000 M3\nG0 X0 Y0 Z5\nG1 Z0 F300\nM30\n");
  ASSERT_EQ(rpm.moves.size(), 2u);
  EXPECT_NEAR(rpm.moves[1].spindle_rad_s, 8000.0 * 2.0 * std::numbers::pi / 60.0, 1e-9);
  EXPECT_EQ(refusal("G21\nG96 S200 M3\n").line(), 2);
}

TEST(GcodeReader, PolarWordsAreRefusedByName) {
  const InputError error = refusal("G20 G90\nG0 X1.5 Y0 Z0\nG91 G81 R.1 Z-.5 ^60 L6 F10\n");
  EXPECT_EQ(error.line(), 3);
  EXPECT_NE(std::string(error.what()).find("^60: polar coordinates"), std::string::npos)
      << error.what();
  EXPECT_NE(std::string(refusal("G21 G0 X0\nG0 @1\n").what()).find("@1: polar"), std::string::npos);
  EXPECT_NE(std::string(refusal("G21 G0 X0 $1\n").what()).find("'$': unexpected character"),
            std::string::npos);
}

// --------------------------------------------------------- refusals -------

struct BadProgram {
  const char* file;
  int line;
  const char* word;
};

class GcodeRefusal : public ::testing::TestWithParam<BadProgram> {};

TEST_P(GcodeRefusal, NamesTheLineAndTheWord) {
  const BadProgram bad = GetParam();
  const auto path =
      std::filesystem::path(ROBOMILL_SOURCE_DIR) / "tests/toolpath/gcode/bad" / bad.file;
  std::ifstream in(path, std::ios::binary);
  ASSERT_TRUE(in) << path;
  std::stringstream text;
  text << in.rdbuf();
  const InputError error = refusal(text.str(), bad.file);
  EXPECT_EQ(error.field(), bad.file);
  EXPECT_EQ(error.line(), bad.line) << error.what();
  EXPECT_NE(std::string(error.what()).find(bad.word), std::string::npos) << error.what();
}

INSTANTIATE_TEST_SUITE_P(
    Bad, GcodeRefusal,
    ::testing::Values(BadProgram{"g41_cutter_comp.nc", 6, "G41: cutter compensation"},
                      BadProgram{"m98_subprogram.nc", 5, "M98: subprogram"},
                      BadProgram{"variable.nc", 4, "#1=5: parameters"},
                      BadProgram{"arc_radius_mismatch.nc", 4, "radius 4 mm at the start and 6"},
                      BadProgram{"g1_without_f.nc", 5, "G1 without a feed rate"},
                      BadProgram{"q_only.nc", 3, "Q5.: no code"},
                      BadProgram{"g12_1_polar.nc", 3, "G12.1: unknown G code"},
                      BadProgram{"e_word.nc", 3, "E5.: unknown word"},
                      BadProgram{"a_axis.nc", 4, "A90.: rotary"},
                      BadProgram{"g93_inverse_time.nc", 2, "G93: inverse-time"}),
    [](const ::testing::TestParamInfo<BadProgram>& info) {
      std::string name = info.param.file;
      for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c)))
          c = '_';
      return name;
    });

TEST(GcodeReader, MoreRefusals) {
  EXPECT_EQ(refusal("G21\nO100 sub\n").line(), 2);
  EXPECT_EQ(refusal("G21 G0 X0\nG65 P9010\n").line(), 2);
  EXPECT_EQ(refusal("G21 G0 X0\nG1 X[1+2] F1\n").line(), 2);
  EXPECT_EQ(refusal("G21 G0 X0 (unclosed\n").line(), 1);
  EXPECT_EQ(refusal("G21 G0 X\n").line(), 1);
  EXPECT_EQ(refusal("G21 G0 X1.2.3\n").line(), 1);
  EXPECT_EQ(refusal("G21 G0 X1e5\n").line(), 1);                       // E is not an exponent here
  EXPECT_EQ(refusal("G21 G0 X0 Y0 Z0\nG2 X10 Y0 R2 F1\n").line(), 2);  // R below half chord
  EXPECT_EQ(refusal("G21 G0 X0 Y0 Z0\nG2 X0 Y0 R2 F1\n").line(), 2);   // R full circle
  EXPECT_EQ(refusal("G21 G0 X0 Y0 Z5\nG81 X1 Z-1 F10\n").line(), 2);   // no R
  EXPECT_EQ(refusal("G21 G0 X0 Y0 Z5\nG83 Z-1000 R0 Q0.001 F10\n").line(), 2);  // too many
  EXPECT_EQ(refusal("G21 G0 X0 Y0 Z5\nG81 Z-1 R1 L1000000 F10\n").line(), 2);
  EXPECT_EQ(refusal("G21 G0 X0 Y0 Z5\nG42 X1\n").line(), 2);
  EXPECT_EQ(refusal("G21 G0 X0 Y0 Z5\nG92 X0\n").line(), 2);
  EXPECT_EQ(refusal("G21 G0 X0 Y0 Z5\nM99\n").line(), 2);
}

// ---------------------------------------------------------- limits --------

TEST(GcodeReader, ReadsAMegabyteProgram) {
  std::string text = "G21 G90 G94\nG0 X0 Y0 Z0\nG1 F1000\n";
  int lines = 0;
  while (text.size() < (1u << 20)) {
    ++lines;
    text += fmt::format("X{}.125 Y{}\n", lines % 100, lines % 37);
  }
  const Program p = read(text);
  EXPECT_EQ(p.moves.size(), static_cast<std::size_t>(lines));
  EXPECT_EQ(p.moves.back().line, lines + 3);
}

TEST(GcodeReader, RefusesProgramsAboveMaxBytes) {
  GcodeOptions options;
  options.max_bytes = 100;
  const std::string text(101, '\n');
  try {
    read_gcode(text, options);
    FAIL() << "no refusal";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("101 bytes"), std::string::npos);
  }
  EXPECT_NO_THROW(read_gcode(std::string(100, '\n'), options));
}

}  // namespace

}  // namespace test_gcode_reader_cpp
