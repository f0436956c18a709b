// The deflection compensation written into a KRL program
// (io/krl_point_edits.hpp): a move's end moves where its point is written —
// inline in the .src or in the .dat — in the base its numbers are in, points
// go before a line that runs once as LIN statements, and a point that ends
// several moves stays, named with the reason. Read back through the KRL
// reader: the moved ends and the added points exactly, every other move as
// it was.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "krl_pair.hpp"
#include "robomill/analysis/program_file.hpp"
#include "robomill/io/krl_point_edits.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/job/job.hpp"

namespace robomill::io {
namespace test_krl_point_edits_cpp {
namespace {

namespace fs = std::filesystem;

std::string read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(KrlPointEdits, EndsMoveWhereTheirPointsAreWrittenAndReadBack) {
  const fs::path source = fs::path(ROBOMILL_SOURCE_DIR) / "examples";
  const job::Job job = job::load_job(source / "toolpath_pocket_krl.yaml");
  job::ToolpathSettings settings = *job.toolpath;
  // Base 1 turned and shifted, so that offsets must be taken into it.
  Eigen::Isometry3d base = Eigen::Isometry3d::Identity();
  base.translate(Eigen::Vector3d(0.1, -0.05, 0.02));
  base.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 0.3, 1.0).normalized()));
  settings.bases[1] = base;
  const std::string src = read(settings.file), dat = read(settings.dat_file);
  toolpath::Program program = analysis::read_program(settings);
  toolpath::apply_transform(program, settings.program_to_workpiece.inverse());

  const robot_path::WritableMoves writable = krl_writable_moves(program);
  ASSERT_EQ(writable.end.size(), program.moves.size());
  int inline_lines = 0, loop_points = 0, home = 0;
  for (std::size_t m = 0; m < program.moves.size(); ++m) {
    const toolpath::Move& move = program.moves[m];
    if (move.line == 23 || move.line == 26) {  // the ramp and the slot, inline
      EXPECT_TRUE(writable.end[m] && writable.points[m]) << move.line;
      ++inline_lines;
    } else if (move.line == 29 || move.line == 34) {  // the FOR loops over .dat points
      EXPECT_TRUE(writable.end[m] && !writable.points[m]) << move.line;
      ++loop_points;
    } else if (move.line == 37) {  // PTP XHOME, the first point too
      EXPECT_FALSE(writable.end[m]);
      EXPECT_NE(writable.reason[m].find("used more than once"), std::string::npos);
      ++home;
    }
  }
  EXPECT_EQ(inline_lines, 2);
  EXPECT_EQ(loop_points, 10);
  EXPECT_EQ(home, 1);

  // The slot (line 26) moved with two points inside; SIDE[2] (the loop's
  // second move) moved at its end.
  std::vector<robot_path::LineCorrection> corrections;
  std::size_t slot = 0, side2 = 0;
  int side_seen = 0;
  for (std::size_t m = 0; m < program.moves.size(); ++m) {
    if (program.moves[m].line == 26)
      slot = m;
    if (program.moves[m].line == 29 && ++side_seen == 2)
      side2 = m;
  }
  const Eigen::Vector3d end_offset(12e-6, -30e-6, 4e-6), point_offset(5e-6, -20e-6, 0.0);
  corrections.push_back({slot, 26, end_offset, {{0.25, point_offset}, {0.75, end_offset}}, {}});
  corrections.push_back({side2, 29, -end_offset, {}, {}});
  const KrlPointEdits edited =
      write_krl_point_edits(src, dat, program, corrections, {"robomill: test", "robomill: test"});
  EXPECT_TRUE(edited.skipped.empty());
  EXPECT_NE(edited.src.find("; robomill: test\nLIN {X"), std::string::npos) << edited.src;
  EXPECT_NE(edited.dat.find("} ; robomill: test"), std::string::npos) << edited.dat;

  toolpath::Program after =
      testing::read_krl_pair(settings, edited.src, edited.dat, "robomill_krl_points");
  toolpath::apply_transform(after, settings.program_to_workpiece.inverse());
  const std::vector<Eigen::Vector3d> expected = robot_path::corrected_ends(program, corrections);
  ASSERT_EQ(after.moves.size(), expected.size());
  for (std::size_t m = 0; m < after.moves.size(); ++m)
    EXPECT_LT((after.moves[m].end_m - expected[m]).norm(), 1e-9)
        << "move " << m << " line " << after.moves[m].line;
}

}  // namespace
}  // namespace test_krl_point_edits_cpp
}  // namespace robomill::io
