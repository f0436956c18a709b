#pragma once
// What every program reader's fuzz target checks of an accepted program
// (toolpath/program.hpp's contract): finite coordinates, feeds, speeds and
// dwells; unit tool axes and arc normals; lines inside the program; feeds and
// dwells not negative; each move starting where the previous one ended (with
// `chained`: the G-code reader, whose moves all chain; APT and KRL may leave
// the tip unknown after an axis-space PTP or a first point); finite cutter
// sizes. A violation traps, which libFuzzer reports as a finding.

#include <Eigen/Core>
#include <cmath>
#include <cstddef>

#include "robomill/toolpath/program.hpp"

namespace robomill::fuzz {

inline bool unit(const Eigen::Vector3d& v) {
  return v.allFinite() && std::abs(v.norm() - 1.0) <= 1e-9;
}

inline void check_program(const toolpath::Program& program, bool chained) {
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (const toolpath::Move& move : program.moves) {
    if (!move.start_m.allFinite() || !move.end_m.allFinite() || !move.centre_m.allFinite() ||
        !std::isfinite(move.sweep_rad) || !std::isfinite(move.feed_m_s) ||
        !std::isfinite(move.spindle_rad_s) || !std::isfinite(move.dwell_s))
      __builtin_trap();
    if (!unit(move.axis_start) || !unit(move.axis_end))
      __builtin_trap();
    if (move.kind == toolpath::MotionKind::arc && !unit(move.normal))
      __builtin_trap();
    if (move.feed_m_s < 0.0 || move.dwell_s < 0.0 || move.line < 1 ||
        static_cast<std::size_t>(move.line) > program.line_count)
      __builtin_trap();
    if (chained && (move.start_m - previous).norm() > 1e-9 * (1.0 + previous.norm()))
      __builtin_trap();
    previous = move.end_m;
  }
  for (const toolpath::ToolCall& call : program.tool_calls)
    if ((call.diameter_m && !std::isfinite(*call.diameter_m)) ||
        (call.corner_radius_m && !std::isfinite(*call.corner_radius_m)))
      __builtin_trap();
}

}  // namespace robomill::fuzz
