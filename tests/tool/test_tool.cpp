#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "robomill/tool/tool.hpp"

namespace test_tool_cpp {

namespace {

using robomill::tool::discretize_edge;
using robomill::tool::Tool;
using robomill::tool::ToolSpec;
using robomill::tool::ToolType;

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

ToolSpec ball_spec() {
  // 001 §3.2: 8 mm two-flute ball-end mill, 45° helix, 25 mm cutter length.
  ToolSpec spec;
  spec.type = ToolType::ball;
  spec.diameter_m = 8e-3;
  spec.teeth = 2;
  spec.helix_rad = 45.0 * kDeg;
  spec.overhang_m = 25e-3;
  return spec;
}

TEST(Tool, RejectsNonPhysicalSpecs) {
  ToolSpec spec = ball_spec();
  spec.diameter_m = 0.0;
  EXPECT_THROW(Tool{spec}, std::invalid_argument);
  spec = ball_spec();
  spec.teeth = -2;
  EXPECT_THROW(Tool{spec}, std::invalid_argument);
  spec = ball_spec();
  spec.helix_rad = 85.0 * kDeg;
  EXPECT_THROW(Tool{spec}, std::invalid_argument);
  spec = ball_spec();
  spec.overhang_m = 3e-3;  // shorter than the ball radius
  EXPECT_THROW(Tool{spec}, std::invalid_argument);
  spec = ball_spec();
  spec.runout.offset_m = 4e-3;  // as large as the radius
  EXPECT_THROW(Tool{spec}, std::invalid_argument);
  spec = ball_spec();
  spec.diameter_m = std::nan("");
  EXPECT_THROW(Tool{spec}, std::invalid_argument);
}

TEST(Tool, PitchAnglesAreEqual) {  // 001 Eq 2
  ToolSpec spec = ball_spec();
  spec.teeth = 3;
  const Tool tool(spec);
  EXPECT_DOUBLE_EQ(tool.pitch_angle_rad(0), 0.0);
  EXPECT_NEAR(tool.pitch_angle_rad(1), 2.0 * kPi / 3.0, 1e-15);
  EXPECT_NEAR(tool.pitch_angle_rad(2), 4.0 * kPi / 3.0, 1e-15);
}

TEST(Tool, BallNoseGeometryFollowsPaper001) {
  const Tool tool(ball_spec());
  const double radius = 4e-3;
  for (double kappa_deg : {10.0, 30.0, 60.0, 89.0}) {
    const double kappa = kappa_deg * kDeg;
    const double height = radius * (1.0 - std::cos(kappa));  // 001 Eq 1, z from the tip
    EXPECT_NEAR(tool.axial_immersion_rad(height), kappa, 1e-12);
    EXPECT_NEAR(tool.edge_radius_m(height), radius * std::sin(kappa), 1e-15);
    // 001 Eq 3: ψ = tan β0 (1 − cos κ).
    EXPECT_NEAR(tool.lag_angle_rad(height), std::tan(45.0 * kDeg) * (1.0 - std::cos(kappa)), 1e-12);
  }
  // Above the ball the edge is cylindrical.
  EXPECT_DOUBLE_EQ(tool.edge_radius_m(6e-3), radius);
  EXPECT_DOUBLE_EQ(tool.axial_immersion_rad(6e-3), kPi / 2.0);
}

TEST(Tool, FlatEndMillLagIsZTanBetaOverR) {  // 000 Eq 11, 004 Eq 3
  ToolSpec spec;
  spec.diameter_m = 24e-3;
  spec.teeth = 2;
  spec.helix_rad = kPi / 3.0;
  spec.overhang_m = 60e-3;
  const Tool tool(spec);
  EXPECT_NEAR(tool.lag_angle_rad(2e-3), 2e-3 * std::tan(kPi / 3.0) / 12e-3, 1e-15);
  EXPECT_DOUBLE_EQ(tool.edge_radius_m(0.0), 12e-3);
}

TEST(Tool, RunoutMovesTeethRadially) {  // 001 Eq 4
  ToolSpec spec = ball_spec();
  spec.runout = {0.02e-3, 0.0};  // 001 §3.3: 0.02 mm radial runout
  const Tool tool(spec);
  const double height = 5e-3;  // cylindrical part, r = R
  // Tooth 0 points along the offset, tooth 1 opposite to it.
  EXPECT_NEAR(tool.edge_radius_with_runout_m(0, height), 4e-3 + 0.02e-3, 1e-15);
  EXPECT_NEAR(tool.edge_radius_with_runout_m(1, height), 4e-3 - 0.02e-3, 1e-15);
  spec.runout.angle_rad = kPi / 2.0;  // offset perpendicular: both teeth equal
  const Tool turned(spec);
  EXPECT_NEAR(turned.edge_radius_with_runout_m(0, height),
              turned.edge_radius_with_runout_m(1, height), 1e-15);
}

TEST(EdgeDiscretization, CoversTheDepthAndTheBallArc) {
  const Tool tool(ball_spec());
  const double radius = 4e-3;
  const auto elements = discretize_edge(tool, radius, 2000);
  double depth = 0.0, arc = 0.0;
  for (const auto& element : elements) {
    depth += element.axial_length_m;
    arc += element.chip_width_m;
  }
  EXPECT_NEAR(depth, radius, 1e-15);
  // Chip widths db = dz / sin κ add up to the edge's arc length R·π/2.
  EXPECT_NEAR(arc, radius * kPi / 2.0, 1e-3 * radius * kPi / 2.0);
  EXPECT_THROW(discretize_edge(tool, 30e-3, 10), std::invalid_argument);  // beyond overhang
  EXPECT_THROW(discretize_edge(tool, 1e-3, 0), std::invalid_argument);
}

// Issue 31, point 2: a bull-nose (torus) end mill. Its corner is a quarter
// circle of radius r_c centred at radius R − r_c, height r_c: 001 Eq 1 with
// the corner's circle, z = r_c (1 − cos κ), r = R − r_c + r_c sin κ.
ToolSpec bull_spec(double corner_m) {
  ToolSpec spec;
  spec.type = ToolType::bull;
  spec.diameter_m = 12e-3;
  spec.teeth = 4;
  spec.helix_rad = 30.0 * kDeg;
  spec.overhang_m = 40e-3;
  spec.corner_radius_m = corner_m;
  return spec;
}

TEST(Tool, BullNoseCornerFollowsItsCircle) {
  const Tool tool(bull_spec(2e-3));
  EXPECT_DOUBLE_EQ(tool.corner_radius_m(), 2e-3);
  const double kappa = 35.0 * kDeg, z = 2e-3 * (1.0 - std::cos(kappa));
  EXPECT_NEAR(tool.axial_immersion_rad(z), kappa, 1e-12);
  EXPECT_NEAR(tool.edge_radius_m(z), 4e-3 + 2e-3 * std::sin(kappa), 1e-15);
  EXPECT_DOUBLE_EQ(tool.axial_immersion_rad(2.5e-3), 0.5 * kPi);
  EXPECT_DOUBLE_EQ(tool.edge_radius_m(2.5e-3), 6e-3);
  // The flat and ball ends as the corner's limits.
  EXPECT_DOUBLE_EQ(Tool(ball_spec()).corner_radius_m(), 4e-3);
  ToolSpec flat = bull_spec(0.0);
  flat.type = ToolType::flat;
  EXPECT_DOUBLE_EQ(Tool(flat).corner_radius_m(), 0.0);
  // Not a bull nose: no corner, or one larger than the radius.
  EXPECT_THROW(Tool(bull_spec(0.0)), std::invalid_argument);
  EXPECT_THROW(Tool(bull_spec(6.1e-3)), std::invalid_argument);
  EXPECT_THROW(Tool(bull_spec(-1e-3)), std::invalid_argument);
  EXPECT_NO_THROW(Tool(bull_spec(6e-3)));
}

TEST(EdgeDiscretization, BullNoseCornerThenCylinder) {
  const Tool tool(bull_spec(2e-3));
  // 1.3 mm: inside the corner. The chip widths add up to r_c κ_max.
  const auto corner_only = discretize_edge(tool, 1.3e-3, 400);
  double depth = 0.0, arc = 0.0;
  for (const auto& element : corner_only) {
    depth += element.axial_length_m;
    arc += element.chip_width_m;
    EXPECT_LT(element.kappa_rad, 0.5 * kPi);
  }
  EXPECT_NEAR(depth, 1.3e-3, 1e-15);
  EXPECT_NEAR(arc, 2e-3 * std::acos(1.0 - 1.3 / 2.0), 1e-15);
  // 5 mm: the whole corner (r_c π/2) and 3 mm of cylinder.
  const auto whole = discretize_edge(tool, 5e-3, 400);
  depth = arc = 0.0;
  for (const auto& element : whole) {
    depth += element.axial_length_m;
    arc += element.chip_width_m;
  }
  EXPECT_NEAR(depth, 5e-3, 1e-15);
  EXPECT_NEAR(arc, 2e-3 * kPi / 2.0 + 3e-3, 1e-15);
  // Between two heights: the part of the edge above a tip in air.
  const auto upper = discretize_edge(tool, 1.1e-3, 4.2e-3, 300);
  depth = arc = 0.0;
  for (const auto& element : upper) {
    depth += element.axial_length_m;
    arc += element.chip_width_m;
    EXPECT_GE(element.height_m, 1.1e-3);
    EXPECT_LE(element.height_m, 4.2e-3);
  }
  EXPECT_NEAR(depth, 3.1e-3, 1e-15);
  EXPECT_NEAR(arc, 2e-3 * (0.5 * kPi - std::acos(1.0 - 1.1 / 2.0)) + 2.2e-3, 1e-15);
  EXPECT_THROW(discretize_edge(tool, 2e-3, 1e-3, 10), std::invalid_argument);
}

}  // namespace

}  // namespace test_tool_cpp
