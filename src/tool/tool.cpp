#include "robomill/tool/tool.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace robomill::tool {
namespace {

void require(bool condition, const std::string& message) {
  if (!condition)
    throw std::invalid_argument(message);
}

}  // namespace

const char* type_name(ToolType type) noexcept {
  switch (type) {
    case ToolType::ball:
      return "ball";
    case ToolType::bull:
      return "bull";
    default:
      return "flat";
  }
}

Tool::Tool(const ToolSpec& spec) : spec_(spec) {
  constexpr double max_helix_rad = 80.0 * std::numbers::pi / 180.0;
  require(std::isfinite(spec.diameter_m) && spec.diameter_m > 0.0,
          "diameter must be positive, got " + std::to_string(spec.diameter_m) + " m");
  require(spec.teeth >= 1, "teeth must be at least 1, got " + std::to_string(spec.teeth));
  require(std::isfinite(spec.helix_rad) && spec.helix_rad >= 0.0 && spec.helix_rad <= max_helix_rad,
          "helix must lie in [0, 80] deg");
  require(std::isfinite(spec.overhang_m) && spec.overhang_m > 0.0, "overhang must be positive");
  require(spec.type != ToolType::ball || spec.overhang_m >= radius_m(),
          "a ball-end mill's overhang must be at least its radius");
  require(spec.type != ToolType::bull ||
              (std::isfinite(spec.corner_radius_m) && spec.corner_radius_m > 0.0 &&
               spec.corner_radius_m <= radius_m() * (1.0 + 1e-12)),
          "a bull-nose end mill's corner radius must lie in (0, R], got " +
              std::to_string(spec.corner_radius_m * 1e3) + " mm");
  require(spec.type != ToolType::bull || spec.overhang_m >= spec.corner_radius_m,
          "a bull-nose end mill's overhang must be at least its corner radius");
  require(std::isfinite(spec.youngs_modulus_pa) && spec.youngs_modulus_pa > 0.0,
          "Young's modulus must be positive");
  require(std::isfinite(spec.runout.offset_m) && spec.runout.offset_m >= 0.0 &&
              spec.runout.offset_m < radius_m(),
          "runout offset must lie in [0, radius)");
  require(std::isfinite(spec.runout.angle_rad), "runout angle must be finite");
}

double Tool::pitch_angle_rad(int tooth) const noexcept {
  return 2.0 * std::numbers::pi * tooth / spec_.teeth;
}

double Tool::corner_radius_m() const noexcept {
  switch (spec_.type) {
    case ToolType::ball:
      return radius_m();
    case ToolType::bull:
      return std::min(spec_.corner_radius_m, radius_m());
    default:
      return 0.0;
  }
}

double Tool::axial_immersion_rad(double height_m) const noexcept {
  const double corner = corner_radius_m();
  if (corner <= 0.0 || height_m >= corner)
    return 0.5 * std::numbers::pi;
  // 001 Eq 1 on the ball, z = R (1 − cos κ) measured from the tip; on a torus
  // corner the corner's circle, z = r_c (1 − cos κ).
  return std::acos(std::clamp(1.0 - height_m / corner, -1.0, 1.0));
}

double Tool::edge_radius_m(double height_m) const noexcept {
  const double corner = corner_radius_m();
  if (corner <= 0.0 || height_m >= corner)
    return radius_m();
  return radius_m() - corner + corner * std::sin(axial_immersion_rad(height_m));
}

double Tool::lag_angle_rad(double height_m) const noexcept {
  return height_m * std::tan(spec_.helix_rad) / radius_m();
}

double Tool::edge_radius_with_runout_m(int tooth, double height_m) const noexcept {
  // The tool axis sits at ρ e(λ) from the spindle axis, rotating with it; the
  // edge point is at r e(θ) from the tool axis, θ = φp_j (the lag is common to
  // all teeth at one height and cancels in tooth-to-tooth differences).
  const double edge_radius = edge_radius_m(height_m);
  const double offset = spec_.runout.offset_m;
  const double relative_angle = pitch_angle_rad(tooth) - spec_.runout.angle_rad;
  return std::sqrt(edge_radius * edge_radius + offset * offset +
                   2.0 * edge_radius * offset * std::cos(relative_angle));
}

