#include "robomill/toolpath/cutter_engagement.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "robomill/core/constants.hpp"

namespace robomill::toolpath {
namespace {

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

namespace {

// The cutter's surface at height h above the tip, seen from the axis at
// angle φ: the point `inset` inside along the surface normal, the normal,
// and the radius there. The normal is n = radial_share u + axial_share a: on
// the corner (a ball's sphere, a bull nose's torus) the corner circle's
// normal, on the side the radial direction.
struct SurfaceProbe {
  double radial_share = 1.0, axial_share = 0.0;
  double test_radius_m = 0.0;  // of the test points, `inset` inside
  double test_height_m = 0.0;  // of the test points along the axis
};

SurfaceProbe surface_probe(const CutterShape& cutter, double height_m, double inset_m) {
  SurfaceProbe probe;
  const double corner = cutter.corner_radius_m;
  const double r = cutter.radius_at(height_m);
  if (height_m < corner) {
    // The corner circle is centred at radius R − r_c, height r_c.
    probe.radial_share = (r - (cutter.radius_m - corner)) / corner;
    probe.axial_share = (height_m - corner) / corner;
  }
  probe.test_radius_m = std::max(0.0, r - inset_m * probe.radial_share);
  probe.test_height_m = height_m - inset_m * probe.axial_share;
  return probe;
}

// The work of one query: the frame, the stock and the grid.
struct Query {
  const DexelStock& stock;
  const CutterShape& cutter;
  Eigen::Vector3d tip, a, x_hat, y_hat;
  double inset = 0.0;
  int points = 0;
  double step = 0.0;
  bool plunge = false;

  Eigen::Vector3d direction(double sin_phi, double cos_phi) const {
    return sin_phi * x_hat + cos_phi * y_hat;
  }

  // Fills scratch.in_material with the test points of height h; true when
  // any is in material.
  bool test(double height_m, Scratch& scratch) const {
    const SurfaceProbe probe = surface_probe(cutter, height_m, inset);
    const Eigen::Vector3d centre = tip + probe.test_height_m * a;
    bool any = false;
    for (int i = 0; i < points; ++i) {
      const Eigen::Vector3d u = direction(scratch.sin[i], scratch.cos[i]);
      const bool in = stock.contains(centre + probe.test_radius_m * u,
                                     probe.radial_share * u + probe.axial_share * a);
      scratch.in_material[i] = in;
      any = any || in;
    }
    return any;
  }

  // The arcs of the in-material test points, at most kMaxArcs.
  void arcs_into(Scratch& scratch, EngagementSlice& slice) const {
    if (plunge && std::all_of(scratch.in_material.begin(), scratch.in_material.end(),
                              [](char c) { return c != 0; })) {
      scratch.arcs.assign(1, EngagedArc{0.0, kTwoPi});
    } else {
      collect_arcs(scratch.in_material, step, scratch.arcs);
    }
    merge_narrowest_gaps(scratch.arcs);
    slice.arc_count = static_cast<int>(scratch.arcs.size());
    std::copy(scratch.arcs.begin(), scratch.arcs.end(), slice.arcs.begin());
  }

