// APT / CL reader: every expected value below is worked out by hand from the
// program text (units, frames, arc senses), not copied from the reader's output.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>

#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/toolpath/program.hpp"

namespace test_apt_reader_cpp {

namespace {

using Eigen::Vector3d;
using robomill::InputError;
using robomill::io::AptOptions;
using robomill::io::read_apt;
using robomill::toolpath::MotionKind;
using robomill::toolpath::Program;

constexpr double kPi = std::numbers::pi;

Program apt(const std::string& text, std::optional<AptOptions::Unit> units = std::nullopt) {
  AptOptions options;
  options.source_name = "test.cl";
  options.units = units;
  return read_apt(text, options);
}

std::string corpus(const std::string& name) {
  std::ifstream file(std::string(ROBOMILL_SOURCE_DIR) + "/tests/toolpath/apt/" + name);
  EXPECT_TRUE(file.good()) << name;
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// The InputError a program raises (fails the test if none).
InputError error_of(const std::string& text, std::optional<AptOptions::Unit> units = std::nullopt) {
  try {
    apt(text, units);
  } catch (const InputError& error) {
    return error;
  }
  ADD_FAILURE() << "no InputError for:\n" << text;
  return InputError("", 0, "");
}

void expect_near(const Vector3d& actual, const Vector3d& expected, double tolerance = 1e-12) {
  EXPECT_LE((actual - expected).norm(), tolerance)
      << "actual " << actual.transpose() << " expected " << expected.transpose();
}

bool has_note(const Program& program, const std::string& part) {
  for (const auto& note : program.notes)
    if (note.text.find(part) != std::string::npos)
      return true;
  return false;
}

// The line of the note containing `part` (-1: none).
int note_line(const Program& program, const std::string& part) {
  for (const auto& note : program.notes)
    if (note.text.find(part) != std::string::npos)
      return note.line;
  return -1;
}

struct Box {
  Vector3d min = Vector3d::Constant(1e300), max = Vector3d::Constant(-1e300);
};

// The box of every move's end points and the first move's start (m).
Box end_point_box(const Program& p) {
  Box box;
  if (p.moves.empty())
    return box;
  box.min = box.max = p.moves.front().start_m;
  for (const auto& move : p.moves) {
    box.min = box.min.cwiseMin(move.end_m);
    box.max = box.max.cwiseMax(move.end_m);
  }
  return box;
}

std::size_t count_kind(const Program& p, MotionKind kind) {
  std::size_t n = 0;
  for (const auto& move : p.moves)
    n += move.kind == kind;
  return n;
}

TEST(AptReader, MillimetresWithoutUnitsRecordAreNoted) {
  const Program p = apt("FROM/0,0,0\nGOTO/1,2,3\n");
  ASSERT_EQ(p.moves.size(), 1u);
  EXPECT_EQ(p.dialect, "apt");
  expect_near(p.moves[0].end_m, Vector3d(1e-3, 2e-3, 3e-3));
  EXPECT_TRUE(has_note(p, "no UNITS record"));
}

TEST(AptReader, InchesConvertOnceWhenRead) {
  const Program p = apt("UNITS / INCHES\nFROM/0,0,0\nGOTO/1,2,-0.5\nUNITS/MM\nGOTO/10,0,0\n");
  ASSERT_EQ(p.moves.size(), 2u);
  expect_near(p.moves[0].end_m, Vector3d(0.0254, 0.0508, -0.0127));
  expect_near(p.moves[1].start_m, Vector3d(0.0254, 0.0508, -0.0127));
  expect_near(p.moves[1].end_m, Vector3d(0.010, 0.0, 0.0));
  EXPECT_FALSE(has_note(p, "no UNITS record"));
  EXPECT_EQ(apt("UNIT/MM\nFROM/0,0,0\nGOTO/5,0,0\n").moves[0].end_m.x(), 5e-3);
  EXPECT_NEAR(apt("UNITS/INCH\nFROM/0,0,0\nGOTO/2,0,0\n").moves[0].end_m.x(), 0.0508, 1e-15);
}

TEST(AptReader, DollarContinuesARecordAndDoubleDollarIsAComment) {
  const Program p =
      apt("UNITS/MM $$ metric\n"
          "FROM/0,0,0\n"
          "GOTO  /  1.5 ,$\n"
          "   2.5,$   $$ y on this line\n"
          "   -3.5\n"
          "GOTO/4,5,6\n");
  ASSERT_EQ(p.moves.size(), 2u);
  expect_near(p.moves[0].end_m, Vector3d(1.5e-3, 2.5e-3, -3.5e-3));
  EXPECT_EQ(p.moves[0].line, 3);  // the record's first line
  EXPECT_EQ(p.moves[1].line, 6);
}

TEST(AptReader, ToolAxisIsModalAndNormalised) {
  const Program p =
      apt("UNITS/MM\nMULTAX\nFROM/0,0,0\n"
          "GOTO/10,0,0,0,3,4\n"  // axis (0, 0.6, 0.8)
          "GOTO/20,0,0\n"        // keeps it
          "TLAXIS/2,0,0\n"
          "GOTO/30,0,0\n");
  ASSERT_EQ(p.moves.size(), 3u);
  expect_near(p.moves[0].axis_start, Vector3d::UnitZ());
  expect_near(p.moves[0].axis_end, Vector3d(0, 0.6, 0.8));
  expect_near(p.moves[1].axis_start, Vector3d(0, 0.6, 0.8));
  expect_near(p.moves[1].axis_end, Vector3d(0, 0.6, 0.8));
  expect_near(p.moves[2].axis_end, Vector3d::UnitX());
}

TEST(AptReader, FeedForms) {
  auto feed = [](const std::string& head) {
    const Program p = apt(head + "\nFROM/0,0,0\nGOTO/1,0,0\n");
    return p.moves.at(0).feed_m_s;
  };
  EXPECT_NEAR(feed("UNITS/MM\nFEDRAT/MMPM,250"), 250e-3 / 60.0, 1e-15);
  EXPECT_NEAR(feed("UNITS/MM\nFEDRAT/742.7,MMPM"), 742.7e-3 / 60.0, 1e-15);
  EXPECT_NEAR(feed("UNITS/MM\nFEDRAT/ 250.0000,MMPM"), 250e-3 / 60.0, 1e-15);
  EXPECT_NEAR(feed("UNITS/MM\nFEDRAT/250"), 250e-3 / 60.0, 1e-15);          // the file's unit
  EXPECT_NEAR(feed("UNITS/INCHES\nFEDRAT/20"), 20 * 0.0254 / 60.0, 1e-15);  // inches per minute
  EXPECT_NEAR(feed("UNITS/MM\nFEDRAT/IPM,10"), 10 * 0.0254 / 60.0, 1e-15);
  // 0.1 mm per revolution at 1200 rpm = 120 mm/min = 2 mm/s.
  EXPECT_NEAR(feed("UNITS/MM\nSPINDL/RPM,1200,CLW\nFEDRAT/MMPR,0.1"), 2e-3, 1e-15);
  // 0.004 in per revolution at 1500 rpm = 6 in/min.
  EXPECT_NEAR(feed("UNITS/MM\nSPINDL/1500\nFEDRAT/0.004,IPR"), 6 * 0.0254 / 60, 1e-15);
}

TEST(AptReader, FeedPerRevolutionFollowsTheSpindleAndNeedsOne) {
  const Program p =
      apt("UNITS/MM\nFEDRAT/MMPR,0.2\nSPINDL/RPM,600\nFROM/0,0,0\nGOTO/1,0,0\nSPINDL/1200\nGOTO/"
          "2,0,0\n");
  EXPECT_NEAR(p.moves[0].feed_m_s, 0.2e-3 * 10, 1e-15);  // 600 rpm = 10 rev/s
  EXPECT_NEAR(p.moves[1].feed_m_s, 0.2e-3 * 20, 1e-15);
  const InputError e = error_of("UNITS/MM\nFEDRAT/MMPR,0.2\nFROM/0,0,0\nGOTO/1,0,0\n");
  EXPECT_EQ(e.line(), 4);
  EXPECT_NE(std::string(e.what()).find("MMPR"), std::string::npos);
  EXPECT_NE(std::string(e.what()).find("SPINDL"), std::string::npos);
}

TEST(AptReader, SpindleForms) {
  auto spindle = [](const std::string& word) {
    return apt("UNITS/MM\n" + word + "\nFROM/0,0,0\nGOTO/1,0,0\n").moves.at(0).spindle_rad_s;
  };
  const double rad_s_1200 = 1200 * 2 * kPi / 60;  // 125.66 rad/s
  EXPECT_NEAR(spindle("SPINDL/RPM,1200,CLW"), rad_s_1200, 1e-12);
  EXPECT_NEAR(spindle("SPINDL/1200"), rad_s_1200, 1e-12);
  EXPECT_NEAR(spindle("SPINDL/1200,RPM,CCW"), -rad_s_1200, 1e-12);
  EXPECT_EQ(spindle("SPINDL/1200\nSPINDL/OFF"), 0.0);
  EXPECT_NEAR(spindle("SPINDL/1200\nSPINDL/OFF\nSPINDL/ON"), rad_s_1200, 1e-12);
}

TEST(AptReader, RapidAppliesToTheNextGotoOnly) {
  const Program p =
      apt("UNITS/MM\nFEDRAT/100\nFROM/0,0,0\nRAPID\nGOTO/0,0,10\nGOTO/0,0,5\nRAPID/\n"
          "GOTO/1,0,5\n");
  ASSERT_EQ(p.moves.size(), 3u);
  EXPECT_EQ(p.moves[0].kind, MotionKind::rapid);
  EXPECT_EQ(p.moves[0].feed_m_s, 0.0);
  EXPECT_EQ(p.moves[1].kind, MotionKind::linear);
  EXPECT_NEAR(p.moves[1].feed_m_s, 100e-3 / 60, 1e-15);
  EXPECT_EQ(p.moves[2].kind, MotionKind::rapid);
}

TEST(AptReader, FromSetsTheStartWithoutAMove) {
  const Program p = apt("UNITS/MM\nFROM/5,6,7,1,0,0\nGOTO/5,6,0\n");
  ASSERT_EQ(p.moves.size(), 1u);
  expect_near(p.moves[0].start_m, Vector3d(5e-3, 6e-3, 7e-3));
  expect_near(p.moves[0].axis_start, Vector3d::UnitX());
  expect_near(p.moves[0].axis_end, Vector3d::UnitX());
}

TEST(AptReader, CatiaCutterBeforeLoadtlIsOneToolCall) {
  const Program p = apt(corpus("catia_multax.aptsource"));
  ASSERT_EQ(p.tool_calls.size(), 1u);
  EXPECT_EQ(p.tool_calls[0].tool, 1);
  EXPECT_NEAR(*p.tool_calls[0].diameter_m, 0.012, 1e-15);
  EXPECT_NEAR(*p.tool_calls[0].corner_radius_m, 0.002, 1e-15);
  // First point (0,0,100) is the start; then 5 moves.
  ASSERT_EQ(p.moves.size(), 5u);
  EXPECT_EQ(p.moves[0].kind, MotionKind::linear);
  EXPECT_NEAR(p.moves[0].feed_m_s, 742.7e-3 / 60, 1e-15);
  EXPECT_NEAR(p.moves[2].feed_m_s, 1000e-3 / 60, 1e-15);
  EXPECT_EQ(p.moves[4].kind, MotionKind::rapid);
  expect_near(p.moves[4].end_m, Vector3d(0, 0.010, 0.100));
  for (const auto& move : p.moves) {
    EXPECT_EQ(move.tool, 1);
    EXPECT_NEAR(move.spindle_rad_s, 1200 * 2 * kPi / 60, 1e-12);
  }
}

TEST(AptReader, LoadThenCutterAndTheSevenParameterForm) {
  const Program p =
      apt("UNITS/MM\nLOAD/TOOL,2,ADJUST,2\nCUTTER/6,3\nLOADTL/7\nCUTTER/20,0.8,9.2,0.8,0,0,40\n"
          "TOOLNO/9\n");
  ASSERT_EQ(p.tool_calls.size(), 3u);
  EXPECT_EQ(p.tool_calls[0].tool, 2);
  EXPECT_NEAR(*p.tool_calls[0].diameter_m, 6e-3, 1e-15);
  EXPECT_NEAR(*p.tool_calls[0].corner_radius_m, 3e-3, 1e-15);
  EXPECT_EQ(p.tool_calls[1].tool, 7);
  EXPECT_NEAR(*p.tool_calls[1].diameter_m, 20e-3, 1e-15);
  EXPECT_NEAR(*p.tool_calls[1].corner_radius_m, 0.8e-3, 1e-15);
  EXPECT_EQ(p.tool_calls[2].tool, 9);
  EXPECT_FALSE(p.tool_calls[2].diameter_m.has_value());
}

TEST(AptReader, SelctlOnlyPreselects) {
  const Program p = apt("UNITS/MM\nLOADTL/1\nSELCTL/2\nFROM/0,0,0\nGOTO/1,0,0\n");
  EXPECT_EQ(p.moves[0].tool, 1);
  EXPECT_TRUE(has_note(p, "SELCTL"));
}

TEST(AptReader, CircleIsCounterClockwiseAboutItsAxis) {
  // From (10,0,0) to (0,10,0) about the origin. Axis +Z: the quarter through
  // (7.07, 7.07). Axis −Z: clockwise seen from +Z, three quarters through (0,−10).
  const Program ccw =
      apt("UNITS/MM\nFEDRAT/100\nFROM/10,0,0\nCIRCLE/0,0,0,0,0,1,10\nGOTO/0,10,0\n");
  ASSERT_EQ(ccw.moves.size(), 1u);
  const auto& a = ccw.moves[0];
  EXPECT_EQ(a.kind, MotionKind::arc);
  EXPECT_NEAR(a.sweep_rad, kPi / 2, 1e-12);
  expect_near(a.centre_m, Vector3d::Zero());
  expect_near(robomill::toolpath::position_at(a, 0.5),
              Vector3d(10e-3 / std::sqrt(2.0), 10e-3 / std::sqrt(2.0), 0), 1e-12);
  EXPECT_NEAR(robomill::toolpath::path_length_m(a), 10e-3 * kPi / 2, 1e-14);

  const Program cw =
      apt("UNITS/MM\nFEDRAT/100\nFROM/10,0,0\nCIRCLE/0,0,0,0,0,-1,10\nGOTO/0,10,0\n");
  const auto& b = cw.moves[0];
  expect_near(b.normal, -Vector3d::UnitZ());
  EXPECT_NEAR(std::abs(b.sweep_rad), 3 * kPi / 2, 1e-12);
  expect_near(robomill::toolpath::position_at(b, 1.0 / 3.0), Vector3d(0, -10e-3, 0), 1e-12);
}

TEST(AptReader, CircleToADifferentHeightIsAHelix) {
  // A full turn down by 3 mm: start = end in the plane.
  const Program p = apt("UNITS/MM\nFEDRAT/100\nFROM/10,0,0\nCIRCLE/0,0,0,0,0,1,10\nGOTO/10,0,-3\n");
  const auto& h = p.moves.at(0);
  EXPECT_NEAR(h.sweep_rad, 2 * kPi, 1e-12);
  expect_near(robomill::toolpath::position_at(h, 0.5), Vector3d(-10e-3, 0, -1.5e-3), 1e-12);
  EXPECT_NEAR(robomill::toolpath::path_length_m(h), std::hypot(2 * kPi * 10e-3, 3e-3), 1e-14);
}

TEST(AptReader, CircleWhoseRadiusDisagreesIsRefusedAtTheGoto) {
  const InputError e = error_of("UNITS/MM\nFROM/10,0,0\nCIRCLE/0,0,0,0,0,1,10\nGOTO/0,12,0\n");
  EXPECT_EQ(e.line(), 4);
  EXPECT_NE(std::string(e.what()).find("CIRCLE of line 3"), std::string::npos);
  EXPECT_EQ(error_of("UNITS/MM\nFROM/9,0,0\nCIRCLE/0,0,0,0,0,1,10\nGOTO/0,9,0\n").line(), 4);
  EXPECT_EQ(error_of("UNITS/MM\nFROM/9,0,0\nCIRCLE/0,0,0,0,0,1,10\n").line(), 3);
}

TEST(AptReader, CreoHelixAndMultiPointArc) {
  const Program p = apt(corpus("creo_ncl.ncl"));
  // Moves: rapid to z 2, feed to z -1, helix orbit, quarter, quarter, rapid up.
  ASSERT_EQ(p.moves.size(), 6u);
  EXPECT_EQ(p.moves[0].kind, MotionKind::rapid);
  EXPECT_NEAR(p.moves[1].feed_m_s, 300e-3 / 60, 1e-15);
  const auto& orbit = p.moves[2];
  EXPECT_EQ(orbit.kind, MotionKind::arc);
  EXPECT_NEAR(orbit.sweep_rad, 2 * kPi, 1e-12);
  EXPECT_NEAR(orbit.end_m.z(), -3e-3, 1e-15);
  EXPECT_NEAR(p.moves[3].sweep_rad, kPi / 2, 1e-12);  // (60,0) → (50,10) about (50,0)
  EXPECT_NEAR(p.moves[4].sweep_rad, kPi / 2, 1e-12);  // (50,10) → (40,0): the bare point
  expect_near(p.moves[4].end_m, Vector3d(40e-3, 0, -3e-3));
  EXPECT_EQ(p.moves[5].kind, MotionKind::rapid);
  ASSERT_EQ(p.tool_calls.size(), 1u);
  EXPECT_EQ(p.tool_calls[0].tool, 1);
  EXPECT_NEAR(*p.tool_calls[0].diameter_m, 16e-3, 1e-15);
}

TEST(AptReader, DrillCycleFixedForm) {
  // Hole top (20,30,0), 10 deep, feed 120 mm/min, clearance 3 mm.
  const Program p =
      apt("UNITS/MM\nFEDRAT/MMPM,500\nFROM/0,0,50\nCYCLE/DRILL,10,MMPM,120,3\nGOTO/20,30,0\n"
          "GOTO/40,30,0\nCYCLE/OFF\nGOTO/40,30,50\n");
  ASSERT_EQ(p.moves.size(), 7u);
  EXPECT_EQ(p.moves[0].kind, MotionKind::rapid);
  expect_near(p.moves[0].end_m, Vector3d(20e-3, 30e-3, 3e-3));
  EXPECT_EQ(p.moves[1].kind, MotionKind::linear);
  expect_near(p.moves[1].end_m, Vector3d(20e-3, 30e-3, -10e-3));
  EXPECT_NEAR(p.moves[1].feed_m_s, 2e-3, 1e-15);
  EXPECT_EQ(p.moves[2].kind, MotionKind::rapid);
  expect_near(p.moves[2].end_m, Vector3d(20e-3, 30e-3, 3e-3));
  expect_near(p.moves[3].end_m, Vector3d(40e-3, 30e-3, 3e-3));  // next hole, at clearance
  expect_near(p.moves[4].end_m, Vector3d(40e-3, 30e-3, -10e-3));
  EXPECT_EQ(p.moves[6].kind, MotionKind::linear);  // the cycle is off: a feed move
  EXPECT_NEAR(p.moves[6].feed_m_s, 500e-3 / 60, 1e-15);
}

TEST(AptReader, DrillCycleCouplets) {
  // NX: rapid to 3 above, feed to 10 below (FEDTO negative), 250 mm/min.
  const Program nx =
      apt("UNITS/MM\nFROM/20,100,50\nCYCLE/"
          "DRILL,RAPTO,3.0000,FEDTO,-10.0000,RTRCTO,AUTO,MMPM,250.0000\n"
          "GOTO/20.0000,100.0000,10.0000\nCYCLE/OFF\n");
  ASSERT_EQ(nx.moves.size(), 3u);
  expect_near(nx.moves[0].end_m, Vector3d(20e-3, 100e-3, 13e-3));
  expect_near(nx.moves[1].end_m, Vector3d(20e-3, 100e-3, 0));
  EXPECT_NEAR(nx.moves[1].feed_m_s, 250e-3 / 60, 1e-15);
  expect_near(nx.moves[2].end_m, Vector3d(20e-3, 100e-3, 13e-3));
  // Fusion: clear 5 above, rapid to 1 above, retract to 5, depth positive, 2 s dwell.
  const Program fusion =
      apt("UNITS/MM\nFROM/0,0,50\nCYCLE/DRILL, FEDTO, 8, MMPM, 90, CLEAR, 5, RAPTO, 1, DWELL, 2\n"
          "GOTO/0,0,0\n");
  ASSERT_EQ(fusion.moves.size(), 5u);
  expect_near(fusion.moves[0].end_m, Vector3d(0, 0, 5e-3));
  expect_near(fusion.moves[1].end_m, Vector3d(0, 0, 1e-3));
  expect_near(fusion.moves[2].end_m, Vector3d(0, 0, -8e-3));
  EXPECT_EQ(fusion.moves[3].kind, MotionKind::dwell);
  EXPECT_EQ(fusion.moves[3].dwell_s, 2.0);
  expect_near(fusion.moves[4].end_m, Vector3d(0, 0, 5e-3));
}

TEST(AptReader, MastercamInchDrillWithUnitAfterTheFeed) {
  // CYCLE/DRILL,.5,6.0,IPM,.1: depth 0.5 in, 6 in/min, clearance 0.1 in.
  const Program p = apt(corpus("mastercam_drill.apt"));
  ASSERT_EQ(p.moves.size(), 7u);
  expect_near(p.moves[0].end_m, Vector3d(0.0254, 0.0127, 0.00254), 1e-15);
  expect_near(p.moves[1].end_m, Vector3d(0.0254, 0.0127, -0.0127), 1e-15);
  EXPECT_NEAR(p.moves[1].feed_m_s, 6 * 0.0254 / 60, 1e-15);
  EXPECT_EQ(p.moves[1].tool, 4);
  expect_near(p.moves[6].end_m, Vector3d(0.0508, 0.0127, 0.0508), 1e-15);
  EXPECT_NEAR(*p.tool_calls.at(0).diameter_m, 0.25 * 0.0254, 1e-15);
}

TEST(AptReader, MsysMapsCoordinatesAxesAndCirclesToThePartFrame) {
  // MCS at (100, 50, 0) turned +90° about Z: x_mcs = +Y_part, y_mcs = −X_part,
  // so part = (100 − y, 50 + x, z).
  const Program p = apt(corpus("nx_planar_profile.cls"));
  ASSERT_EQ(p.moves.size(), 6u);
  expect_near(p.moves[0].start_m, Vector3d(0.100, 0.070, 0.010));
  expect_near(p.moves[0].end_m, Vector3d(0.100, 0.070, -0.002));
  expect_near(p.moves[1].end_m, Vector3d(0.100, 0.080, -0.002));
  const auto& quarter = p.moves[2];
  expect_near(quarter.centre_m, Vector3d(0.090, 0.080, -0.002));
  EXPECT_NEAR(quarter.sweep_rad, kPi / 2, 1e-12);
  expect_near(quarter.end_m, Vector3d(0.090, 0.090, -0.002));
  // The half circle about −Z passes y_mcs = 20, i.e. part (80, 80).
  const auto& half = p.moves[4];
  expect_near(robomill::toolpath::position_at(half, 0.5), Vector3d(0.080, 0.080, -0.002), 1e-12);
  EXPECT_EQ(p.moves[5].kind, MotionKind::rapid);
  EXPECT_NEAR(p.moves[1].feed_m_s, 0.005, 1e-15);
  EXPECT_NEAR(p.moves[1].spindle_rad_s, 6000 * 2 * kPi / 60, 1e-12);
  ASSERT_EQ(p.tool_calls.size(), 1u);
  EXPECT_EQ(p.tool_calls[0].tool, 3);
  EXPECT_NEAR(*p.tool_calls[0].diameter_m, 0.010, 1e-15);
  EXPECT_NEAR(*p.tool_calls[0].corner_radius_m, 0.001, 1e-15);
}

TEST(AptReader, MsysRotatesToolAxes) {
  // X axis of the MCS = part +Y; a GOTO axis along x_mcs is part +Y.
  const Program p = apt("UNITS/MM\nMSYS/0,0,0,0,1,0,-1,0,0\nFROM/0,0,0\nGOTO/1,0,0,1,0,0\n");
  expect_near(p.moves[0].end_m, Vector3d(0, 1e-3, 0));
  expect_near(p.moves[0].axis_end, Vector3d::UnitY());
  // The 12-number matrix of the same frame, translated by (1, 2, 3).
  const Program q = apt("UNITS/MM\nCSYS/0,-1,0,1,1,0,0,2,0,0,1,3\nFROM/0,0,0\nGOTO/1,0,0\n");
  expect_near(q.moves[0].end_m, Vector3d(1e-3, 3e-3, 3e-3));
}

TEST(AptReader, FiveAxisBallEndLeansTheToolAlongThePass) {
  const Program p = apt(corpus("five_axis_ball.cl"));
  ASSERT_EQ(p.moves.size(), 8u);
  for (int n = 1; n < 7; ++n) {
    const double lean = 5.0 * n * kPi / 180;
    expect_near(p.moves[n].axis_end, Vector3d(-std::sin(lean), 0, std::cos(lean)), 1e-9);
    EXPECT_NEAR(p.moves[n].axis_end.norm(), 1.0, 1e-15);
    EXPECT_NEAR(p.moves[n].feed_m_s, 0.04, 1e-15);
  }
  EXPECT_EQ(p.moves[7].kind, MotionKind::rapid);
  expect_near(p.moves[7].axis_end, p.moves[6].axis_end);  // the axis stays modal
}

TEST(AptReader, NoOpWordsAreAccepted) {
  const Program p =
      apt("PARTNO TEST $ not a continuation\nREMARK anything, even GOTO/1\nPPRINT $$ text\n"
          "INSERT G54\nCLPRNT\nINTOL/0.01\nOUTTOL/0.01\nAUTOPS\nDISPLY/ON\nOPSKIP/ON\nPPFUN/1\n"
          "STOP\nOPSTOP\nCOOLNT/MIST\nCUTCOM/OFF\nMULTAX/OFF\nPAINT/COLOR,3\nUNITS/MM\nFROM/0,0,0\n"
          "GOTO/1,1,1\nEND\nFINI\nGOTO/junk\n");
  EXPECT_EQ(p.moves.size(), 1u);
  EXPECT_EQ(p.line_count, 23u);
}

TEST(AptReader, ErrorsNameTheLineAndTheWord) {
  InputError e = error_of("UNITS/MM\nFROM/0,0,0\nCUTCOM/LEFT\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.field(), "test.cl");
  EXPECT_NE(std::string(e.what()).find("CUTCOM/LEFT"), std::string::npos);
  EXPECT_NE(std::string(e.what()).find("tool centre path"), std::string::npos);

  e = error_of("UNITS/MM\nFOOBAR/1,2\n");
  EXPECT_EQ(e.line(), 2);
  EXPECT_NE(std::string(e.what()).find("FOOBAR"), std::string::npos);

  e = error_of("UNITS/MM\nFROM/0,0,0\nGOTO/1,2,3x\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(std::string(e.what()).find("3X"), std::string::npos);

  e = error_of("UNITS/MM\n\nGOTO/1,2,3,4\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(std::string(e.what()).find("4 numbers"), std::string::npos);

  e = error_of("UNITS/MM\nFROM/0,0,0\nGOTO/1,2,3,0,0,0\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(std::string(e.what()).find("zero"), std::string::npos);

  EXPECT_EQ(error_of("UNITS/MM\nTLAXIS/0,0,0\n").line(), 2);
  EXPECT_EQ(error_of("UNITS/FEET\n").line(), 1);
  EXPECT_EQ(error_of("FEDRAT/-5\n").line(), 1);
  EXPECT_EQ(error_of("GOFWD/(CIRCLE/0,0,0,5),ON,(LINE/0,0,0,1,1,0)\n").line(), 1);
  EXPECT_EQ(error_of("FROM/0,0,0\n1,2,3\n").line(), 2);  // bare coordinates after no GOTO
  EXPECT_EQ(error_of("SPINDL/SFM,300\n").line(), 1);
  EXPECT_EQ(error_of("CYCLE/CSINK,10,90\n").line(), 1);
  EXPECT_EQ(error_of("MSYS/0,0,0,1,0,0,1,0,0\n").line(), 1);  // parallel axes
}

// --- Units of a CL file that declares none (NX CLSF) ---------------------

TEST(AptReader, InchInferredFromTheFirstFeedWithoutUnitsRecord) {
  // NX writes no UNITS record: FEDRAT/IPM (line 5) is the only word on inch.
  const Program p =
      apt("TLDATA/MILL,0.5000,0.0600,3.0000,0.0000,0.0000\nLOAD/TOOL,1\nRAPID\nGOTO/1,0,1\n"
          "FEDRAT/IPM,10\nGOTO/1,0,-0.5\n");
  ASSERT_EQ(p.moves.size(), 1u);
  expect_near(p.moves[0].start_m, Vector3d(0.0254, 0, 0.0254));
  expect_near(p.moves[0].end_m, Vector3d(0.0254, 0, -0.0127));
  EXPECT_NEAR(p.moves[0].feed_m_s, 10 * 0.0254 / 60, 1e-15);
  ASSERT_EQ(p.tool_calls.size(), 1u);
  EXPECT_NEAR(*p.tool_calls[0].diameter_m, 0.0127, 1e-15);
  EXPECT_NEAR(*p.tool_calls[0].corner_radius_m, 0.001524, 1e-15);
  EXPECT_EQ(note_line(p, "FEDRAT/IPM (line 5) gives feeds in inches"), 5);
  EXPECT_TRUE(has_note(p, "toolpath.units: mm"));
  // IPR says inch as well; MMPM first says millimetres, noted.
  EXPECT_NEAR(apt("SPINDL/1000\nFROM/0,0,0\nFEDRAT/0.004,IPR\nGOTO/2,0,0\n").moves[0].end_m.x(),
              0.0508, 1e-15);
  const Program mm = apt("FROM/0,0,0\nFEDRAT/MMPM,300\nGOTO/2,0,0\nFEDRAT/IPM,10\n");
  EXPECT_EQ(mm.moves[0].end_m.x(), 2e-3);
  EXPECT_EQ(note_line(mm, "no UNITS record: coordinates read in millimetres (as FEDRAT/MMPM"), 2);
}

TEST(AptReader, TheJobsUnitRulesAProgramWithoutUnitsRecord) {
  using Unit = AptOptions::Unit;
  // toolpath.units: inch; the feed is per minute in its own unit (MMPM).
  const Program p = apt("FROM/0,0,0\nFEDRAT/MMPM,254\nGOTO/1,2,3\n", Unit::inch);
  expect_near(p.moves[0].end_m, Vector3d(0.0254, 0.0508, 0.0762));
  EXPECT_NEAR(p.moves[0].feed_m_s, 0.254 / 60, 1e-15);
  EXPECT_TRUE(has_note(p, "no UNITS record: lengths read in inches (toolpath.units)"));
  // toolpath.units: mm wins over an IPM feed's hint.
  EXPECT_EQ(apt("FROM/0,0,0\nFEDRAT/IPM,10\nGOTO/2,0,0\n", Unit::mm).moves[0].end_m.x(), 2e-3);
  // A UNITS record that agrees is fine; one that disagrees names both.
  EXPECT_NEAR(apt("UNITS/INCHES\nFROM/0,0,0\nGOTO/2,0,0\n", Unit::inch).moves[0].end_m.x(), 0.0508,
              1e-15);
  InputError e = error_of("PARTNO/X\nUNITS/INCHES\nFROM/0,0,0\n", Unit::mm);
  EXPECT_EQ(e.line(), 2);
  EXPECT_NE(std::string(e.what()).find("UNITS/INCHES says the program is in inches"),
            std::string::npos);
  EXPECT_NE(std::string(e.what()).find("toolpath.units says mm"), std::string::npos);
  e = error_of("UNIT/MM\n", Unit::inch);
  EXPECT_EQ(e.line(), 1);
  EXPECT_NE(std::string(e.what()).find("toolpath.units says inch"), std::string::npos);
}

TEST(AptReader, LeadingUnitForWritersFollowsTheReadersRule) {
  using robomill::io::apt_leading_unit;
  using Unit = AptOptions::Unit;
  EXPECT_EQ(apt_leading_unit("GOTO/1,0,0\nFEDRAT/IPM,10\n"), Unit::inch);
  EXPECT_EQ(apt_leading_unit("GOTO/1,0,0\nFEDRAT/IPM,10\n", Unit::mm), Unit::mm);
  EXPECT_EQ(apt_leading_unit("FEDRAT/MMPM,10\nFEDRAT/IPM,10\n"), Unit::mm);
  EXPECT_EQ(apt_leading_unit("GOTO/1,0,0\n"), Unit::mm);
  // A UNITS record rules from where it stands: before it, millimetres.
  EXPECT_EQ(apt_leading_unit("GOTO/1,0,0\nUNITS/INCHES\nFEDRAT/IPM,10\n"), Unit::mm);
  EXPECT_EQ(apt_leading_unit("UNITS/INCHES\n", Unit::inch), Unit::inch);
}

// --- Vendor records ------------------------------------------------------

TEST(AptReader, RecordsThatChangeNothingAreSkippedWithLineAndCount) {
  const Program p =
      apt("UNITS/MM\nPAINT/PATH\nLOAD/TOOL,2,ADJUST,2\nSELECT/TOOL,4\nPPWORD/OPSKIP,1039\n"
          "CSI_SET_FLUTE_LENGTH/19.\nCSI_SOMETHING_ELSE/1,2\nTRNTYP/WORLD,0,0,0\nFROM/0,0,0\n"
          "PAINT/COLOR,31\nGOTO/1,0,0\nPAINT/COLOR,37\nSELECT/TOOL,5\n");
  ASSERT_EQ(p.moves.size(), 1u);
  EXPECT_EQ(p.moves[0].tool, 2);  // SELECT/TOOL only readies the next tool
  EXPECT_EQ(note_line(p, "PAINT (3 records from line 2)"), 2);
  EXPECT_EQ(note_line(p, "SELECT (2 records from line 4): tool preselection"), 4);
  EXPECT_EQ(note_line(p, "PPWORD (1 record from line 5): vocabulary"), 5);
  EXPECT_EQ(note_line(p, "CSI_SET_FLUTE_LENGTH (1 record from line 6): CAMWorks"), 6);
  EXPECT_EQ(note_line(p, "CSI_SOMETHING_ELSE (1 record from line 7)"), 7);
  EXPECT_EQ(note_line(p, "TRNTYP (1 record from line 8)"), 8);
}

TEST(AptReader, WordsThatWouldChangeThePathAreRefusedByLineAndWord) {
  InputError e = error_of("UNITS/MM\nFROM/0,0,0\nNURBS/\nKNOT/1.0\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(std::string(e.what()).find("NURBS: spline motion is not modelled"), std::string::npos);
  e = error_of("UNITS/MM\nTRNTYP/WORLD,10,0,0\n");
  EXPECT_EQ(e.line(), 2);
  EXPECT_NE(std::string(e.what()).find("TRNTYP/WORLD,10,0,0"), std::string::npos);
  e = error_of("UNITS/MM\nSELECT/PLANE,1\n");
  EXPECT_EQ(e.line(), 2);
  EXPECT_NE(std::string(e.what()).find("SELECT/TOOL, n"), std::string::npos);
  EXPECT_EQ(error_of("UNITS/MM\nFROM/0,0,0\nMOVARC/0,0,0,0,0,1,5,90\n").line(), 3);
  EXPECT_EQ(error_of("UNITS/MM\nCSI_/1\n").line(), 2);  // the prefix alone names nothing
  e = error_of("UNITS/MM\nPPWORDS/1\n");                // a near miss is still unknown
  EXPECT_NE(std::string(e.what()).find("'PPWORDS' is not an APT / CL major word"),
            std::string::npos);
}

TEST(AptReader, CamworksCircleWithoutRadiusTakesTheStarts) {
  // CAMWorks: CIRCLE/xc,yc,zc,i,j,k; the quarter from (10,0) clockwise to (0,-10).
  const Program p =
      apt("UNIT/MM\nFROM/10,0,0\nFEDRAT/100,MMPM\nCIRCLE/0,0,0,0,0,-1.\nGOTO/0,-10,0\n");
  ASSERT_EQ(p.moves.size(), 1u);
  EXPECT_EQ(p.moves[0].kind, MotionKind::arc);
  EXPECT_NEAR(robomill::toolpath::path_length_m(p.moves[0]), 0.010 * kPi / 2, 1e-12);
  const InputError e =
      error_of("UNIT/MM\nFROM/10,0,0\nFEDRAT/100,MMPM\nCIRCLE/0,0,0,0,0,-1.\nGOTO/0,-12,0\n");
  EXPECT_EQ(e.line(), 5);
}

// --- Real CL programs by others (tests/toolpath/apt/README.md) -----------

TEST(AptReader, CamworksBossPocketReadsWithItsVendorRecords) {
  // CAMWorks APT (aamorim1913/AptPostProcessor, parts-tools/boss.apt, GPL-3.0),
  // its first two levels: 62 GOTOs (the first is the start), 8 CIRCLEs.
  const Program p = apt(corpus("camworks_boss.apt"));
  ASSERT_EQ(p.moves.size(), 61u);
  EXPECT_EQ(count_kind(p, MotionKind::arc), 8u);
  EXPECT_EQ(count_kind(p, MotionKind::rapid), 5u);
  EXPECT_FALSE(has_note(p, "no UNITS record"));
  ASSERT_EQ(p.tool_calls.size(), 1u);  // CUTTER/6.,0,3.,... then LOAD/TOOL,1
  EXPECT_EQ(p.tool_calls[0].tool, 1);
  EXPECT_NEAR(*p.tool_calls[0].diameter_m, 6e-3, 1e-15);
  EXPECT_EQ(*p.tool_calls[0].corner_radius_m, 0.0);
  for (const auto& move : p.moves) {
    EXPECT_EQ(move.tool, 1);
    EXPECT_NEAR(move.spindle_rad_s, 12000 * 2 * kPi / 60, 1e-9);
  }
  EXPECT_NEAR(p.moves[1].feed_m_s, 411.48e-3 / 60, 1e-15);   // the plunge
  EXPECT_NEAR(p.moves[2].feed_m_s, 1645.92e-3 / 60, 1e-15);  // the cut
  const Box box = end_point_box(p);
  expect_near(box.min, Vector3d(77.914806e-3, -1.4375e-3, -5.993718e-3), 1e-15);
  expect_near(box.max, Vector3d(96.4375e-3, 41.334899e-3, 25e-3), 1e-15);
  EXPECT_EQ(note_line(p, "CSI_SET_FLUTE_LENGTH (1 record from line 6)"), 6);
  EXPECT_EQ(note_line(p, "CSI_SET_EXTENSION_LENGTH (1 record from line 7)"), 7);
  EXPECT_EQ(note_line(p, "SELECT (1 record from line 8)"), 8);
  EXPECT_EQ(note_line(p, "TRNTYP (1 record from line 12)"), 12);
  EXPECT_EQ(note_line(p, "INSERT (2 records from line 3)"), 3);
}

TEST(AptReader, NxVariableContourBallInInchesWithoutUnitsOrSpindle) {
  // 16 zig-zag rows of 19 points on z = sqrt(4 - x^2) - 2 in, the axis along
  // the normal (x/2, 0, (z + 2)/2): 2 rapids, the plunge, 303 cuts, the exit.
  const Program p = apt(corpus("nx_variable_contour_ball_in.cls"));
  ASSERT_EQ(p.moves.size(), 307u);
  EXPECT_EQ(count_kind(p, MotionKind::rapid), 2u);
  EXPECT_EQ(note_line(p, "FEDRAT/IPM (line 16) gives feeds in inches"), 16);
  ASSERT_EQ(p.tool_calls.size(), 1u);
  EXPECT_EQ(p.tool_calls[0].tool, 3);
  EXPECT_NEAR(*p.tool_calls[0].diameter_m, 0.25 * 0.0254, 1e-15);
  EXPECT_NEAR(*p.tool_calls[0].corner_radius_m, 0.125 * 0.0254, 1e-15);  // a ball: R
  EXPECT_TRUE(has_note(p, "SELECT (1 record from line 8)"));
  for (const auto& move : p.moves)
    EXPECT_EQ(move.spindle_rad_s, 0.0);  // no SPINDL record: the job's toolpath.spindle
  EXPECT_NEAR(p.moves[1].feed_m_s, 20 * 0.0254 / 60, 1e-15);
  EXPECT_NEAR(p.moves[2].feed_m_s, 40 * 0.0254 / 60, 1e-15);
  // The first cut ends at x = -0.8 in: the axis leans (-0.4, 0, 0.9165).
  const double z = std::sqrt(4.0 - 0.64) - 2.0;
  expect_near(p.moves[2].end_m, 0.0254 * Vector3d(-0.8, 0, z), 0.0254 * 5e-5);
  expect_near(p.moves[2].axis_end, Vector3d(-0.4, 0, (z + 2) / 2), 2e-7);
  // The axis stays modal between rows: the last row runs back, x 0.9 → -0.9.
  const double zl = std::sqrt(4.0 - 0.81) - 2.0;
  expect_near(p.moves[304].end_m, 0.0254 * Vector3d(-0.9, 1.5, zl), 0.0254 * 5e-5);
  expect_near(p.moves[304].axis_end, Vector3d(-0.45, 0, (zl + 2) / 2), 2e-7);
  const Box box = end_point_box(p);  // the clearance 1 in along the first and last normals
  expect_near(box.min, 0.0254 * Vector3d(-1.35, 0, zl), 0.0254 * 5e-5);
  expect_near(box.max, 0.0254 * Vector3d(0.9, 1.5, zl + (zl + 2) / 2), 0.0254 * 5e-5);
}

TEST(AptReader, NxProfileWithABullNoseInInches) {
  // TLDATA/MILL,0.5,0.06: a bull nose (0 < r < R). The rapid down, two
  // levels of 12 moves (the step down, the lead-in, 4 sides, 4 clockwise
  // corners of radius 0.5 in, the lead-out), the exit and the rapid up.
  const Program p = apt(corpus("nx_profile_bull_in.cls"));
  ASSERT_EQ(p.moves.size(), 27u);
  EXPECT_EQ(count_kind(p, MotionKind::arc), 8u);
  EXPECT_EQ(count_kind(p, MotionKind::rapid), 2u);
  ASSERT_EQ(p.tool_calls.size(), 1u);
  EXPECT_NEAR(*p.tool_calls[0].diameter_m, 0.0127, 1e-15);
  EXPECT_NEAR(*p.tool_calls[0].corner_radius_m, 0.06 * 0.0254, 1e-15);
  EXPECT_TRUE(has_note(p, "gives feeds in inches"));
  double arcs = 0.0;
  for (const auto& move : p.moves)
    if (move.kind == MotionKind::arc)
      arcs += robomill::toolpath::path_length_m(move);
  EXPECT_NEAR(arcs, 8 * 0.5 * 0.0254 * kPi / 2, 1e-9);  // quarters, not three-quarters
  const Box box = end_point_box(p);
  expect_near(box.min, 0.0254 * Vector3d(-0.25, -0.75, -0.25), 1e-12);
  expect_near(box.max, 0.0254 * Vector3d(2.25, 1.75, 1.0), 1e-12);
}

TEST(AptReader, CreoInchesWithPpwordVocabulary) {
  const Program p = apt(corpus("creo_bracket_in.ncl"));
  ASSERT_EQ(p.moves.size(), 10u);
  EXPECT_EQ(count_kind(p, MotionKind::arc), 4u);  // a full circle in four points
  EXPECT_EQ(note_line(p, "PPWORD (2 records from line 8)"), 8);
  ASSERT_EQ(p.tool_calls.size(), 1u);
  EXPECT_EQ(p.tool_calls[0].tool, 2);
  EXPECT_NEAR(*p.tool_calls[0].diameter_m, 0.0127, 1e-15);
  EXPECT_NEAR(p.moves[3].feed_m_s, 16 * 0.0254 / 60, 1e-15);
  double arcs = 0.0;
  for (const auto& move : p.moves)
    if (move.kind == MotionKind::arc)
      arcs += robomill::toolpath::path_length_m(move);
  EXPECT_NEAR(arcs, 2 * kPi * 0.5 * 0.0254, 1e-9);
  const Box box = end_point_box(p);
  expect_near(box.min, 0.0254 * Vector3d(0.5, 0.5, -0.1), 1e-12);
  expect_near(box.max, 0.0254 * Vector3d(3.5, 2.0, 0.5), 1e-12);
}

TEST(AptReader, TooLargeIsRefusedBeforeParsing) {
  AptOptions options;
  options.max_bytes = 16;
  EXPECT_THROW(read_apt("UNITS/MM\nGOTO/1,2,3\nGOTO/4,5,6\n", options), InputError);
}

}  // namespace

}  // namespace test_apt_reader_cpp
