// KUKA KRL reader: expected values are worked out by hand from the frames
// (Rz(A)·Ry(B)·Rx(C), mm → m) and the bases, not copied from the output.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/toolpath/program.hpp"

namespace test_krl_reader_cpp {

namespace {

using Eigen::Vector3d;
using robomill::InputError;
using robomill::io::KrlOptions;
using robomill::io::read_krl;
using robomill::toolpath::MotionKind;
using robomill::toolpath::Program;

constexpr double kPi = std::numbers::pi;

std::string corpus(const std::string& name) {
  std::ifstream file(std::string(ROBOMILL_SOURCE_DIR) + "/tests/toolpath/" + name);
  EXPECT_TRUE(file.good()) << name;
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

KrlOptions options_with(const std::string& dat = "", char direction = 'x') {
  KrlOptions options;
  options.source_name = "test.src";
  options.dat_name = "test.dat";
  options.dat_text = dat;
  options.tool_direction = direction;
  return options;
}

Program krl(const std::string& body, const std::string& dat = "", char direction = 'x') {
  return read_krl("DEF test( )\n" + body + "END\n", options_with(dat, direction));
}

InputError error_of(const std::string& body, const std::string& dat = "") {
  try {
    krl(body, dat);
  } catch (const InputError& error) {
    return error;
  }
  ADD_FAILURE() << "no InputError for:\n" << body;
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

// The tool axis at the end of a single LIN to the frame {X 1, A a, B b, C c}.
Vector3d axis_for(const std::string& abc, char direction) {
  const Program p = krl("LIN {X 0,Y 0,Z 0," + abc + "}\nLIN {X 1}\n", "", direction);
  return p.moves.at(0).axis_end;
}

TEST(KrlReader, OrientationIsZYXAnglesAndTheToolWorksAlongMinusItsAxis) {
  // #X: the tool works along +X of the TCP frame; tip → spindle is −X.
  expect_near(axis_for("A 0,B 90,C 0", 'x'), Vector3d(0, 0, 1));  // milling down
  expect_near(axis_for("A 0,B 0,C 0", 'x'), Vector3d(-1, 0, 0));
  expect_near(axis_for("A 90,B 0,C 0", 'x'), Vector3d(0, -1, 0));
  // Rz(30)·Ry(60)·ex = (cos30 cos60, sin30 cos60, −sin60).
  expect_near(axis_for("A 30,B 60,C 45", 'x'),
              -Vector3d(std::cos(kPi / 6) * 0.5, 0.25, -std::sin(kPi / 3)), 1e-12);
  // #Z: the tool works along +Z; Rx(30)·ez = (0, −sin30, cos30).
  expect_near(axis_for("A 0,B 0,C 30", 'z'), -Vector3d(0, -0.5, std::cos(kPi / 6)), 1e-12);
  expect_near(axis_for("A 0,B 0,C 180", 'z'), Vector3d(0, 0, 1), 1e-12);
}

// The frames' rotation about the tool axis reaches the moves (Move::oriented,
// tool_x_start/end): robomill's tool x is the TCP frame's Z with #X, its X
// with #Z. With #X and B 90 the tool points down and A turns it about its
// axis: Rz(A)·Ry(90)·ez = Rz(A)·ex = (cos A, sin A, 0).
TEST(KrlReader, FramesFixTheToolsRotationAboutItsAxis) {
  const Program p =
      krl("$VEL.CP=0.01\nLIN {X 0,Y 0,Z 0,A 0,B 90,C 0}\nLIN {X 10,Y 0,Z 0,A 30,B 90,C 0}\n"
          "WAIT SEC 1\n");
  ASSERT_EQ(p.moves.size(), 2u);
  EXPECT_TRUE(p.moves[0].oriented);
  expect_near(p.moves[0].tool_x_start, Vector3d(1, 0, 0), 1e-12);
  expect_near(p.moves[0].tool_x_end, Vector3d(std::cos(kPi / 6), 0.5, 0), 1e-12);
  // Halfway the tool has turned 15° about its axis (+Z).
  expect_near(robomill::toolpath::tool_x_at(p.moves[0], 0.5),
              Vector3d(std::cos(kPi / 12), std::sin(kPi / 12), 0), 1e-12);
  EXPECT_TRUE(p.moves[1].oriented);  // the dwell keeps the rotation
  expect_near(p.moves[1].tool_x_end, Vector3d(std::cos(kPi / 6), 0.5, 0), 1e-12);
  // #Z: x is the TCP frame's X; Rx(180) keeps ex: the tool down, x along +X.
  const Program z =
      krl("$VEL.CP=0.01\nLIN {X 0,Y 0,Z 0,A 0,B 0,C 180}\nLIN {X 10,Y 0,Z 0}\n", "", 'z');
  ASSERT_EQ(z.moves.size(), 1u);
  expect_near(z.moves[0].axis_end, Vector3d(0, 0, 1), 1e-12);
  expect_near(z.moves[0].tool_x_end, Vector3d(1, 0, 0), 1e-12);
  // Every move's x is normal to its axis, right-handed with it (x, axis × x, axis).
  for (const auto& move : p.moves)
    EXPECT_NEAR(move.tool_x_end.dot(move.axis_end), 0.0, 1e-12);
}

TEST(KrlReader, PositionsAreMillimetresAndFeedIsVelCp) {
  const Program p =
      krl("$VEL.CP=0.2\nLIN {X 10,Y 20,Z 30,A 0,B 90,C 0}\nLIN {X 15,Y 20,Z 30} C_DIS\n");
  ASSERT_EQ(p.moves.size(), 1u);
  EXPECT_EQ(p.dialect, "krl");
  expect_near(p.moves[0].start_m, Vector3d(0.010, 0.020, 0.030));
  expect_near(p.moves[0].end_m, Vector3d(0.015, 0.020, 0.030));
  EXPECT_EQ(p.moves[0].kind, MotionKind::linear);
  EXPECT_EQ(p.moves[0].feed_m_s, 0.2);
  EXPECT_EQ(p.moves[0].spindle_rad_s, 0.0);
  EXPECT_EQ(p.moves[0].line, 4);
}

TEST(KrlReader, PartialFramesKeepTheCurrentComponents) {
  const Program p = krl("LIN {X 10,Y 20,Z 30,A 0,B 90,C 0}\nLIN {Z -2}\nLIN {Y 5}\n");
  ASSERT_EQ(p.moves.size(), 2u);
  expect_near(p.moves[0].end_m, Vector3d(0.010, 0.020, -0.002));
  expect_near(p.moves[1].end_m, Vector3d(0.010, 0.005, -0.002));
  expect_near(p.moves[1].axis_end, Vector3d(0, 0, 1));
}

TEST(KrlReader, PtpIsRapid) {
  const Program p =
      krl("PTP {X 0,Y 0,Z 100,A 0,B 90,C 0}\nPTP {Z 50} C_PTP\n$VEL.CP=0.1\n"
          "LIN {Z 0}\n");
  ASSERT_EQ(p.moves.size(), 2u);
  EXPECT_EQ(p.moves[0].kind, MotionKind::rapid);
  EXPECT_EQ(p.moves[0].feed_m_s, 0.0);
  EXPECT_EQ(p.moves[1].kind, MotionKind::linear);
  EXPECT_EQ(p.moves[1].feed_m_s, 0.1);
}

TEST(KrlReader, LinRelInTheBaseAndInTheTool) {
  // With B 90 the TCP frame's z axis is Ry(90)·ez = +X of the base.
  const Program p =
      krl("LIN {X 10,Y 0,Z 0,A 0,B 90,C 0}\nLIN_REL {X 5}\nLIN_REL {Y -2,Z 1} C_DIS #BASE\n"
          "LIN_REL {Z 5} #TOOL\n");
  ASSERT_EQ(p.moves.size(), 3u);
  expect_near(p.moves[0].end_m, Vector3d(0.015, 0, 0));
  expect_near(p.moves[1].end_m, Vector3d(0.015, -0.002, 0.001));
  expect_near(p.moves[2].end_m, Vector3d(0.020, -0.002, 0.001));
}

TEST(KrlReader, CircThroughThreePoints) {
  // (10,0) → via (0,10) → (−10,0): the upper half circle about the origin, CCW about +Z.
  const Program p =
      krl("$VEL.CP=0.05\nLIN {X 10,Y 0,Z 0,A 0,B 90,C 0}\nCIRC {X 0,Y 10,Z 0},{X -10,Y 0,Z 0}\n");
  ASSERT_EQ(p.moves.size(), 1u);
  const auto& arc = p.moves[0];
  EXPECT_EQ(arc.kind, MotionKind::arc);
  expect_near(arc.centre_m, Vector3d::Zero());
  EXPECT_NEAR(arc.sweep_rad * arc.normal.z(), kPi, 1e-12);
  expect_near(robomill::toolpath::position_at(arc, 0.5), Vector3d(0, 0.010, 0), 1e-12);
  EXPECT_EQ(arc.feed_m_s, 0.05);
}

TEST(KrlReader, CircAngleSetsTheSweep) {
  // CA 270 in the start → aux sense ends at (0, −10); CA −90 goes the other way to the same point.
  const std::string start = "LIN {X 10,Y 0,Z 0,A 0,B 90,C 0}\n";
  const Program forward = krl(start + "CIRC {X 0,Y 10},{X -10,Y 0},CA 270.0 C_DIS\nLIN {Z 5}\n");
  const auto& f = forward.moves.at(0);
  EXPECT_NEAR(f.sweep_rad * f.normal.z(), 3 * kPi / 2, 1e-12);
  expect_near(f.end_m, Vector3d(0, -0.010, 0), 1e-12);
  expect_near(forward.moves.at(1).start_m, Vector3d(0, -0.010, 0), 1e-12);
  expect_near(forward.moves.at(1).end_m, Vector3d(0, -0.010, 0.005), 1e-12);
  const Program backward = krl(start + "CIRC {X 0,Y 10},{X -10,Y 0},CA -90\n");
  const auto& b = backward.moves.at(0);
  EXPECT_NEAR(b.sweep_rad * b.normal.z(), -kPi / 2, 1e-12);
  expect_near(b.end_m, Vector3d(0, -0.010, 0), 1e-12);
}

TEST(KrlReader, ForLoopsOverADatArray) {
  const std::string dat =
      "DEFDAT test\nDECL FRAME P[8]\n"
      "P[1]={X 1,Y 0,Z 0,A 0,B 90,C 0}\nP[2]={X 2,Y 0,Z 0,A 0,B 90,C 0}\n"
      "P[3]={X 3,Y 0,Z 0,A 0,B 90,C 0}\nP[4]={X 4,Y 0,Z 0,A 0,B 90,C 0}\n"
      "P[5]={X 5,Y 0,Z 0,A 0,B 90,C 0}\nP[6]={X 6,Y 0,Z 0,A 0,B 90,C 0}\n"
      "P[7]={X 7,Y 0,Z 0,A 0,B 90,C 0}\nP[8]={X 8,Y 0,Z 0,A 0,B 90,C 0}\nENDDAT\n";
  const Program up =
      krl("DECL INT I\nLIN P[1]\nFOR I=2 TO 8 STEP 2\n  LIN P[I]\n  LIN P[1]\nENDFOR\n", dat);
  ASSERT_EQ(up.moves.size(), 8u);  // I = 2, 4, 6, 8: there and back
  expect_near(up.moves[0].end_m, Vector3d(0.002, 0, 0));
  expect_near(up.moves[6].end_m, Vector3d(0.008, 0, 0));
  EXPECT_EQ(up.moves[6].line, 5);
  // I = 7, 4, 1 → P[8], P[5], P[2].
  const Program down = krl("INT I\nLIN P[1]\nFOR I = 7 TO 1 STEP -3\nLIN P[I+1]\nENDFOR\n", dat);
  ASSERT_EQ(down.moves.size(), 3u);
  expect_near(down.moves[0].end_m, Vector3d(0.008, 0, 0));
  expect_near(down.moves[1].end_m, Vector3d(0.005, 0, 0));
  expect_near(down.moves[2].end_m, Vector3d(0.002, 0, 0));
}

TEST(KrlReader, NestedLoopsAndEmptyLoops) {
  const std::string dat =
      "DEFDAT test\nDECL FRAME P[3]\nP[1]={X 1,Y 0,Z 0,A 0,B 90,C 0}\n"
      "P[2]={X 2,Y 0,Z 0,A 0,B 90,C 0}\nP[3]={X 3,Y 0,Z 0,A 0,B 90,C 0}\n"
      "ENDDAT\n";
  const Program p =
      krl("DECL INT I,J\nLIN P[1]\nFOR I=1 TO 2\nFOR J=2 TO 3\nLIN P[J]\nENDFOR\nENDFOR\n"
          "FOR I=5 TO 1\nLIN P[9]\nENDFOR\n",
          dat);
  ASSERT_EQ(p.moves.size(), 4u);  // (2, 3) twice; the empty loop never reads P[9]
  expect_near(p.moves[3].end_m, Vector3d(0.003, 0, 0));
}

TEST(KrlReader, BasesFromTheJobAndInline) {
  KrlOptions options = options_with();
  Eigen::Isometry3d base = Eigen::Isometry3d::Identity();
  base.translation() = Vector3d(1.0, 0.5, 0.0);
  base.linear() = Eigen::AngleAxisd(kPi / 2, Vector3d::UnitZ()).toRotationMatrix();
  options.bases[1] = base;
  // In base 1: (10, 0, 0) mm → (1.0, 0.5 + 0.010, 0); the tool axis stays +Z (rotation about Z).
  const Program p = read_krl(
      "DEF t( )\n$BASE=BASE_DATA[1]\nLIN {X 0,Y 0,Z 0,A 0,B 90,C 0}\nLIN {X 10}\n"
      "$BASE = {FRAME: X 100,Y 0,Z 0,A 90,B 0,C 0}\nLIN {X 10,Y 0,Z 0,A 0,B 90,C 0}\n"
      "$BASE=BASE_DATA[5]\nLIN {X 1,Y 2,Z 3}\nEND\n",
      options);
  ASSERT_EQ(p.moves.size(), 3u);
  expect_near(p.moves[0].start_m, Vector3d(1.0, 0.5, 0));
  expect_near(p.moves[0].end_m, Vector3d(1.0, 0.51, 0), 1e-15);
  expect_near(p.moves[0].axis_end, Vector3d(0, 0, 1));
  expect_near(p.moves[1].end_m, Vector3d(0.100, 0.010, 0), 1e-15);  // inline frame, mm
  expect_near(p.moves[2].end_m, Vector3d(0.001, 0.002, 0.003), 1e-15);
  EXPECT_TRUE(has_note(p, "BASE_DATA[5]"));
}

TEST(KrlReader, ABaseChangeKeepsThePoseForPartialFrames) {
  KrlOptions options = options_with();
  Eigen::Isometry3d base = Eigen::Isometry3d::Identity();
  base.translation() = Vector3d(0.1, 0, 0);
  options.bases[1] = base;
  // The pose (10,0,0) in base 0 is (−90,0,0) in base 1; {Z 5} only lifts it.
  const Program p = read_krl(
      "DEF t( )\nLIN {X 10,Y 0,Z 0,A 0,B 90,C 0}\n$BASE=BASE_DATA[1]\nLIN {Z 5}\nEND\n", options);
  ASSERT_EQ(p.moves.size(), 1u);
  expect_near(p.moves[0].end_m, Vector3d(0.010, 0, 0.005), 1e-15);
}

TEST(KrlReader, PtpToAnAxisPositionEndsAtTheNextCartesianPoint) {
  const Program p =
      krl("$VEL.CP=0.1\nLIN {X 0,Y 0,Z 50,A 0,B 90,C 0}\nPTP {A1 0,A2 -90,A3 90,A4 0,A5 0,A6 0}\n"
          "LIN {X 20,Y 0,Z 50,A 0,B 90,C 0}\nLIN {X 30}\n");
  ASSERT_EQ(p.moves.size(), 2u);
  EXPECT_EQ(p.moves[0].kind, MotionKind::rapid);
  expect_near(p.moves[0].start_m, Vector3d(0, 0, 0.050));
  expect_near(p.moves[0].end_m, Vector3d(0.020, 0, 0.050));
  EXPECT_EQ(p.moves[1].kind, MotionKind::linear);
  EXPECT_TRUE(has_note(p, "air move"));
  // After the axis position a partial frame has nothing to complete it.
  EXPECT_EQ(error_of("LIN {X 0,Y 0,Z 50,A 0,B 90,C 0}\nPTP {A1 0,A2 -90,A3 90,A4 0,A5 0,A6 0}\n"
                     "LIN {X 10}\n")
                .line(),
            4);
}

TEST(KrlReader, WaitSecIsADwell) {
  const Program p = krl("LIN {X 1,Y 2,Z 3,A 0,B 90,C 0}\nWAIT SEC 1.5\nWAIT SEC 0\n");
  ASSERT_EQ(p.moves.size(), 1u);
  EXPECT_EQ(p.moves[0].kind, MotionKind::dwell);
  EXPECT_EQ(p.moves[0].dwell_s, 1.5);
  expect_near(p.moves[0].start_m, Vector3d(0.001, 0.002, 0.003));
}

TEST(KrlReader, SprutCamStyleRasterWithForLoop) {
  KrlOptions options = options_with(corpus("krl/raster_for.dat"));
  Eigen::Isometry3d base = Eigen::Isometry3d::Identity();
  base.translation() = Vector3d(1.0, 2.0, 0.0);
  options.bases[2] = base;
  const Program p = read_krl(corpus("krl/raster_for.src"), options);
  ASSERT_EQ(p.moves.size(), 9u);  // XAPPROACH is the start; P[1..8]; the lift
  expect_near(p.moves[0].start_m, Vector3d(1.0, 2.0, 0.050), 1e-15);
  expect_near(p.moves[0].end_m, Vector3d(1.0, 2.0, -0.0015), 1e-15);
  expect_near(p.moves[1].end_m, Vector3d(1.060, 2.0, -0.0015), 1e-15);
  expect_near(p.moves[7].end_m, Vector3d(1.0, 2.006, -0.0015), 1e-15);
  expect_near(p.moves[8].end_m, Vector3d(1.0, 2.006, 0.0185), 1e-15);
  for (const auto& move : p.moves) {
    EXPECT_EQ(move.feed_m_s, 0.04);
    EXPECT_EQ(move.tool, 1);
    EXPECT_EQ(move.kind, MotionKind::linear);
  }
  EXPECT_TRUE(has_note(p, "$OUT[1]"));
}

TEST(KrlReader, KukaInlineFormsRunTheStatementsInsideTheFolds) {
  KrlOptions options = options_with(corpus("krl/inline_forms.dat"));
  Eigen::Isometry3d table = Eigen::Isometry3d::Identity();
  table.translation() = Vector3d(0.5, 0.0, 0.2);
  options.bases[3] = table;  // FP1..FP3 name BASE_NO 3, TOOL_NO 2
  const Program p = read_krl(corpus("krl/inline_forms.src"), options);
  ASSERT_EQ(p.moves.size(), 3u);
  const auto& lin = p.moves[0];
  expect_near(lin.start_m, Vector3d(0.5, 0, 0.230), 1e-15);
  expect_near(lin.end_m, Vector3d(0.520, 0, 0.2), 1e-15);
  EXPECT_EQ(lin.feed_m_s, 0.2);  // BAS(#CP_PARAMS,0.2), not the fold's comment
  EXPECT_EQ(lin.tool, 2);
  const auto& circ = p.moves[1];
  EXPECT_EQ(circ.kind, MotionKind::arc);
  expect_near(circ.centre_m, Vector3d(0.520, 0.010, 0.2), 1e-12);
  EXPECT_NEAR(circ.sweep_rad * circ.normal.z(), kPi, 1e-12);
  EXPECT_EQ(circ.feed_m_s, 0.1);
  EXPECT_EQ(p.moves[2].kind, MotionKind::dwell);
  EXPECT_EQ(p.moves[2].dwell_s, 1.5);
  ASSERT_EQ(p.tool_calls.size(), 1u);
  EXPECT_EQ(p.tool_calls[0].tool, 2);
}

// WHILE, REPEAT ... UNTIL and IF on INT comparisons run as the robot would.
TEST(KrlReader, WhileRepeatAndIfOnIntComparisons) {
  const std::string dat =
      "DEFDAT test\nDECL INT N=3\nDECL FRAME P[3]\nP[1]={X 1,Y 0,Z 0,A 0,B 90,C 0}\n"
      "P[2]={X 2,Y 0,Z 0,A 0,B 90,C 0}\nP[3]={X 3,Y 0,Z 0,A 0,B 90,C 0}\nENDDAT\n";
  // WHILE over the array, then a WHILE whose condition is false at once.
  Program p =
      krl("DECL INT I\nLIN {X 0,Y 0,Z 0,A 0,B 90,C 0}\nI = 1\nWHILE I <= N\nLIN P[I]\nI = I + 1\n"
          "ENDWHILE\nWHILE (I < 2)\nLIN P[9]\nENDWHILE\n",
          dat);
  ASSERT_EQ(p.moves.size(), 3u);
  expect_near(p.moves[2].end_m, Vector3d(0.003, 0, 0));
  EXPECT_EQ(p.moves[2].line, 6);
  // REPEAT runs its body once before UNTIL is tested: K = 3, 2, 1.
  p =
      krl("DECL INT K\nLIN {X 0,Y 0,Z 0,A 0,B 90,C 0}\nK = N\nREPEAT\nLIN P[K]\nK = K - 1\n"
          "UNTIL K == 0\nK = 7\nREPEAT\nLIN P[2]\nUNTIL K>0\n",
          dat);
  ASSERT_EQ(p.moves.size(), 4u);  // UNTIL K>0 holds at once: P[2] once
  expect_near(p.moves[0].end_m, Vector3d(0.003, 0, 0));
  expect_near(p.moves[2].end_m, Vector3d(0.001, 0, 0));
  expect_near(p.moves[3].end_m, Vector3d(0.002, 0, 0));
  // IF ... ELSE ... ENDIF inside a FOR: odd and even I take different branches;
  // <> and >= compare too.
  p =
      krl("DECL INT I\nLIN {X 0,Y 0,Z 0,A 0,B 90,C 0}\nFOR I = 1 TO 3\n"
          "IF I == 2 THEN\nLIN {Z 5}\nELSE\nLIN P[I]\nENDIF\nIF I <> 2 THEN\nIF I >= 3 THEN\n"
          "LIN {Y 1}\nENDIF\nENDIF\nENDFOR\n",
          dat);
  ASSERT_EQ(p.moves.size(), 4u);
  expect_near(p.moves[0].end_m, Vector3d(0.001, 0, 0));
  expect_near(p.moves[1].end_m, Vector3d(0.001, 0, 0.005));
  expect_near(p.moves[2].end_m, Vector3d(0.003, 0, 0));
  expect_near(p.moves[3].end_m, Vector3d(0.003, 0.001, 0));
  // CONTINUE only concerns the advance run.
  EXPECT_EQ(krl("LIN {X 0,Y 0,Z 0,A 0,B 90,C 0}\nCONTINUE\nLIN {X 1}\n").moves.size(), 1u);
}

TEST(KrlReader, ConditionsThatDependOnTheRobotAreRefused) {
  auto message = [](const InputError& e) { return std::string(e.what()); };
  InputError e = error_of("LIN {X 0,Y 0,Z 0,A 0,B 90,C 0}\nWHILE $IN[3] == TRUE\nENDWHILE\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(message(e).find("WHILE $IN[3] == TRUE"), std::string::npos) << message(e);
  EXPECT_NE(message(e).find("control flow is not modelled"), std::string::npos);
  e = error_of("DECL BOOL DONE\nIF DONE THEN\nENDIF\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(message(e).find("IF DONE"), std::string::npos) << message(e);
  e = error_of("DECL INT I,J\nWHILE I < 3 AND J < 3\nENDWHILE\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(message(e).find("AND"), std::string::npos) << message(e);
  EXPECT_EQ(error_of("IF 1 < 2\nENDIF\n").line(), 2);  // no THEN
  // Blocks that do not close, or close the wrong block, fail before anything runs.
  e = error_of("LIN {X 0,Y 0,Z 0,A 0,B 90,C 0}\nWHILE 1 < 2\nLIN {X 1}\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(message(e).find("WHILE without ENDWHILE"), std::string::npos) << message(e);
  e = error_of("DECL INT I\nFOR I = 1 TO 2\nENDWHILE\nENDFOR\n");
  EXPECT_EQ(e.line(), 4);
  EXPECT_NE(message(e).find("the FOR of line 3"), std::string::npos) << message(e);
  EXPECT_EQ(error_of("IF 1 < 2 THEN\nELSE\nELSE\nENDIF\n").line(), 4);
  EXPECT_EQ(error_of("UNTIL 1 > 0\n").line(), 2);
  // A loop that never ends is stopped by the bound on unrolled statements.
  KrlOptions options = options_with();
  options.max_executed_statements = 1000;
  try {
    read_krl(
        "DEF t( )\nDECL INT I\nLIN {X 0,Y 0,Z 0,A 0,B 90,C 0}\nWHILE I < 1\nLIN {X 1}\n"
        "ENDWHILE\nEND\n",
        options);
    ADD_FAILURE() << "an endless WHILE was read";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("more than 1000"), std::string::npos);
  }
}

TEST(KrlReader, RealSpeedsPositionCopiesAndFrameComponents) {
  const std::string dat =
      "DEFDAT test\nDECL REAL FEED=0.05\nDECL FRAME P[2]\nP[1]={X 1,Y 0,Z 0,A 0,B 90,C 0}\n"
      "P[2]={X 2,Y 0,Z 0,A 0,B 90,C 0}\nDECL FRAME XT\nENDDAT\n";
  Program p =
      krl("$VEL.CP = FEED\nLIN P[1]\nXT = P[2]\nLIN XT\nFEED = 0.1\n$VEL.CP=FEED\n"
          "LIN P[1]\n",
          dat);
  ASSERT_EQ(p.moves.size(), 2u);
  EXPECT_EQ(p.moves[0].feed_m_s, 0.05);
  expect_near(p.moves[0].end_m, Vector3d(0.002, 0, 0));
  EXPECT_EQ(p.moves[1].feed_m_s, 0.1);
  // A REAL given an expression has no known value any more.
  EXPECT_EQ(error_of("FEED = FEED * 2\n$VEL.CP = FEED\n", dat).line(), 3);
  const InputError e = error_of("P[1].Z = 5\n", dat);
  EXPECT_EQ(e.line(), 2);
  EXPECT_NE(std::string(e.what()).find("one component of a frame"), std::string::npos) << e.what();
}

// A program that walks FRAME tables in a FOR, a WHILE and a REPEAT loop
// (tests/toolpath/krl/README.md): numbers from its .dat, by hand.
TEST(KrlReader, FrameArrayLoopProgram) {
  const std::string dat = corpus("krl/frame_array_loop.dat");
  Program p = read_krl(corpus("krl/frame_array_loop.src"), options_with(dat));
  // WAIT SEC; 12 LIN P[I] and LIN P[1]; 12 LIN P2[I] and LIN P2[1]; the
  // REPEAT pass P2[12] ... P2[1]; the lift. XSAFE is the first point.
  ASSERT_EQ(p.moves.size(), 40u);
  EXPECT_EQ(p.moves[0].kind, MotionKind::dwell);
  EXPECT_EQ(p.moves[0].dwell_s, 1.0);
  double length_m = 0.0;
  Vector3d low = Vector3d::Constant(1e9), high = Vector3d::Constant(-1e9);
  for (std::size_t n = 1; n < p.moves.size(); ++n) {
    const auto& move = p.moves[n];
    EXPECT_EQ(move.kind, MotionKind::linear) << n;
    EXPECT_EQ(move.feed_m_s, 0.02) << n;  // $VEL.CP = FEED, DECL REAL FEED=0.02
    EXPECT_EQ(move.tool, 1) << n;
    expect_near(move.axis_end, Vector3d(0, 0, 1));
    length_m += (move.end_m - move.start_m).norm();
    low = low.cwiseMin(move.end_m);
    high = high.cwiseMax(move.end_m);
  }
  // Plunge 52 mm, three 120 mm rounds of the 40 x 20 mm wall, 2 mm down, 50 mm up.
  EXPECT_NEAR(length_m, 0.464, 1e-12);
  expect_near(low, Vector3d(0, 0, -0.004));
  expect_near(high, Vector3d(0.040, 0.020, 0.046));
  expect_near(p.moves[1].start_m, Vector3d(0, 0, 0.050));
  expect_near(p.moves[14].end_m, Vector3d(0, 0, -0.004));  // LIN P2[1] in the WHILE
  EXPECT_EQ(p.moves[14].line, 34);
  expect_near(p.moves[27].end_m, Vector3d(0, 0.010, -0.004));  // REPEAT starts at P2[12]
  EXPECT_EQ(p.moves[27].line, 42);
  EXPECT_TRUE(has_note(p, "ends after a PTP to an axis position"));
  // One pass only: the ELSE branch lifts 10 mm before the final 50 mm.
  std::string one_pass = dat;
  one_pass.replace(one_pass.find("PASSES=2"), 8, "PASSES=1");
  p = read_krl(corpus("krl/frame_array_loop.src"), options_with(one_pass));
  ASSERT_EQ(p.moves.size(), 16u);
  expect_near(p.moves.back().end_m, Vector3d(0, 0, 0.058));
}

TEST(KrlReader, ControlFlowAndCallsAreRefusedByLineAndWord) {
  InputError e = error_of("LIN {X 0,Y 0,Z 0,A 0,B 90,C 0}\nWHILE TRUE\nENDWHILE\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(std::string(e.what()).find("WHILE"), std::string::npos);
  EXPECT_NE(std::string(e.what()).find("control flow is not modelled"), std::string::npos);
  e = error_of("IF $IN[1] THEN\nENDIF\n");
  EXPECT_EQ(e.line(), 2);
  EXPECT_NE(std::string(e.what()).find("IF"), std::string::npos);
  e = error_of("\nSPINDLE_ON(12000)\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(std::string(e.what()).find("SPINDLE_ON"), std::string::npos);
  EXPECT_EQ(error_of("GOTO LABEL1\n").line(), 2);
  EXPECT_EQ(error_of("SWITCH N\n").line(), 2);
}

TEST(KrlReader, OtherErrors) {
  EXPECT_EQ(error_of("LIN XP9\n").line(), 2);                                     // not declared
  EXPECT_EQ(error_of("LIN {X 10}\n").line(), 2);                                  // pose unknown
  EXPECT_EQ(error_of("DECL INT I\nFOR I=1 TO 3\nLIN {X 1}\n").line(), 3);         // no ENDFOR
  EXPECT_EQ(error_of("LIN {X 0,Y 0,Z 0,A 0,B 90,C 0}\nLIN {X 1O}\n").line(), 3);  // letter O
  EXPECT_EQ(error_of("LIN {X 0,Y 0,Z 0,A 0,B 90,C 0}\nLIN {Q 1}\n").line(), 3);
  EXPECT_EQ(error_of("LIN {X 0,Y 0,Z 0,A 0,B 90,C 0}\nCIRC {X 1},{X 2}\n").line(), 3);  // collinear
  EXPECT_EQ(error_of("$VEL.CP=-1\n").line(), 2);
  EXPECT_EQ(error_of("FROBNICATE\n").line(), 2);
  const InputError e = error_of("LIN P[3]\n", "DEFDAT test\nDECL FRAME P[5]\nENDDAT\n");
  EXPECT_EQ(e.line(), 2);
  EXPECT_NE(std::string(e.what()).find("P[3]"), std::string::npos);
  const InputError d = error_of("", "DEFDAT test\nDECL FRAME P[5]\nP[6]={X 1}\nENDDAT\n");
  EXPECT_EQ(d.field(), "test.dat");
  EXPECT_EQ(d.line(), 3);
  EXPECT_THROW(read_krl("LIN {X 1}\n", options_with()), InputError);  // no DEF
  EXPECT_THROW(read_krl("DEF t( )\n", options_with()), InputError);   // no END
}

TEST(KrlReader, UnrolledStatementsAreBounded) {
  KrlOptions options = options_with();
  options.max_executed_statements = 1000;
  EXPECT_THROW(read_krl("DEF t( )\nINT I\nLIN {X 0,Y 0,Z 0,A 0,B 90,C 0}\nFOR I=1 TO 100000\n"
                        "LIN {X 1}\nENDFOR\nEND\n",
                        options),
               InputError);
}

// The same pocket as APT (MSYS at (100, 50) turned 90°) and as KRL (RoboDK's
// inline $BASE, the same frame) must give the same tip path.
TEST(ProgramReaders, AptAndKrlPocketsAgree) {
  robomill::io::AptOptions apt_options;
  const Program apt = robomill::io::read_apt(corpus("apt/pocket.cl"), apt_options);
  const Program kuka = read_krl(corpus("krl/pocket.src"), options_with(corpus("krl/pocket.dat")));
  ASSERT_EQ(apt.moves.size(), 8u);
  ASSERT_EQ(kuka.moves.size(), apt.moves.size());
  for (std::size_t n = 0; n < apt.moves.size(); ++n) {
    SCOPED_TRACE(n);
    const auto& a = apt.moves[n];
    const auto& k = kuka.moves[n];
    EXPECT_EQ(a.kind, k.kind);
    expect_near(k.start_m, a.start_m, 1e-9);
    expect_near(k.end_m, a.end_m, 1e-9);
    expect_near(k.axis_end, a.axis_end, 1e-9);
    for (double u : {0.25, 0.5, 0.75})
      expect_near(robomill::toolpath::position_at(k, u), robomill::toolpath::position_at(a, u),
                  1e-9);
    EXPECT_NEAR(k.feed_m_s, a.feed_m_s, 1e-15);
  }
  // Spot check by hand: (40,10) in the MCS is (100 − 10, 50 + 40) in the part frame.
  expect_near(apt.moves[2].end_m, Vector3d(0.090, 0.090, -0.002), 1e-15);
}

}  // namespace

}  // namespace test_krl_reader_cpp
