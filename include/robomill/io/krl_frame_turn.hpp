#pragma once
// A KUKA KRL program's frames turned about the tool axis (issue 19 item 5):
// the redundancy angle ψ that `robomill toolpath --optimize` chooses for a
// KRL program, written where a KRL program keeps it — in the A, B, C of
// every Cartesian point it moves to (docs/toolpath.md, "ψ from a KRL
// program").
//
// KUKA writes a frame's orientation as A, B, C: R = Rz(A) Ry(B) Rx(C). The
// tool axis is the TCP frame's `tool_direction` axis (X by default, the
// spindle pointing along −X), so turning ψ by Δ about the axis (tip →
// spindle, robomill's sign) is R' = R Rx(−Δ) with #X, R Rz(−Δ) with #Z.
// The positions (X, Y, Z) and everything else stay as written.

#include <array>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "robomill/toolpath/program.hpp"

namespace robomill::io {

struct KrlFrameTurn {
  std::string src, dat;    ///< the texts with the turned frames
  std::size_t frames = 0;  ///< aggregates turned (in both texts)
  /// Aggregates that would need turning but cannot be: their file ("src" or
  /// "dat"), line and the reason (a partial orientation {A 10}, a value
  /// written as an expression). A program with any is not turned.
  struct Refused {
    std::string file;
    int line = 0;
    std::string reason;
  };
  std::vector<Refused> refused;
};

/// Every aggregate `{…}` with the components A, B and C in the .src and .dat
/// texts, except the frames assigned to $BASE, $TOOL, BASE_DATA[…] and
/// TOOL_DATA[…] (they place the tool's frames, not its path), gets the A, B,
/// C of the turned orientation (9 significant digits; at B = ±90° the
/// equivalent with C = 0). Axis aggregates (E6AXIS: A1 … A6) have no A, B, C
/// and stay. An E6POS's S and T bits are kept: a turn that moves joint 6
/// across 0 may need another T at a PTP point.
KrlFrameTurn turn_krl_frames(std::string_view src, std::string_view dat, double turn_rad,
                             char tool_direction);

/// One frame's turn (a redundancy schedule ψ(s)): by `turn_rad` about the
/// tool axis. A frame written without all of A, B, C (`LIN {X 45, Y 20, Z
/// 17}` keeps the orientation before it) gets the turn of `in_force_abc_deg`,
/// the orientation it inherits, its missing components appended.
struct KrlFrameEdit {
  double turn_rad = 0.0;
  std::optional<std::array<double, 3>> in_force_abc_deg;
};

/// Each frame by its own angle: the Cartesian aggregate at each site of
/// `edits` (toolpath::FrameSite, as the KRL reader records where each move's
/// end frame is written) turned, every other one kept. Refused: a listed
/// aggregate whose A, B or C is an expression, or that lacks some of them
/// with no orientation in force given.
KrlFrameTurn turn_krl_frames(std::string_view src, std::string_view dat,
                             const std::map<toolpath::FrameSite, KrlFrameEdit>& edits,
                             char tool_direction);

}  // namespace robomill::io
