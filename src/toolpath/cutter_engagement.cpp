#include "robomill/toolpath/cutter_engagement.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace robomill::toolpath {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Per-thread scratch, so a query allocates only when the angle grid grows.
struct Scratch {
  int points = 0;
  double step = 0.0;
  std::vector<double> sin, cos;
  std::vector<char> in_material;
  std::vector<EngagedArc> arcs;

  void prepare(int count, double step_rad) {
    if (count != points || step_rad != step) {
      points = count;
      step = step_rad;
      sin.resize(count);
      cos.resize(count);
      for (int i = 0; i < count; ++i) {  // cell-centred angles (i + ½) Δφ
        const double phi = (i + 0.5) * step_rad;
        sin[i] = std::sin(phi);
        cos[i] = std::cos(phi);
      }
    }
    in_material.resize(count);
  }
};

// Runs of in-material points → arcs, each end at the midpoint between an
// in-material point and its neighbour in air (a cell edge of the angle grid,
// so 0 and the end of the range for runs reaching them). A plunge's run
// through φ = 0 comes out as two arcs, [0, exit] and [entry, 2π].
void collect_arcs(const std::vector<char>& in, double step, std::vector<EngagedArc>& arcs) {
  arcs.clear();
  const int n = static_cast<int>(in.size());
  for (int i = 0; i < n;) {
    if (!in[i]) {
      ++i;
      continue;
    }
    int j = i;
    while (j + 1 < n && in[j + 1])
      ++j;
    arcs.push_back({i * step, (j + 1) * step});
    i = j + 1;
  }
}

// At most kMaxArcs: close the narrowest gaps first (the material between two
// arcs separated by less than a grid step or two is the likeliest to be a
// rib the grid could not resolve).
void merge_narrowest_gaps(std::vector<EngagedArc>& arcs) {
  while (static_cast<int>(arcs.size()) > EngagementSlice::kMaxArcs) {
    std::size_t best = 0;
    double gap = arcs[1].entry_rad - arcs[0].exit_rad;
    for (std::size_t k = 1; k + 1 < arcs.size(); ++k) {
      const double g = arcs[k + 1].entry_rad - arcs[k].exit_rad;
      if (g < gap) {
        gap = g;
        best = k;
      }
    }
    arcs[best].exit_rad = arcs[best + 1].exit_rad;
    arcs.erase(arcs.begin() + static_cast<std::ptrdiff_t>(best) + 1);
  }
}

// Largest and smallest cos φ over an arc within [0, 2π].
void cos_range(const EngagedArc& arc, double& lo, double& hi) {
  hi = std::max(std::cos(arc.entry_rad), std::cos(arc.exit_rad));
  lo = std::min(std::cos(arc.entry_rad), std::cos(arc.exit_rad));
  if (arc.entry_rad <= 0.0 || arc.exit_rad >= kTwoPi)
    hi = 1.0;
  if (arc.entry_rad <= kPi && arc.exit_rad >= kPi)
    lo = -1.0;
}

}  // namespace

double EngagementSlice::engaged_rad() const noexcept {
  double total = 0.0;
  for (int k = 0; k < arc_count; ++k)
    total += arcs[k].exit_rad - arcs[k].entry_rad;
  return total;
}

EngagementGrid default_engagement_grid(const CutterShape& cutter, double resolution_m) {
  EngagementGrid grid;
  double slice = std::max(resolution_m, 0.1e-3);
  if (cutter.length_m > 0.0)
    slice = std::max(slice, cutter.length_m / 200.0);
  grid.slice_height_m = slice;
  const double steps = cutter.radius_m > 0.0 && resolution_m > 0.0
                           ? kPi * cutter.radius_m / (0.5 * resolution_m)
                           : 36.0;
  grid.angle_steps = static_cast<int>(std::clamp(std::round(steps), 36.0, 360.0));
  return grid;
}

double surface_inset_m(const EngagementGrid& grid, const CutterShape& cutter,
                       double resolution_m) noexcept {
  if (grid.surface_inset_m >= 0.0)
    return grid.surface_inset_m;
  return std::min(0.5 * resolution_m, 0.5 * resolution_m * resolution_m / cutter.radius_m + 1e-6);
}

