// Z-map surface generation (001 §2.1, §2.3, §2.4); see topography.hpp.

#include "robomill/surface/topography.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "robomill/core/constants.hpp"
#include "robomill/core/parallel.hpp"

namespace robomill::surface {
namespace {

void require(bool condition, const std::string& message) {
  if (!condition)
    throw std::invalid_argument("surface: " + message);
}

double feed_speed(const RasterPath& path, int teeth) {
  return path.feed_per_tooth_m * teeth * path.spindle_rad_s / kTwoPi;
}

/// Rotation {S} → {W} of pass `pass`: M_WE (a half turn for zig-zag return
/// passes) times M_ES.
Eigen::Matrix3d spindle_to_workpiece(const Eigen::Matrix3d& to_engagement, const RasterPath& path,
                                     int pass) {
  if (path.pattern == RasterPattern::zigzag && pass % 2 == 1) {
    Eigen::Matrix3d half_turn = Eigen::Vector3d(-1.0, -1.0, 1.0).asDiagonal();
    return half_turn * to_engagement;
  }
  return to_engagement;
}

/// Angle θ between the tool axis and the workpiece normal.
double axis_angle(const ToolOrientation& orientation) {
  const Eigen::Vector3d axis = spindle_to_engagement(orientation) * Eigen::Vector3d::UnitZ();
  return std::acos(std::clamp(axis.z(), -1.0, 1.0));
}

/// The band of the edge that can reach within `budget` of the tool's
/// lowest point: κ range on a ball (rad), height range of a flat end's side.
struct Band {
  double from = 0.0, to = 0.0;
};

Band evaluated_band(const tool::Tool& tool, double axial_depth_m,
                    const ToolOrientation& orientation, double budget_m) {
  const double radius = tool.radius_m();
  const double theta = axis_angle(orientation);
  if (tool.type() == tool::ToolType::ball) {
    const double delta = std::acos(std::clamp(1.0 - budget_m / radius, -1.0, 1.0)) * 1.05 + 1e-4;
    return {std::max(0.0, theta - delta), std::min(0.5 * std::numbers::pi, theta + delta)};
  }
  const double cos_theta = std::max(std::cos(theta), 0.1);
  return {0.0, std::min(axial_depth_m + budget_m, budget_m / cos_theta + radius * std::sin(theta))};
}

double lateral_reach(const tool::Tool& tool, const ToolOrientation& orientation, const Band& band) {
  const double radius = tool.radius_m();
  if (tool.type() != tool::ToolType::ball)
    return 2.0 * radius + band.to;
  const double theta = axis_angle(orientation);
  return radius * std::sin(std::min(0.5 * std::numbers::pi,
                                    std::max(band.to - theta, theta - band.from) + 1e-3));
}

/// Largest horizontal and vertical deviation of the vibration from its mean, in {W}.
std::pair<double, double> vibration_ranges(const ToolOrientation& orientation,
                                           const Vibration& vibration) {
  if (vibration.empty())
    return {0.0, 0.0};
  const Eigen::Matrix3d q = spindle_to_engagement(orientation);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& u : vibration.displacement_m)
    mean += u;
  mean /= static_cast<double>(vibration.displacement_m.size());
  double lateral = 0.0, vertical = 0.0;
  for (const auto& u : vibration.displacement_m) {
    const Eigen::Vector3d w = q * (u - mean);
    lateral = std::max(lateral, std::hypot(w.x(), w.y()));
    vertical = std::max(vertical, std::abs(w.z()));
  }
  return {lateral, vertical};
}

double automatic_budget(const tool::Tool& tool, const ToolOrientation& orientation,
                        const RasterPath& path, const Vibration& vibration) {
  const double radius = tool.radius_m();
  const double theta = axis_angle(orientation);
  const auto [lateral, vertical] = vibration_ranges(orientation, vibration);
  const double per_revolution = path.feed_per_tooth_m * tool.teeth();
  const double kinematic =
      scallop_height(radius, std::min(path.stepover_m + 2.0 * lateral, 2.0 * radius)) +
      scallop_height(radius, std::min(per_revolution + 2.0 * lateral, 2.0 * radius));
  return 3.0 * kinematic + 2.0 * tool.runout().offset_m * std::sin(theta) + 4.0 * vertical + 0.5e-6;
}

double max_edge_radius(const tool::Tool& tool, const Band& band) {
  const double radius = tool.radius_m();
  const double r = tool.type() == tool::ToolType::ball ? radius * std::sin(band.to) : radius;
  return r + tool.runout().offset_m;
}

}  // namespace