  // Where the material met at the middle of each arc of a slice tested at
  // height h ends along the axis, above (`upwards`) or below: the farthest
  // end over the arcs, as a height above the tip. The dexel rays are exact
  // along their own direction, so for a flat floor or top this is exact
  // whatever the slice grid (DexelStock::material_run). An end beyond
  // `beyond_m` is a ray running on up (or down) a wall that the slice's test
  // points beside it read as air (a bore's side grazed in a helical ramp),
  // and is not taken. Empty when no arc gives an end.
  std::optional<double> material_end(const EngagementSlice& slice, double height_m, bool upwards,
                                     double beyond_m) const {
    const SurfaceProbe probe = surface_probe(cutter, height_m, inset);
    std::optional<double> end;
    for (int k = 0; k < slice.arc_count; ++k) {
      const double phi = 0.5 * (slice.arcs[k].entry_rad + slice.arcs[k].exit_rad);
      const Eigen::Vector3d point = tip + probe.test_height_m * a +
                                    probe.test_radius_m * direction(std::sin(phi), std::cos(phi));
      const auto run = stock.material_run(point, a);
      if (!run)
        continue;
      const double h =
          upwards ? probe.test_height_m + run->after_m : probe.test_height_m - run->before_m;
      if (upwards ? h > beyond_m : h < beyond_m)
        continue;
      end = !end ? h : upwards ? std::max(*end, h) : std::min(*end, h);
    }
    return end;
  }
};

// Local frame: x along the feed's component normal to the axis; for a
// plunge (no such component) any normal direction, and the whole turn.
void set_frame(const Eigen::Vector3d& feed_direction, Query& query) {
  const Eigen::Vector3d& a = query.a;
  const Eigen::Vector3d feed_normal = feed_direction - feed_direction.dot(a) * a;
  query.plunge = !(feed_normal.norm() > 1e-6 * feed_direction.norm());
  if (query.plunge) {
    Eigen::Vector3d least = Eigen::Vector3d::Zero();
    Eigen::Index i = 0;
    a.cwiseAbs().minCoeff(&i);
    least[i] = 1.0;
    query.x_hat = (least - least.dot(a) * a).normalized();
  } else {
    query.x_hat = feed_normal.normalized();
  }
  query.y_hat = a.cross(query.x_hat);
}

// Slice k of the grid, before any test.
EngagementSlice grid_slice(const CutterShape& cutter, double dz, double length, int k) {
  EngagementSlice slice;
  slice.thickness_m = std::min(dz, length - k * dz);
  slice.height_m = k * dz + 0.5 * slice.thickness_m;
  slice.radius_m = cutter.radius_at(slice.height_m);
  return slice;
}

// 1. Each slice of the grid tested at its centre height, up to the top of
// the stock box (h_lo, h_hi: the heights along the axis where the slice
// plane meets the box at all); `tested_at` the height each slice's arcs were
// found at.
void test_grid(const Query& query, double dz, double h_lo, double h_hi, Scratch& scratch,
               std::vector<EngagementSlice>& slices, std::vector<double>& tested_at) {
  const CutterShape& cutter = query.cutter;
  const double length = cutter.length_m;
  const double inset = query.inset;
  const int slice_count = std::max(1, static_cast<int>(std::ceil(length / dz - 1e-9)));
  for (int k = 0; k < slice_count; ++k) {
    EngagementSlice slice = grid_slice(cutter, dz, length, k);
    const double h = slice.height_m;
    if (h > h_hi + 0.5 * dz)
      break;  // this slice and all above are outside the stock box
    slices.push_back(slice);
    tested_at.push_back(h);
    if (h < h_lo - inset || h > h_hi)
      continue;
    if (query.test(h, scratch))
      query.arcs_into(scratch, slices.back());
  }
  // A cut thinner than half a slice (a finishing pass at a coarse grid)
  // misses the first slice's centre: test it again just above the floor,
  // clear of the inset the test points keep.
  if (!slices.empty() && slices[0].arc_count == 0) {
    const double low = std::min(0.5 * slices[0].thickness_m, 3.0 * inset + 1e-6);
    if (low >= h_lo - inset && query.test(low, scratch)) {
      query.arcs_into(scratch, slices[0]);
      tested_at[0] = low;
    }
  }
}

// 2. Each run of engaged slices ends where the material ends: its top
// slice is cut off, or the empty slice above it taken in with the same
// arcs, at the material's end along the axis; likewise its bottom when it
// does not start at the tip (the tip below the stock). ap, the chip area,
// the section and the forces then follow the program's depth, not the
// slice grid's. `bottom` and `top` (each slice's) are filled here.
void end_runs_at_material(const Query& query, double dz, std::vector<EngagementSlice>& slices,
                          std::vector<double>& tested_at, std::vector<double>& bottom,
                          std::vector<double>& top) {
  const DexelStock& stock = query.stock;
  const double length = query.cutter.length_m;
  const int count = static_cast<int>(slices.size());
  bottom.resize(count);
  top.resize(count);
  for (int k = 0; k < count; ++k) {
    bottom[k] = slices[k].height_m - 0.5 * slices[k].thickness_m;
    top[k] = slices[k].height_m + 0.5 * slices[k].thickness_m;
  }
  constexpr double kMinThickness = 1e-9;
  for (int k = 0; k < count;) {
    if (slices[k].arc_count == 0) {
      ++k;
      continue;
    }
    int k1 = k;
    while (k1 + 1 < count && slices[k1 + 1].arc_count > 0)
      ++k1;
    const int k0 = k;
    k = k1 + 1;
    // The next slice's own test at its centre found no material. Near a
    // horizontal face that can be the interpolation of the rays across it,
    // which reads air up to a cell below the face: an end up to a cell above
    // that test is taken (at most through the next slice), one further up is
    // a wall's.
    const double cell = stock.resolution_m();
    const double beyond = k1 + 1 < count ? tested_at[k1 + 1] + cell : top[k1] + dz;
    const double limit = k1 + 1 < count ? top[k1 + 1] : std::min(length, top[k1] + dz);
    if (const auto end = query.material_end(slices[k1], tested_at[k1], true, beyond)) {
      const double material_top = std::clamp(*end, bottom[k1] + kMinThickness, limit);
      if (material_top > top[k1] + kMinThickness && k1 + 1 < count) {
        slices[k1 + 1].arc_count = slices[k1].arc_count;
        slices[k1 + 1].arcs = slices[k1].arcs;
        top[k1 + 1] = material_top;
        ++k;  // the slice taken in ends this run
      } else if (material_top > top[k1] + kMinThickness && k1 + 1 == count &&
                 material_top <= length) {
        EngagementSlice above = slices[k1];
        slices.push_back(above);
        tested_at.push_back(tested_at[k1]);
        bottom.push_back(top[k1]);
        top.push_back(material_top);
      } else {
        top[k1] = std::min(top[k1], material_top);
      }
    }
    if (k0 > 0 && bottom[k0] > 0.0) {
      const double below = tested_at[k0 - 1] - stock.resolution_m();
      if (const auto end = query.material_end(slices[k0], tested_at[k0], false, below)) {
        const double material_bottom = std::clamp(*end, bottom[k0 - 1], top[k0] - kMinThickness);
        if (material_bottom < bottom[k0] && slices[k0 - 1].arc_count == 0) {
          slices[k0 - 1].arc_count = slices[k0].arc_count;
          slices[k0 - 1].arcs = slices[k0].arcs;
          bottom[k0 - 1] = material_bottom;
        } else {
          bottom[k0] = std::max(bottom[k0], material_bottom);
        }
      }
    }
  }
}

// With the axis vertical, the height above the tip of a z level of the
// stock's rays strictly inside [from_h, to_h] (the z levels i: box.min z +
// (i + ½) cell); empty otherwise.
std::optional<double> level_inside(const Query& query, bool vertical_axis, double from_h,
                                   double to_h) {
  if (!vertical_axis)
    return std::nullopt;
  const StockBox& box = query.stock.box();
  const Eigen::Vector3d& tip_m = query.tip;
  const Eigen::Vector3d& a = query.a;
  // Heights above the tip of the z levels i: box.min z + (i + ½) cell.
  const double cell = query.stock.cell_size_m(2);
  const double z_from = tip_m.z() + a.z() * from_h, z_to = tip_m.z() + a.z() * to_h;
  const double z_mid = 0.5 * (z_from + z_to);
  const double i = std::round((z_mid - box.min_m.z()) / cell - 0.5);
  const double z_level = box.min_m.z() + (i + 0.5) * cell;
  const double h = (z_level - tip_m.z()) * a.z();
  const double margin = 1e-9;
  if (h > std::min(from_h, to_h) + margin && h < std::max(from_h, to_h) - margin)
    return h;
  return std::nullopt;
}

// 3. The arcs of a run's end slices again, where they were found too close
// to the material's face. The horizontal rays that answer for the side
// test points (the grid along their normal) lie on levels one cell apart,
// and a test point between the last level inside the material and the
// first outside it reads an interpolation with air: a slot's sides go
// missing in its top slice. With the axis vertical, the end slice is
// tested again on a ray level inside it (where the interpolation across
// levels has no weight); otherwise it takes the arcs of its neighbour in
// the run. A run thinner than the level spacing with no level inside it
// keeps what its own test found (docs/toolpath.md, "Limits").
void retest_run_ends(const Query& query, Scratch& scratch, std::vector<EngagementSlice>& slices,
                     std::vector<double>& tested_at, const std::vector<double>& bottom,
                     const std::vector<double>& top) {
  const bool vertical_axis = std::abs(query.a.z()) > 1.0 - 1e-12;
  for (std::size_t k = 0; k < slices.size(); ++k) {
    if (slices[k].arc_count == 0)
      continue;
    const bool run_top = k + 1 == slices.size() || slices[k + 1].arc_count == 0;
    const bool run_bottom = k == 0 || slices[k - 1].arc_count == 0;
    if (!run_top && !run_bottom)
      continue;
    if (const auto level = level_inside(query, vertical_axis, bottom[k], top[k])) {
      if (std::abs(*level - tested_at[k]) > 1e-12 && query.test(*level, scratch)) {
        query.arcs_into(scratch, slices[k]);
        tested_at[k] = *level;
      }
    } else if (run_top && !run_bottom) {
      slices[k].arc_count = slices[k - 1].arc_count;
      slices[k].arcs = slices[k - 1].arcs;
    } else if (run_bottom && !run_top) {
      slices[k].arc_count = slices[k + 1].arc_count;
      slices[k].arcs = slices[k + 1].arcs;
    }
  }
}

// The slices stay contiguous from the tip (the force model reads each
// slice as reaching from the top of the one below to its own top): an
// empty slice spans the gap between the engaged slices around it.
void close_gaps(const std::vector<EngagementSlice>& slices, std::vector<double>& bottom,
                std::vector<double>& top) {
  const std::size_t final_count = slices.size();
  for (std::size_t k = 0; k + 1 < final_count; ++k) {
    if (slices[k].arc_count == 0)
      top[k] = bottom[k + 1];
  }
  for (std::size_t k = 1; k < final_count; ++k) {
    if (slices[k].arc_count == 0)
      bottom[k] = top[k - 1];
  }
}

// 4. The engagement's figures from the final slices; `result` keeps its
// defaults (and no slices) when none is engaged.
void take_figures(const Query& query, std::vector<EngagementSlice>& slices,
                  const std::vector<double>& bottom, const std::vector<double>& top,
                  CutterEngagement& result) {
  const CutterShape& cutter = query.cutter;
  int highest = -1;
  double best_width = 0.0, best_angle = -1.0, plunge_section = 0.0;
  for (std::size_t k = 0; k < slices.size(); ++k) {
    EngagementSlice& s = slices[k];
    s.thickness_m = std::max(0.0, top[k] - bottom[k]);
    s.height_m = 0.5 * (top[k] + bottom[k]);
    s.radius_m = cutter.radius_at(s.height_m);
    if (s.arc_count == 0)
      continue;
    highest = static_cast<int>(k);
    const double r = s.radius_m;
    double width = 0.0;
    if (query.plunge) {
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
    return;
  slices.resize(static_cast<std::size_t>(highest) + 1);
  result.axial_depth_m = slices.back().height_m + 0.5 * slices.back().thickness_m;
  result.radial_width_m = best_width;
  if (query.plunge)
    result.section_m2 = plunge_section;
  result.slices = std::move(slices);
}

}  // namespace

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
  Query query{stock, cutter, tip_m, axis.normalized(), {}, {}};
  const Eigen::Vector3d& a = query.a;
  set_frame(feed_direction, query);

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
  query.inset = surface_inset_m(grid, cutter, stock.resolution_m());

  const int half_steps = grid.angle_steps;
  query.step = kPi / half_steps;
  query.points = query.plunge ? 2 * half_steps : half_steps;
  thread_local Scratch scratch;
  scratch.prepare(query.points, query.step);

  std::vector<EngagementSlice> slices;
  std::vector<double> tested_at;  // the height each slice's arcs were found at
  test_grid(query, dz, h_lo, h_hi, scratch, slices, tested_at);
  std::vector<double> bottom, top;  // each slice's ends along the axis
  end_runs_at_material(query, dz, slices, tested_at, bottom, top);
  retest_run_ends(query, scratch, slices, tested_at, bottom, top);
  close_gaps(slices, bottom, top);
  take_figures(query, slices, bottom, top, result);
  return result;
}

}  // namespace robomill::toolpath