CutterEngagement engagement_at(const DexelStock& stock, const CutterShape& cutter,
                               const Eigen::Vector3d& tip_m, const Eigen::Vector3d& axis,
                               const Eigen::Vector3d& feed_direction, const EngagementGrid& grid) {
  CutterEngagement result;
  const double radius = cutter.radius_m, length = cutter.length_m;
  const double dz = grid.slice_height_m;
  if (!(radius > 0.0) || !(length > 0.0) || !(dz > 0.0) || grid.angle_steps < 1 ||
      !(axis.norm() > 0.0) || !tip_m.allFinite()) {
    return result;
  }
  const Eigen::Vector3d a = axis.normalized();

  // Local frame: x along the feed's component normal to the axis; for a
  // plunge (no such component) any normal direction, and the whole turn.
  const Eigen::Vector3d feed_normal = feed_direction - feed_direction.dot(a) * a;
  const bool plunge = !(feed_normal.norm() > 1e-6 * feed_direction.norm());
  Eigen::Vector3d x_hat;
  if (plunge) {
    Eigen::Vector3d least = Eigen::Vector3d::Zero();
    Eigen::Index i = 0;
    a.cwiseAbs().minCoeff(&i);
    least[i] = 1.0;
    x_hat = (least - least.dot(a) * a).normalized();
  } else {
    x_hat = feed_normal.normalized();
  }
  const Eigen::Vector3d y_hat = a.cross(x_hat);

  // Heights along the axis where the slice plane meets the stock box at all.
  const StockBox& box = stock.box();
  double h_lo = 0.0, h_hi = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double p = (box.min_m[i] - tip_m[i]) * a[i], q = (box.max_m[i] - tip_m[i]) * a[i];
    h_lo += std::min(p, q);
    h_hi += std::max(p, q);
  }

  // Test points half a curvature error inside the surface: the walls the
  // cutter itself left (a plunge's hole, a slot's sides) coincide with its
  // surface, and the stock's interpolated boundary is off by up to about
  // 0.35 res² / R there (DexelStock::material_depth_m), so a point exactly on
  // the surface would read air or material by rounding.
  const double inset = surface_inset_m(grid, cutter, stock.resolution_m());

  const int half_steps = grid.angle_steps;
  const double step = kPi / half_steps;
  const int points = plunge ? 2 * half_steps : half_steps;
  thread_local Scratch scratch;
  scratch.prepare(points, step);

  const int slice_count = std::max(1, static_cast<int>(std::ceil(length / dz - 1e-9)));
  const double corner = cutter.is_ball() ? radius : 0.0;
  int highest = -1;
  double best_width = 0.0, best_angle = -1.0, plunge_section = 0.0;
  std::vector<EngagementSlice> slices;
  for (int k = 0; k < slice_count; ++k) {
    EngagementSlice slice;
    slice.thickness_m = std::min(dz, length - k * dz);
    slice.height_m = k * dz + 0.5 * slice.thickness_m;
    const double h = slice.height_m;
    if (h > h_hi)
      break;  // this slice and all above are outside the stock box
    slice.radius_m = cutter.radius_at(h);
    slices.push_back(slice);
    if (h < h_lo - inset)
      continue;

    // Surface normal n = radial_share u + axial_share a (on the ball the
    // sphere's normal); the test point sits `inset` inside along it.
    double radial_share = 1.0, axial_share = 0.0;
    if (h < corner) {
      radial_share = slice.radius_m / radius;
      axial_share = (h - corner) / radius;
    }
    const double r_test = std::max(0.0, slice.radius_m - inset * radial_share);
    const Eigen::Vector3d centre = tip_m + (h - inset * axial_share) * a;
    bool any = false;
    for (int i = 0; i < points; ++i) {
      const Eigen::Vector3d u = scratch.sin[i] * x_hat + scratch.cos[i] * y_hat;
      const bool in = stock.contains(centre + r_test * u, radial_share * u + axial_share * a);
      scratch.in_material[i] = in;
      any = any || in;
    }
    if (!any)
      continue;

    EngagementSlice& s = slices.back();
    if (plunge && std::all_of(scratch.in_material.begin(), scratch.in_material.end(),
                              [](char c) { return c != 0; })) {
      scratch.arcs.assign(1, EngagedArc{0.0, kTwoPi});
    } else {
      collect_arcs(scratch.in_material, step, scratch.arcs);
    }
    merge_narrowest_gaps(scratch.arcs);
    s.arc_count = static_cast<int>(scratch.arcs.size());
    std::copy(scratch.arcs.begin(), scratch.arcs.end(), s.arcs.begin());
    highest = k;

    const double r = s.radius_m;
    double width = 0.0;
    if (plunge) {
      double lo = 1.0, hi = -1.0;
      for (int m = 0; m < s.arc_count; ++m) {
        double arc_lo = 0.0, arc_hi = 0.0;
        cos_range(s.arcs[m], arc_lo, arc_hi);
        lo = std::min(lo, arc_lo);
        hi = std::max(hi, arc_hi);
      }
      width = r * (hi - lo);
      plunge_section = std::max(plunge_section, 0.5 * r * r * s.engaged_rad());
    } else {
      for (int m = 0; m < s.arc_count; ++m) {
        const double projected = r * (std::cos(s.arcs[m].entry_rad) - std::cos(s.arcs[m].exit_rad));
        width += projected;
        result.section_m2 += projected * s.thickness_m;
      }
    }
    best_width = std::max(best_width, width);
    if (s.engaged_rad() > best_angle) {
      best_angle = s.engaged_rad();
      result.engaged_rad = best_angle;
      result.entry_rad = s.arcs[0].entry_rad;
      result.exit_rad = s.arcs[s.arc_count - 1].exit_rad;
    }
  }
  if (highest < 0)
    return result;
  slices.resize(static_cast<std::size_t>(highest) + 1);
  result.axial_depth_m = slices.back().height_m + 0.5 * slices.back().thickness_m;
  result.radial_width_m = best_width;
  if (plunge)
    result.section_m2 = plunge_section;
  result.slices = std::move(slices);
  return result;
}

}  // namespace robomill::toolpath
