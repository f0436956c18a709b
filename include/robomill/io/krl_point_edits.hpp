#pragma once
// The deflection compensation of `robomill toolpath JOB --optimize` written
// into a KUKA KRL program (issue 19 item 5; robot_path/deflection_compensation.hpp
// chooses the corrections). A KRL program keeps its points where its moves
// name them — inline in the .src (`LIN {X 45,Y 20,Z 17}`) or declared in the
// .dat (`DECL E6POS P1={…}`, array elements run by FOR loops) — and the KRL
// reader records where each move's end is written (toolpath::FrameSource).
// A correction moves the X, Y, Z of that aggregate, in the base its numbers
// are in; points added inside a line become `LIN {X …,Y …,Z …} C_DIS`
// statements before it.

#include <string>
#include <string_view>
#include <vector>

#include "robomill/io/program_writer.hpp"
#include "robomill/robot_path/deflection_compensation.hpp"
#include "robomill/toolpath/program.hpp"

namespace robomill::io {

/// Which moves' ends can move on their own (PathCorrections::corrections):
/// a straight move whose end is written whole (X, Y and Z) at a point no
/// other move ends at. Points may be added inside such a move where it runs
/// once (alone on its program line, not in a loop) with the same tool
/// orientation at both ends (an added `LIN {X, Y, Z}` keeps the orientation
/// before it). Kept, with the reason: a CIRC, a move whose end is computed
/// (…_REL), a point written without all of X, Y, Z, a point used more than
/// once (a FOR loop over one point, a home pose the program starts and ends
/// at).
robot_path::WritableMoves krl_writable_moves(const toolpath::Program& program);

struct KrlPointEdits {
  std::string src, dat;
  std::vector<PointEditResult::Skipped> skipped;  ///< moves' lines not written, and why
};

/// Each correction (`corrections[i]`: its move, the end's offset and the
/// points inside, in the program frame, SI; `program` in the program frame
/// too) written with the comment `comments[i]`: the end point's X, Y, Z in
/// its aggregate in the .src or the .dat, a `; comment` line before the
/// move's statement (or the comment after a .dat point), and the points as
/// `LIN {X …,Y …,Z …} C_DIS ; comment, point k of n` before the statement.
/// Skipped: a point whose X, Y or Z is an expression.
KrlPointEdits write_krl_point_edits(std::string_view src, std::string_view dat,
                                    const toolpath::Program& program,
                                    const std::vector<robot_path::LineCorrection>& corrections,
                                    const std::vector<std::string>& comments);

}  // namespace robomill::io
