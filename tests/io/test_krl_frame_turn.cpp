// A KRL program's frames turned about the tool axis (io/krl_frame_turn.hpp,
// issue 19 item 5): the turn lands on every Cartesian point of the .src and
// the .dat and nowhere else, reads back through the KRL reader as the same
// points with each tool x turned about its axis, and a frame that cannot be
// turned is named by file and line.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>

#include "krl_pair.hpp"
#include "robomill/analysis/program_file.hpp"
#include "robomill/io/krl_frame_turn.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/job/job.hpp"

namespace robomill::io {
namespace test_krl_frame_turn_cpp {
namespace {

namespace fs = std::filesystem;
constexpr double kDeg = std::numbers::pi / 180.0;

std::string read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

Eigen::Matrix3d abc(double a, double b, double c) {
  return (Eigen::AngleAxisd(a * kDeg, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(b * kDeg, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(c * kDeg, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// The A, B, C of the first aggregate in `text` that has them.
Eigen::Matrix3d first_orientation(const std::string& text) {
  std::smatch m;
  const std::regex frame(R"(A ([-0-9.e]+),\s*B ([-0-9.e]+),\s*C ([-0-9.e]+))");
  EXPECT_TRUE(std::regex_search(text, m, frame)) << text;
  return abc(std::stod(m[1]), std::stod(m[2]), std::stod(m[3]));
}

TEST(KrlFrameTurn, TheExamplePocketReadsBackWithEveryToolXTurned) {
  const fs::path source = fs::path(ROBOMILL_SOURCE_DIR) / "examples";
  const job::Job job = job::load_job(source / "toolpath_pocket_krl.yaml");
  const job::ToolpathSettings& settings = *job.toolpath;
  const std::string src = read(settings.file), dat = read(settings.dat_file);
  const double turn = 30.0 * kDeg;
  const KrlFrameTurn turned = turn_krl_frames(src, dat, turn, settings.tool_direction);
  EXPECT_TRUE(turned.refused.empty());
  // 2 inline PTP frames in the .src; XHOME and the 10 array points in the .dat.
  EXPECT_EQ(turned.frames, 13u);
  // B 90 with #X: the turn adds to A (C 0 at the gimbal).
  EXPECT_NE(turned.dat.find("SIDE[1]={X 15,Y 15,Z 17,A 30,B 90,C 0}"), std::string::npos)
      << turned.dat;
  EXPECT_NE(turned.src.find("PTP {X 15,Y 20,Z 25,A 30,B 90,C 0}"), std::string::npos);
  // Points without an orientation, comments, $BASE and $TOOL stay as written.
  EXPECT_NE(turned.src.find("LIN {X 45,Y 20,Z 17}"), std::string::npos);
  EXPECT_NE(turned.src.find(";FOLD INI;%{PE}"), std::string::npos);
  EXPECT_NE(turned.src.find("$BASE=BASE_DATA[1]"), std::string::npos);

  const toolpath::Program before = analysis::read_program(settings);
  const toolpath::Program after =
      testing::read_krl_pair(settings, turned.src, turned.dat, "robomill_krl_turn");
  ASSERT_EQ(before.moves.size(), after.moves.size());
  ASSERT_GT(before.moves.size(), 10u);
  for (std::size_t m = 0; m < before.moves.size(); ++m) {
    const toolpath::Move& b = before.moves[m];
    const toolpath::Move& a = after.moves[m];
    EXPECT_LT((a.end_m - b.end_m).norm(), 1e-12) << m;
    EXPECT_LT((a.axis_end - b.axis_end).norm(), 1e-12) << m;
    const Eigen::Vector3d want = Eigen::AngleAxisd(turn, b.axis_end) * b.tool_x_end;
    EXPECT_LT((a.tool_x_end - want).norm(), 1e-9) << "move " << m << " line " << a.line;
  }
}

TEST(KrlFrameTurn, AGeneralFrameTurnsAboutTheTcpAxis) {
  // R' = R Rx(−Δ) with #X, R Rz(−Δ) with #Z, whatever A, B, C were.
  const std::string src = "LIN {X 1,Y 2,Z 3,A 10,B 20,C 30} C_DIS\n";
  for (const char axis : {'x', 'z'}) {
    const KrlFrameTurn turned = turn_krl_frames(src, "", 45.0 * kDeg, axis);
    ASSERT_EQ(turned.frames, 1u);
    const Eigen::Vector3d local = axis == 'z' ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
    const Eigen::Matrix3d want = abc(10, 20, 30) * Eigen::AngleAxisd(-45.0 * kDeg, local);
    EXPECT_LT((first_orientation(turned.src) - want).norm(), 1e-8) << turned.src;
    EXPECT_NE(turned.src.find("{X 1,Y 2,Z 3,"), std::string::npos);
    EXPECT_NE(turned.src.find("} C_DIS"), std::string::npos);
  }
}

TEST(KrlFrameTurn, FramesThatCannotBeTurnedAreNamedAndPlacementsKept) {
  const std::string src =
      "$TOOL={X 0,Y 0,Z 350,A 0,B 90,C 0}\n"
      "BASE_DATA[2]={X 100,Y 0,Z 0,A 45,B 0,C 0}\n"
      "LIN {X 1,Y 2,Z 3,A 10,B 90,C 0}\n"
      "LIN {A 20}\n"
      "LIN {X 1,Y 2,Z 3,A ANGLE+1,B 90,C 0}\n"
      "PTP {A1 0,A2 -90,A3 90,A4 0,A5 0,A6 0}\n";
  const KrlFrameTurn turned = turn_krl_frames(src, "", 10.0 * kDeg, 'x');
  EXPECT_EQ(turned.frames, 1u);
  ASSERT_EQ(turned.refused.size(), 2u);
  EXPECT_EQ(turned.refused[0].line, 4);
  EXPECT_NE(turned.refused[0].reason.find("partial orientation"), std::string::npos);
  EXPECT_EQ(turned.refused[1].line, 5);
  EXPECT_NE(turned.refused[1].reason.find("expression"), std::string::npos);
  EXPECT_NE(turned.src.find("$TOOL={X 0,Y 0,Z 350,A 0,B 90,C 0}"), std::string::npos);
  EXPECT_NE(turned.src.find("BASE_DATA[2]={X 100,Y 0,Z 0,A 45,B 0,C 0}"), std::string::npos);
  EXPECT_NE(turned.src.find("PTP {A1 0,A2 -90,A3 90,A4 0,A5 0,A6 0}"), std::string::npos);
  EXPECT_NE(turned.src.find("LIN {X 1,Y 2,Z 3,A 20,B 90,C 0}"), std::string::npos) << turned.src;
}

// Each frame by its own angle (a schedule ψ(s)): the KRL reader records
// where every move's end frame is written (toolpath::FrameSource), and
// turn_krl_frames turns just those sites. On the example pocket: the two
// inline PTP frames by 15°, the partial LIN of the slot completed with the
// orientation it inherits turned by 90°, the .dat's SIDE points by 90° and
// FINISH left as they were. Read back, every move ends with its tool x
// turned by its own frame's angle (the ramp's partial frame inherits the
// PTP's 15°, the FINISH points keep 0°).
TEST(KrlFrameTurn, EachFrameByItsOwnAngleFromTheSitesTheReaderRecords) {
  const fs::path source = fs::path(ROBOMILL_SOURCE_DIR) / "examples";
  const job::Job job = job::load_job(source / "toolpath_pocket_krl.yaml");
  const job::ToolpathSettings& settings = *job.toolpath;
  const std::string src = read(settings.file), dat = read(settings.dat_file);
  const toolpath::Program before = analysis::read_program(settings);
  // The sites: XHOME (.dat line 4) is the first point; the PTPs on .src lines
  // 19-20; the ramp and the slot (lines 23, 26) partial; SIDE[1..5] on .dat
  // lines 7-11, FINISH on 13-17; the last PTP partial, then XHOME again.
  ASSERT_TRUE(before.first_frame.has_value());
  EXPECT_EQ(before.first_frame->site, (toolpath::FrameSite{true, 4, 0}));
  ASSERT_EQ(before.frame_sources.size(), before.moves.size());
  std::map<toolpath::FrameSite, KrlFrameEdit> edits;
  std::vector<double> expected(before.moves.size(), 0.0);
  double inherited = 0.0;
  for (std::size_t m = 0; m < before.moves.size(); ++m) {
    const auto& source = before.frame_sources[m];
    ASSERT_TRUE(source.has_value()) << m;
    const int line = source->site.line;
    double turn = inherited;
    if (!source->site.in_dat && (line == 19 || line == 20)) {
      EXPECT_TRUE(source->complete);
      turn = 15.0 * kDeg;
      edits[source->site] = {turn, std::nullopt};
    } else if (!source->site.in_dat && line == 26) {
      EXPECT_FALSE(source->complete);
      EXPECT_NEAR(source->abc_deg[1], 90.0, 1e-12);  // the B it inherits
      turn = 90.0 * kDeg;
      edits[source->site] = {turn, source->abc_deg};
    } else if (source->site.in_dat && line >= 7 && line <= 11) {
      turn = 90.0 * kDeg;
      edits[source->site] = {turn, std::nullopt};
    } else if (source->site.in_dat && line >= 13 && line <= 17) {
      turn = 0.0;
    } else if (!source->complete) {
      EXPECT_TRUE(line == 23 || line == 36) << line;  // inherits the frame before
    }
    expected[m] = inherited = turn;
  }
  const KrlFrameTurn turned = turn_krl_frames(src, dat, edits, settings.tool_direction);
  EXPECT_TRUE(turned.refused.empty());
  EXPECT_EQ(turned.frames, 8u);  // 2 PTPs, the slot, 5 SIDE points
  EXPECT_NE(turned.src.find("PTP {X 15,Y 20,Z 21,A 15,B 90,C 0}"), std::string::npos);
  EXPECT_NE(turned.src.find("LIN {X 45,Y 20,Z 17}"), std::string::npos);
  EXPECT_NE(turned.src.find("LIN {X 15,Y 20,Z 17,A 90,B 90,C 0}"), std::string::npos) << turned.src;
  EXPECT_NE(turned.dat.find("SIDE[5]={X 15,Y 20,Z 17,A 90,B 90,C 0}"), std::string::npos);
  EXPECT_NE(turned.dat.find("FINISH[1]={X 15,Y 13,Z 17,A 0,B 90,C 0}"), std::string::npos);

  const toolpath::Program after =
      testing::read_krl_pair(settings, turned.src, turned.dat, "robomill_krl_turn_each");
  ASSERT_EQ(before.moves.size(), after.moves.size());
  for (std::size_t m = 0; m < before.moves.size(); ++m) {
    const toolpath::Move& b = before.moves[m];
    const toolpath::Move& a = after.moves[m];
    EXPECT_LT((a.end_m - b.end_m).norm(), 1e-12) << m;
    const Eigen::Vector3d want = Eigen::AngleAxisd(expected[m], b.axis_end) * b.tool_x_end;
    EXPECT_LT((a.tool_x_end - want).norm(), 1e-9) << "move " << m << " line " << a.line;
  }
  // A site without all of A, B, C and no orientation in force: refused.
  const KrlFrameTurn partial = turn_krl_frames(
      "LIN {X 1,Y 2,Z 3}\n", "", {{toolpath::FrameSite{false, 1, 0}, {0.1, std::nullopt}}}, 'x');
  ASSERT_EQ(partial.refused.size(), 1u);
  EXPECT_EQ(partial.refused[0].line, 1);
}

}  // namespace
}  // namespace test_krl_frame_turn_cpp
}  // namespace robomill::io
