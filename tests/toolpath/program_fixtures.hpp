#pragma once
// What the program-analysis tests share: the 10 mm three-flute end mill,
// aluminium 7075's linear law and a straight move (SI units).

#include <cmath>
#include <numbers>

#include "robomill/cutting/cutting_law.hpp"
#include "robomill/tool/tool.hpp"
#include "robomill/toolpath/program.hpp"

namespace robomill::toolpath::fixtures {

inline tool::Tool flat_tool(double diameter_m = 10e-3, int teeth = 3, double helix_deg = 30.0) {
  tool::ToolSpec spec;
  spec.type = tool::ToolType::flat;
  spec.diameter_m = diameter_m;
  spec.teeth = teeth;
  spec.helix_rad = helix_deg * std::numbers::pi / 180.0;
  spec.overhang_m = 40e-3;
  return tool::Tool(spec);
}

/// Aluminium 7075 with a three-flute carbide end mill (typical values).
inline cutting::CuttingLaw aluminium() {
  cutting::LinearLaw law;
  law.Ktc_pa = 796e6;
  law.Krc_pa = 169e6;
  law.Kac_pa = 223e6;
  law.Kte_n_per_m = 27.7e3;
  law.Kre_n_per_m = 15.4e3;
  law.Kae_n_per_m = 1.2e3;
  return law;
}

/// A straight move (a rapid has no feed).
inline Move line_move(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double feed_m_s,
                      double spindle_rad_s, MotionKind kind = MotionKind::linear, int line = 1) {
  Move move;
  move.kind = kind;
  move.start_m = from;
  move.end_m = to;
  move.feed_m_s = kind == MotionKind::rapid ? 0.0 : feed_m_s;
  move.spindle_rad_s = spindle_rad_s;
  move.line = line;
  return move;
}

}  // namespace robomill::toolpath::fixtures
