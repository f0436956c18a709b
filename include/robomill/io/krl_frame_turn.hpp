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

#include <string>
#include <string_view>
#include <vector>

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

}  // namespace robomill::io