double automatic_height_budget(const tool::Tool& tool, const ToolOrientation& orientation,
                               const RasterPath& path, const Vibration& vibration) {
  return automatic_budget(tool, orientation, path, vibration);
}

Eigen::Matrix3d spindle_to_engagement(const ToolOrientation& o) {
  return (Eigen::AngleAxisd(o.tilt_rad, Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(o.lead_rad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(o.redundancy_rad, Eigen::Vector3d::UnitZ()))
      .toRotationMatrix();
}

Eigen::Vector3d Vibration::at(double t_s) const noexcept {
  if (displacement_m.empty() || !(step_s > 0.0))
    return Eigen::Vector3d::Zero();
  const std::size_t n = displacement_m.size();
  if (n == 1)
    return displacement_m[0];
  const double period = step_s * static_cast<double>(n - 1);
  double t = std::fmod(t_s, period);
  if (t < 0.0)
    t += period;
  const double position = t / step_s;
  const std::size_t i = std::min(static_cast<std::size_t>(position), n - 2);
  const double w = position - static_cast<double>(i);
  return (1.0 - w) * displacement_m[i] + w * displacement_m[i + 1];
}

double Vibration::amplitude_m() const noexcept {
  if (displacement_m.empty())
    return 0.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& u : displacement_m)
    mean += u;
  mean /= static_cast<double>(displacement_m.size());
  double largest = 0.0;
  for (const auto& u : displacement_m)
    largest = std::max(largest, (u - mean).norm());
  return largest;
}

double scallop_height(double radius_m, double stepover_m) noexcept {
  const double half = 0.5 * stepover_m;
  return radius_m - std::sqrt(std::max(0.0, radius_m * radius_m - half * half));
}

Eigen::Vector3d reference_offset(const tool::Tool& tool, const ToolOrientation& orientation) {
  if (tool.type() == tool::ToolType::ball)
    return Eigen::Vector3d::Zero();
  // Flat end: the tip centre sits R sin θ above the contact plane, so that
  // the lowest point of the bottom rim touches it.
  return {0.0, 0.0, tool.radius_m() * std::sin(axis_angle(orientation))};
}

double shank_clearance_m(const tool::Tool& tool, const ToolOrientation& orientation) {
  const double radius = tool.radius_m();
  const double theta = axis_angle(orientation);
  if (tool.type() == tool::ToolType::ball)
    return radius * (1.0 - std::sin(theta));
  // A flat end's side edges reach up the whole overhang: the holder is the
  // shank, at the overhang above the tip.
  return tool.overhang_m() * std::cos(theta);
}

ResolutionRules resolution_rules(const tool::Tool& tool, double axial_depth_m,
                                 const ToolOrientation& orientation, const RasterPath& path,
                                 const ZMapGrid& grid, double height_budget_m) {
  ResolutionRules rules;
  rules.max_cell_m = std::min(path.feed_per_tooth_m, path.stepover_m) / 5.0;
  const double budget = height_budget_m > 0.0
                            ? height_budget_m
                            : automatic_budget(tool, orientation, path, Vibration{});
  const Band band = evaluated_band(tool, axial_depth_m, orientation, budget);
  rules.max_edge_radius_m = max_edge_radius(tool, band);
  rules.lateral_reach_m = lateral_reach(tool, orientation, band);
  const double cell = std::min(grid.dx(), grid.dy());
  const double v_f = feed_speed(path, tool.teeth());
  // Eq 30: (Ω r_max + v_f) Δt ≤ min(dx, dy), Δt = 2π / (Ω · steps).
  rules.min_steps_per_revolution = static_cast<int>(std::ceil(
      (kTwoPi * rules.max_edge_radius_m + v_f * kTwoPi / path.spindle_rad_s) / cell - 1e-9));
  rules.max_edge_spacing_m = cell;
  return rules;
}

Eigen::Vector3d edge_point(const tool::Tool& tool, const ToolOrientation& orientation,
                           const RasterPath& path, int pass, int tooth, double axial, double t_s) {
  const double radius = tool.radius_m();
  const Eigen::Matrix3d q = spindle_to_workpiece(spindle_to_engagement(orientation), path, pass);
  const double v_f = feed_speed(path, tool.teeth());
  const double pass_time = (path.x_end_m - path.x_start_m) / v_f;
  const double local = t_s - pass * pass_time;
  const bool back = path.pattern == RasterPattern::zigzag && pass % 2 == 1;
  const double x = back ? path.x_end_m - v_f * local : path.x_start_m + v_f * local;
  const double spin =
      path.start_angle_rad + path.spindle_rad_s * (path.restart_each_pass ? local : t_s);
  const auto& runout = tool.runout();
  const Eigen::Vector3d offset(runout.offset_m * std::sin(spin + runout.angle_rad),
                               runout.offset_m * std::cos(spin + runout.angle_rad), 0.0);
  Eigen::Vector3d v;  // from the reference point, {S}
  if (tool.type() == tool::ToolType::ball) {
    const double kappa = axial;
    const double phi =
        spin + tool.pitch_angle_rad(tooth) - std::tan(tool.helix_rad()) * (1.0 - std::cos(kappa));
    v = {radius * std::sin(kappa) * std::sin(phi), radius * std::sin(kappa) * std::cos(phi),
         -radius * std::cos(kappa)};
  } else {
    const double r = axial < 0.0 ? -axial : radius;
    const double z = axial < 0.0 ? 0.0 : axial;
    const double phi = spin + tool.pitch_angle_rad(tooth) - z * std::tan(tool.helix_rad()) / radius;
    v = {r * std::sin(phi), r * std::cos(phi), z};
  }
  const Eigen::Vector3d base(x, path.first_pass_y_m + pass * path.stepover_m,
                             tool.type() == tool::ToolType::ball ? radius : 0.0);
  return base + q * (reference_offset(tool, orientation) + offset + v);
}

namespace {

/// Everything the kernel needs, computed once.
struct Plan {
  const tool::Tool* tool = nullptr;
  const RasterPath* path = nullptr;
  const ZMapGrid* grid = nullptr;
  const Vibration* vibration = nullptr;
  bool ball = true;
  double radius = 0.0;
  int teeth = 0;
  double v_f = 0.0, pass_time = 0.0, dt = 0.0, spin_step = 0.0;
  double budget = 0.0, reach = 0.0, cell = 0.0;
  Eigen::Matrix3d to_engagement;
  Eigen::Vector3d reference;  ///< reference_offset in {E}
  // Edge samples (κ on a ball; for a flat end the bottom radii then the side heights).
  std::vector<double> sin_kappa, cos_kappa, sin_lag, cos_lag;  // ball
  std::vector<double> flat_r, flat_z;                          // flat
  std::size_t flat_bottom = 0;  ///< flat_r[0, flat_bottom) are bottom points
  std::vector<double> pitch;
  double lag_from = 0.0, lag_to = 0.0;  ///< helix lag range over the ball band
  long long steps_per_pass = 0;
};

struct Counters {
  long long points = 0, updates = 0, tests = 0;
};

/// How an edge point sweeps its neighbourhood: the horizontal part (tx, ty)
/// of its velocity per radian of spindle turn, 1 / |(tx, ty)|², and the
/// ball centre's velocity per radian (feed and runout).
struct Sweep {
  double tx = 0.0, ty = 0.0, inverse = 0.0, limit = 0.0;
  Eigen::Vector3d centre_rate = Eigen::Vector3d::Zero();
};

/// Lowers the nodes of the cell around p to the local tool surface.
template <bool Ball>
inline void lower(const Plan& plan, std::vector<double>& z, int column_from, int column_to,
                  const Eigen::Vector3d& p, const Eigen::Vector3d& centre,
                  const Eigen::Vector3d& axis, bool side, const Sweep& sweep, Counters& counters) {
  const ZMapGrid& g = *plan.grid;
  const double dx = g.dx(), dy = g.dy();
  const double fx = (p.x() - g.x0_m) / dx, fy = (p.y() - g.y0_m) / dy;
  if (fx < -1.0 || fy < -1.0 || fx > g.cells_x + 1.0 || fy > g.cells_y + 1.0)
    return;
  const int ci = static_cast<int>(std::floor(fx)), cj = static_cast<int>(std::floor(fy));
  const std::size_t stride = static_cast<std::size_t>(g.nodes_x());
  const double r2 = plan.radius * plan.radius;
  const bool steep = !Ball && (side || std::abs(axis.z()) < 0.3);
  for (int j = cj; j <= cj + 1; ++j) {
    if (j < 0 || j >= g.nodes_y())
      continue;
    const double yn = g.y0_m + j * dy;
    for (int i = ci; i <= ci + 1; ++i) {
      if (i < column_from || i >= column_to)
        continue;
      const double xn = g.x0_m + i * dx;
      double height;
      if constexpr (Ball) {
        // The edge reaches the node Δφ later (earlier) than this step, when
        // the ball centre has moved on by Δφ · dc/dφ (first order).
        double turn = ((xn - p.x()) * sweep.tx + (yn - p.y()) * sweep.ty) * sweep.inverse;
        turn = std::clamp(turn, -sweep.limit, sweep.limit);
        const double ex = xn - (centre.x() + turn * sweep.centre_rate.x());
        const double ey = yn - (centre.y() + turn * sweep.centre_rate.y());
        const double d2 = ex * ex + ey * ey;
        if (d2 >= r2)
          continue;
        height = centre.z() + turn * sweep.centre_rate.z() - std::sqrt(r2 - d2);
      } else {
        if (steep) {
          // Side of a flat end (or a bottom seen edge-on): the node nearest
          // to the point takes its height.
          if (std::abs(xn - p.x()) > 0.5 * dx || std::abs(yn - p.y()) > 0.5 * dy)
            continue;
          height = p.z();
        } else {
          height = p.z() - (axis.x() * (xn - p.x()) + axis.y() * (yn - p.y())) / axis.z();
        }
      }
      double& cell = z[static_cast<std::size_t>(j) * stride + static_cast<std::size_t>(i)];
      ++counters.tests;
      if (height < cell) {
        cell = height;
        ++counters.updates;
      }
    }
  }
}

/// Cuts every pass into the columns [column_from, column_to) of the grid.
template <bool Ball>
void cut_strip(const Plan& plan, std::vector<double>& z, int column_from, int column_to,
               int pass_from, int pass_to, Counters& counters) {
  const ZMapGrid& g = *plan.grid;
  const RasterPath& path = *plan.path;
  const tool::Tool& tool = *plan.tool;
  const double x_from = g.x0_m + (column_from - 1) * g.dx() - plan.reach;
  const double x_to = g.x0_m + column_to * g.dx() + plan.reach;
  const double y_from = g.y0_m - g.dy() - plan.reach;
  const double y_to = g.y0_m + g.length_y_m + g.dy() + plan.reach;
  const double rho = tool.runout().offset_m, lambda = tool.runout().angle_rad;
  const std::size_t band = Ball ? plan.sin_kappa.size() : plan.flat_r.size();
  const double radius = plan.radius;
  for (int pass = pass_from; pass < pass_to; ++pass) {
    const double y_pass = path.first_pass_y_m + pass * path.stepover_m;
    if (y_pass < y_from || y_pass > y_to)
      continue;
    const bool back = path.pattern == RasterPattern::zigzag && pass % 2 == 1;
    const Eigen::Matrix3d q = spindle_to_workpiece(plan.to_engagement, path, pass);
    // Vertical of {W} seen in {S}: the height of a point v (from the
    // reference point) is a · v.
    const Eigen::Vector3d a = q.transpose() * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d axis = q * Eigen::Vector3d::UnitZ();
    const double lowest = Ball ? -radius : -radius * std::hypot(a.x(), a.y());
    // Tooth-level cull (ball): with c = cos(φ − φ_a) ≥ c_lo over the tooth's
    // lagged angles, every band point is at least
    // R (1 − √(cos²θ + min(c_lo, 0)² sin²θ)) above the lowest point.
    const double sin_theta = std::hypot(a.x(), a.y()), cos_theta = a.z() < 0.0 ? -a.z() : a.z();
    const double bottom_azimuth = std::atan2(-a.x(), -a.y());  // where the edge is lowest
    const double lag_half = 0.5 * (plan.lag_to - plan.lag_from);
    // The runout lifts and lowers the ball by up to ρ_v over a revolution;
    // the budget counts from the lowest position, so a raised ball leaves less.
    const double runout_lift = rho * std::hypot(q(2, 0), q(2, 1));
    // Steps of this pass whose contact point is within reach of the strip.
    double t_lo = back ? (path.x_end_m - x_to) / plan.v_f : (x_from - path.x_start_m) / plan.v_f;
    double t_hi = back ? (path.x_end_m - x_from) / plan.v_f : (x_to - path.x_start_m) / plan.v_f;
    t_lo = std::max(t_lo, 0.0);
    t_hi = std::min(t_hi, plan.pass_time);
    if (t_hi < t_lo)
      continue;
    const long long k_from = static_cast<long long>(std::ceil(t_lo / plan.dt));
    const long long k_to = static_cast<long long>(std::floor(t_hi / plan.dt));
    const Eigen::Vector3d reference_w = q * plan.reference;
    for (long long k = k_from; k <= k_to; ++k) {
      const double local = static_cast<double>(k) * plan.dt;
      const double t = pass * plan.pass_time + local;
      const double x_cc =
          back ? path.x_end_m - plan.v_f * local : path.x_start_m + plan.v_f * local;
      const double spin = std::fmod(
          path.start_angle_rad + path.spindle_rad_s * (path.restart_each_pass ? local : t), kTwoPi);
      const Eigen::Vector3d offset_s(rho * std::sin(spin + lambda), rho * std::cos(spin + lambda),
                                     0.0);
      Eigen::Vector3d centre =
          Eigen::Vector3d(x_cc, y_pass, Ball ? radius : 0.0) + reference_w + q * offset_s;
      const double budget = plan.budget - runout_lift - (q * offset_s).z();
      if (!plan.vibration->empty())
        centre += q * plan.vibration->at(plan.vibration->per_pass ? local : t);
      Sweep sweep;
      sweep.centre_rate =
          q * Eigen::Vector3d(rho * std::cos(spin + lambda), -rho * std::sin(spin + lambda), 0.0);
      sweep.centre_rate.x() += (back ? -plan.v_f : plan.v_f) / path.spindle_rad_s;
      sweep.limit = kTwoPi / (4.0 * plan.teeth);
      for (int tooth = 0; tooth < plan.teeth; ++tooth) {
        const double angle = spin + plan.pitch[static_cast<std::size_t>(tooth)];
        const double s0 = std::sin(angle), c0 = std::cos(angle);
        if constexpr (Ball) {
          // Angular distance from the lowest azimuth to the nearest lagged angle.
          const double middle = angle - 0.5 * (plan.lag_from + plan.lag_to);
          double gap = std::remainder(middle - bottom_azimuth, kTwoPi);
          gap = std::max(0.0, std::abs(gap) - lag_half);
          const double c_lo = -std::cos(std::min(gap, std::numbers::pi));
          const double c_neg = std::min(c_lo, 0.0);
          const double bound =
              radius *
              (1.0 - std::sqrt(cos_theta * cos_theta + c_neg * c_neg * sin_theta * sin_theta));
          if (bound > budget * (1.0 + 1e-9) + 1e-12)
            continue;
        }
        // A flat end's bottom edge is the segment centre + r d, r in [0, R]:
        // only the radii whose point falls inside the strip are visited.
        std::size_t first = 0, skip_from = 0, skip_to = 0;
        if constexpr (!Ball) {
          const Eigen::Vector3d d = q * Eigen::Vector3d(s0, c0, 0.0);
          double r_lo = 0.0, r_hi = radius;
          const double lo[2] = {x_from + plan.reach - plan.cell, y_from + plan.reach - plan.cell};
          const double hi[2] = {x_to - plan.reach + plan.cell, y_to - plan.reach + plan.cell};
          for (int axis_index = 0; axis_index < 2; ++axis_index) {
            const double c = centre(axis_index), dd = d(axis_index);
            if (std::abs(dd) < 1e-15) {
              if (c < lo[axis_index] || c > hi[axis_index])
                r_hi = -1.0;
              continue;
            }
            double a0 = (lo[axis_index] - c) / dd, a1 = (hi[axis_index] - c) / dd;
            if (a0 > a1)
              std::swap(a0, a1);
            r_lo = std::max(r_lo, a0);
            r_hi = std::min(r_hi, a1);
          }
          const double step = radius / static_cast<double>(plan.flat_bottom - 1);
          if (r_hi < r_lo) {
            skip_from = 0;
            skip_to = plan.flat_bottom;
          } else {
            skip_from = static_cast<std::size_t>(
                std::min<double>(plan.flat_bottom, std::max(0.0, std::floor(r_hi / step) + 1.0)));
            skip_to = plan.flat_bottom;
            first = static_cast<std::size_t>(std::max(0.0, std::ceil(r_lo / step)));
          }
        }
        for (std::size_t m = first; m < band; ++m) {
          if constexpr (!Ball) {
            if (m >= skip_from && m < skip_to) {
              m = skip_to - 1;
              continue;
            }
          }
          Eigen::Vector3d v;
          if constexpr (Ball) {
            // φ = angle − ψ(κ): sin and cos by the difference formulas.
            const double sp = s0 * plan.cos_lag[m] - c0 * plan.sin_lag[m];
            const double cp = c0 * plan.cos_lag[m] + s0 * plan.sin_lag[m];
            v = {radius * plan.sin_kappa[m] * sp, radius * plan.sin_kappa[m] * cp,
                 -radius * plan.cos_kappa[m]};
            // d v / d φ = (r cos φ, −r sin φ, 0), in {W}.
            const Eigen::Vector3d rate = q * Eigen::Vector3d(v.y(), -v.x(), 0.0);
            const double norm2 = rate.x() * rate.x() + rate.y() * rate.y();
            const double floor2 = 0.25 * plan.cell * plan.cell;
            sweep.tx = rate.x();
            sweep.ty = rate.y();
            sweep.inverse = norm2 > floor2 ? 1.0 / norm2 : 0.0;
          } else {
            const double r = plan.flat_r[m], zt = plan.flat_z[m];
            const double lag = zt * std::tan(tool.helix_rad()) / radius;
            const double sp = lag == 0.0 ? s0 : std::sin(angle - lag);
            const double cp = lag == 0.0 ? c0 : std::cos(angle - lag);
            v = {r * sp, r * cp, zt};
          }
          if (a.dot(v) - lowest > budget)
            continue;  // too high above the tool's lowest point to leave the surface
          ++counters.points;
          const Eigen::Vector3d p = centre + q * v;
          lower<Ball>(plan, z, column_from, column_to, p, centre, axis,
                      !Ball && m >= plan.flat_bottom, sweep, counters);
        }
      }
    }
  }
}

/// The edge points the Z-map evaluates into the plan: a ball end's band of
/// κ, a flat end's bottom radii and side heights, about ds apart. Returns
/// their spacing.
double sample_edge(Plan& plan, const tool::Tool& tool, const Band& band, double ds) {
  double spacing = 0.0;
  if (plan.ball) {
    const int n = std::max(
        2, static_cast<int>(std::ceil((band.to - band.from) * plan.radius / ds - 1e-9)) + 1);
    const double step = (band.to - band.from) / (n - 1);
    const double tan_helix = std::tan(tool.helix_rad());
    for (int m = 0; m < n; ++m) {
      const double kappa = band.from + m * step;
      plan.sin_kappa.push_back(std::sin(kappa));
      plan.cos_kappa.push_back(std::cos(kappa));
      const double lag = tan_helix * (1.0 - std::cos(kappa));  // 001 Eq 3
      plan.sin_lag.push_back(std::sin(lag));
      plan.cos_lag.push_back(std::cos(lag));
    }
    spacing = step * plan.radius;
    plan.lag_from = tan_helix * (1.0 - std::cos(band.from));
    plan.lag_to = tan_helix * (1.0 - std::cos(band.to));
  } else {
    const int bottom = std::max(2, static_cast<int>(std::ceil(plan.radius / ds)) + 1);
    for (int m = 0; m < bottom; ++m) {
      plan.flat_r.push_back(plan.radius * m / (bottom - 1));
      plan.flat_z.push_back(0.0);
    }
    plan.flat_bottom = plan.flat_r.size();
    const int side = std::max(1, static_cast<int>(std::ceil(band.to / ds)));
    for (int m = 1; m <= side; ++m) {
      plan.flat_r.push_back(plan.radius);
      plan.flat_z.push_back(band.to * m / side);
    }
    spacing = std::max(plan.radius / (bottom - 1), band.to / side);
  }
  return spacing;
}

/// Cuts every pass into result.map.z_m (the stock top at first); the
/// counters of each worker.
std::vector<Counters> cut_passes(const Plan& plan, const ZMapGrid& grid, const RasterPath& path,
                                 double axial_depth_m, const ZMapOptions& options,
                                 ZMapResult& result) {
  // Parallel without races, two ways. When a private grid per worker is
  // affordable (≤ 256 MB in all), the workers share out the passes, each
  // cutting its passes into its own grid, and the grids are merged by min
  // (exact: the Z-map is a min over edge points, in any order). Otherwise
  // the grid's columns are split into strips, each evaluating the time steps
  // within reach of its columns and writing only them; strips are no
  // narrower than twice the reach, so no point is evaluated more than ~twice.
  const int threads = core::resolve_thread_count(options.threads);
  const int workers_by_pass = std::min(threads, path.passes);
  const double private_bytes =
      static_cast<double>(grid.node_count()) * sizeof(double) * (workers_by_pass - 1);
  auto cut = [&](std::vector<double>& z, int from, int to, int pass_from, int pass_to,
                 Counters& c) {
    if (plan.ball)
      cut_strip<true>(plan, z, from, to, pass_from, pass_to, c);
    else
      cut_strip<false>(plan, z, from, to, pass_from, pass_to, c);
  };
  std::vector<Counters> counters;
  if (workers_by_pass > 1 && private_bytes <= options.private_grid_bytes) {
    const int workers = workers_by_pass;
    counters.resize(static_cast<std::size_t>(workers));
    std::vector<std::vector<double>> own(static_cast<std::size_t>(workers - 1));
    core::parallel_for(static_cast<std::size_t>(workers), threads, [&](std::size_t w) {
      std::vector<double>& z = w == 0 ? result.map.z_m : own[w - 1];
      if (w > 0)
        z.assign(grid.node_count(), axial_depth_m);
      const int from = static_cast<int>(path.passes * w / workers);
      const int to = static_cast<int>(path.passes * (w + 1) / workers);
      cut(z, 0, grid.nodes_x(), from, to, counters[w]);
    });
    const std::size_t nodes = grid.node_count();
    const std::size_t blocks = static_cast<std::size_t>(threads);
    core::parallel_for(blocks, threads, [&](std::size_t b) {
      const std::size_t from = nodes * b / blocks, to = nodes * (b + 1) / blocks;
      for (const std::vector<double>& z : own)
        for (std::size_t n = from; n < to; ++n)
          result.map.z_m[n] = std::min(result.map.z_m[n], z[n]);
    });
  } else {
    const double width_limit = std::max(1.0, grid.length_x_m / (2.0 * plan.reach));
    const int strips =
        std::clamp(static_cast<int>(std::min<double>(threads, width_limit)), 1, grid.nodes_x());
    counters.resize(static_cast<std::size_t>(strips));
    core::parallel_for(static_cast<std::size_t>(strips), threads, [&](std::size_t s) {
      const int from = static_cast<int>(grid.nodes_x() * s / strips);
      const int to = static_cast<int>(grid.nodes_x() * (s + 1) / strips);
      cut(result.map.z_m, from, to, 0, path.passes, counters[s]);
    });
  }
  return counters;
}

}  // namespace

ZMapResult cut_zmap(const tool::Tool& tool, double axial_depth_m,
                    const ToolOrientation& orientation, const RasterPath& path,
                    const ZMapGrid& grid, const Vibration& vibration, const ZMapOptions& options) {
  require(axial_depth_m > 0.0 && std::isfinite(axial_depth_m), "ap must be positive");
  require(path.spindle_rad_s > 0.0 && path.feed_per_tooth_m > 0.0,
          "spindle speed and feed must be positive");
  require(path.stepover_m > 0.0 && path.passes >= 1, "stepover and passes must be positive");
  require(path.x_end_m > path.x_start_m, "the path must run from x_start to a larger x_end");
  require(grid.cells_x >= 1 && grid.cells_y >= 1 && grid.length_x_m > 0.0 && grid.length_y_m > 0.0,
          "the grid needs positive lengths and cell counts");
  require(grid.node_count() <= 400'000'000u, "the grid is larger than 4e8 nodes");

  Plan plan;
  plan.tool = &tool;
  plan.path = &path;
  plan.grid = &grid;
  plan.vibration = &vibration;
  plan.ball = tool.type() == tool::ToolType::ball;
  plan.radius = tool.radius_m();
  plan.teeth = tool.teeth();
  plan.v_f = feed_speed(path, tool.teeth());
  plan.pass_time = (path.x_end_m - path.x_start_m) / plan.v_f;
  plan.to_engagement = spindle_to_engagement(orientation);
  plan.reference = reference_offset(tool, orientation);
  const double vibration_amplitude = vibration.amplitude_m();
  plan.budget = options.height_budget_m > 0.0
                    ? options.height_budget_m
                    : automatic_budget(tool, orientation, path, vibration);
  const Band band = evaluated_band(tool, axial_depth_m, orientation, plan.budget);
  const ResolutionRules rules =
      resolution_rules(tool, axial_depth_m, orientation, path, grid, plan.budget);
  const double cell = std::min(grid.dx(), grid.dy());

  const int steps = options.steps_per_revolution > 0 ? options.steps_per_revolution
                                                     : rules.min_steps_per_revolution;
  require(steps >= rules.min_steps_per_revolution,
          "steps_per_revolution " + std::to_string(steps) + " breaks 001 Eq 30; needs " +
              std::to_string(rules.min_steps_per_revolution));
  const double ds = options.edge_spacing_m > 0.0 ? options.edge_spacing_m : 0.5 * cell;
  require(ds <= cell * (1.0 + 1e-9), "the edge spacing breaks 001 Eq 31 (ds <= min(dx, dy))");
  plan.dt = kTwoPi / (path.spindle_rad_s * steps);
  plan.cell = cell;
  plan.steps_per_pass = static_cast<long long>(std::floor(plan.pass_time / plan.dt)) + 1;

  for (int j = 0; j < tool.teeth(); ++j)
    plan.pitch.push_back(tool.pitch_angle_rad(j));
  const double spacing = sample_edge(plan, tool, band, ds);
  const double theta = axis_angle(orientation);
  // Horizontal reach of the evaluated points around the contact point.
  const double lateral =
      plan.ball
          ? plan.radius * std::sin(std::min(0.5 * std::numbers::pi,
                                            std::max(band.to - theta, theta - band.from) + 1e-3))
          : 2.0 * plan.radius + band.to;
  plan.reach = lateral + tool.runout().offset_m + vibration_amplitude * 2.0 + 2.0 * cell;

  ZMapResult result;
  result.map.grid = grid;
  result.map.z_m.assign(grid.node_count(), axial_depth_m);

  const std::vector<Counters> counters =
      cut_passes(plan, grid, path, axial_depth_m, options, result);

  ZMapStats& stats = result.stats;
  stats.steps_per_revolution = steps;
  stats.edge_points = static_cast<int>(plan.ball ? plan.sin_kappa.size() : plan.flat_r.size());
  stats.time_step_s = plan.dt;
  stats.edge_spacing_m = spacing;
  stats.max_edge_radius_m = max_edge_radius(tool, band);
  stats.step_travel_m = (path.spindle_rad_s * stats.max_edge_radius_m + plan.v_f) * plan.dt;
  stats.height_budget_m = plan.budget;
  stats.path_time_s = plan.pass_time * path.passes;
  for (const Counters& c : counters) {
    stats.point_evaluations += c.points;
    stats.node_updates += c.updates;
    stats.node_tests += c.tests;
  }
  return result;
}

}  // namespace robomill::surface