std::vector<EdgeElement> discretize_edge(const Tool& tool, double axial_depth_m, int count) {
  return discretize_edge(tool, 0.0, axial_depth_m, count);
}

std::vector<EdgeElement> discretize_edge(const Tool& tool, double from_m, double to_m, int count) {
  if (!(to_m > 0.0))
    throw std::invalid_argument("axial depth must be positive");
  if (to_m > tool.overhang_m() * (1.0 + 1e-12)) {
    throw std::invalid_argument("axial depth exceeds the tool overhang");
  }
  if (!(from_m >= 0.0 && from_m < to_m))
    throw std::invalid_argument("the edge's lower end must lie in [0, axial depth)");
  if (count < 1)
    throw std::invalid_argument("need at least one axial element");

  const double radius = tool.radius_m();
  const double corner = tool.corner_radius_m();
  std::vector<EdgeElement> elements;
  elements.reserve(static_cast<std::size_t>(count) + 1);

  // Ball nose or torus corner: equal steps of κ, i.e. equal arc length.
  // Uniform steps in z would resolve the tip badly, where the edge runs
  // almost radially and db = dz / sin κ is singular. On the corner
  // z = r_c (1 − cos κ).
  auto kappa_at = [&](double height_m) {
    return std::acos(std::clamp(1.0 - height_m / corner, -1.0, 1.0));
  };
  const double corner_from_m = corner > 0.0 ? std::min(from_m, corner) : 0.0;
  const double corner_to_m = corner > 0.0 ? std::min(to_m, corner) : 0.0;
  const double kappa_min = corner_to_m > corner_from_m ? kappa_at(corner_from_m) : 0.0;
  const double kappa_max = corner_to_m > corner_from_m ? kappa_at(corner_to_m) : 0.0;
  const double ball_arc_m = corner * (kappa_max - kappa_min);
  const double cylinder_from_m = std::max(from_m, corner_to_m);
  const double cylinder_depth_m = std::max(0.0, to_m - cylinder_from_m);
  int ball_count = 0;
  if (ball_arc_m > 0.0) {
    const double share = ball_arc_m / (ball_arc_m + cylinder_depth_m);
    ball_count = std::clamp(static_cast<int>(std::lround(share * count)), 1, count);
  }
  // A cylinder too short for a share of the count (a bull nose whose corner
  // is almost R, a depth just past a ball) gets one element of its own on top
  // of the corner's: taking it from the corner would coarsen the κ steps
  // where the edge's direction changes fastest.
  const int cylinder_count = cylinder_depth_m > 0.0 ? std::max(count - ball_count, 1) : 0;

  for (int k = 0; k < ball_count; ++k) {
    const double kappa_low = kappa_min + (kappa_max - kappa_min) * k / ball_count;
    const double kappa_high = kappa_min + (kappa_max - kappa_min) * (k + 1) / ball_count;
    EdgeElement element;
    element.kappa_rad = 0.5 * (kappa_low + kappa_high);
    element.height_m = corner * (1.0 - std::cos(element.kappa_rad));
    element.axial_length_m = corner * (std::cos(kappa_low) - std::cos(kappa_high));
    element.chip_width_m = corner * (kappa_high - kappa_low);  // exact arc length
    element.radius_m = radius - corner + corner * std::sin(element.kappa_rad);
    element.lag_rad = tool.lag_angle_rad(element.height_m);
    elements.push_back(element);
  }
  for (int k = 0; k < cylinder_count; ++k) {
    const double dz = cylinder_depth_m / cylinder_count;
    EdgeElement element;
    element.height_m = cylinder_from_m + (k + 0.5) * dz;
    element.axial_length_m = dz;
    element.kappa_rad = 0.5 * std::numbers::pi;
    element.chip_width_m = dz;  // db = dz / sin κ with κ = π/2
    element.radius_m = radius;
    element.lag_rad = tool.lag_angle_rad(element.height_m);
    elements.push_back(element);
  }
  return elements;
}

}  // namespace robomill::tool
