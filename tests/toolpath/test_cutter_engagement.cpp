// Cutter-workpiece engagement (toolpath/cutter_engagement.hpp) against the
// closed forms of milling geometry. Each run follows the caller's order:
// engagement at p_k on the stock cut up to p_{k-1}, then the sweep p_{k-1} →
// p_k is removed.
//
// Where the tolerances come from (R the cutter radius, res the dexel
// resolution, Δφ = π / angle_steps the angle grid, dz the slice height,
// f the sample spacing, δ = 0.5 res² / R the test points' inset):
//  - an arc's end lies on a cell edge of the angle grid: ±Δφ/2;
//  - a material boundary across the answering grid's rays is placed to half a
//    cell (res/2) where the boundary is parallel to those rays, which moves
//    an end by res / (2 R |∂/∂φ of the point's distance to the boundary|);
//  - an end at the side of the cut (φ = 0 or π) sits where the material left
//    ahead by the previous sample is f sin φ thin: it reads as material once
//    that exceeds the inset and the interpolation error, asin(2δ / f) + Δφ;
//  - ap is quantized to slice tops (dz) and a top surface parallel to the
//    horizontal rays is placed to res/2.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "robomill/toolpath/cutter_engagement.hpp"

namespace test_cutter_engagement_cpp {

namespace {

using namespace robomill::toolpath;
using Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;
const Vector3d kUp = Vector3d::UnitZ();

StockBox box_mm(double x0, double y0, double z0, double x1, double y1, double z1) {
  StockBox box;
  box.min_m = Vector3d(x0, y0, z0) * 1e-3;
  box.max_m = Vector3d(x1, y1, z1) * 1e-3;
  return box;
}

std::vector<Vector3d> line(const Vector3d& from, const Vector3d& to, double step_m) {
  const int n = std::max(1, static_cast<int>(std::ceil((to - from).norm() / step_m)));
  std::vector<Vector3d> points;
  for (int k = 0; k <= n; ++k)
    points.push_back(from + (to - from) * (static_cast<double>(k) / n));
  return points;
}

// Engagement at every sample after the first, the stock cut as it goes. The
// feed is the chord from the previous sample unless `tangents` gives the
// path's direction at each sample (on an arc the chord lags the tangent by
// half the step's angle, which turns the whole engagement by as much).
std::vector<CutterEngagement> follow(DexelStock& stock, const CutterShape& cutter,
                                     const std::vector<Vector3d>& path, const EngagementGrid& grid,
                                     const std::vector<Vector3d>& tangents = {}) {
  std::vector<CutterEngagement> out;
  stock.remove(cutter, path.front(), kUp);
  for (std::size_t k = 1; k < path.size(); ++k) {
    const Vector3d feed = tangents.empty() ? Vector3d(path[k] - path[k - 1]) : tangents[k];
    out.push_back(engagement_at(stock, cutter, path[k], kUp, feed, grid));
    stock.remove_sweep(cutter, path[k - 1], kUp, path[k], kUp);
  }
  return out;
}

struct Case {
  double radius = 5e-3, res = 0.25e-3, step = 0.5e-3;
  CutterShape flat() const { return {radius, 0.0, 30e-3}; }
  CutterShape ball() const { return {radius, radius, 30e-3}; }
  EngagementGrid grid() const { return default_engagement_grid(flat(), res); }
  double dphi() const { return kPi / grid().angle_steps; }
  double inset() const { return 0.5 * res * res / radius + 1e-6; }
  double side_end() const { return std::asin(2 * inset() / step) + dphi(); }
  // An end set by a wall parallel to the answering rays, at angle φ.
  double wall_end(double phi) const {
    return 0.5 * dphi() + res / (2 * radius * std::abs(std::sin(phi)));
  }
};

TEST(CutterEngagement, DefaultGrid) {
  const CutterShape cutter{5e-3, 0.0, 30e-3};
  const EngagementGrid grid = default_engagement_grid(cutter, 0.5e-3);
  EXPECT_DOUBLE_EQ(grid.slice_height_m, 0.5e-3);
  EXPECT_EQ(grid.angle_steps, 63);  // R Δφ = res / 2
  EXPECT_DOUBLE_EQ(default_engagement_grid(cutter, 0.01e-3).slice_height_m, 0.15e-3);  // L / 200
  EXPECT_EQ(default_engagement_grid(cutter, 0.01e-3).angle_steps, 360);
}

TEST(CutterEngagement, InAirIsEmpty) {
  const Case s;
  const DexelStock stock(box_mm(0, 0, 0, 20, 20, 10), s.res);
  EXPECT_TRUE(engagement_at(stock, s.flat(), Vector3d(10e-3, 10e-3, 11e-3), kUp, Vector3d::UnitX(),
                            s.grid())
                  .empty());
}

TEST(CutterEngagement, FullSlotIsHalfATurnDeepAsTheCutAndWideAsTheCutter) {
  // Slot: φ ∈ [0, π], ap = depth, ae = D, section = D ap.
  const Case s;
  DexelStock stock(box_mm(0, 0, 0, 60, 30, 10), s.res);
  const double depth = 3e-3;
  const auto run = follow(
      stock, s.flat(),
      line(Vector3d(-6e-3, 15.03e-3, 7e-3), Vector3d(50e-3, 15.03e-3, 7e-3), s.step), s.grid());
  const double dz = s.grid().slice_height_m;
  int checked = 0;
  for (std::size_t k = 40; k < 90; ++k) {
    const CutterEngagement& e = run[k];
    ASSERT_FALSE(e.empty());
    EXPECT_NEAR(e.engaged_rad, kPi, 2 * s.side_end());
    EXPECT_NEAR(e.entry_rad, 0.0, s.side_end());
    EXPECT_NEAR(e.exit_rad, kPi, s.side_end());
    EXPECT_NEAR(e.axial_depth_m, depth, dz);
    EXPECT_NEAR(e.radial_width_m, 2 * s.radius, 2 * s.radius * (1 - std::cos(s.side_end())));
    EXPECT_NEAR(e.section_m2, 2 * s.radius * depth,
                2 * s.radius * dz + depth * 2 * s.radius * (1 - std::cos(s.side_end())));
    for (const EngagementSlice& slice : e.slices)
      EXPECT_LE(slice.arc_count, 1);
    ++checked;
  }
  EXPECT_EQ(checked, 50);
}

// A second pass beside a first (full-length) slot, ae into the wall; down
// milling with the material on −y (feed +x), up milling on the way back.
std::vector<CutterEngagement> side_cut(const Case& s, double ae, bool down) {
  DexelStock stock(box_mm(0, 0, 0, 60, 30, 10), s.res);
  const double y1 = 20.03e-3, y2 = y1 - ae, z = 7e-3;
  follow(stock, s.flat(), line(Vector3d(-6e-3, y1, z), Vector3d(66e-3, y1, z), s.step), s.grid());
  const Vector3d left(-6e-3, y2, z), right(66e-3, y2, z);
  return follow(stock, s.flat(), down ? line(left, right, s.step) : line(right, left, s.step),
                s.grid());
}

TEST(CutterEngagement, SideCutFollowsTheArccosLaw) {
  // Down: φ ∈ [acos(ae/R − 1), π]; up: φ ∈ [0, acos(1 − ae/R)]
  // (cutting/engagement.hpp, Altintas); ae = R (cos φst − cos φex).
  const Case s;
  for (double ae : {1e-3, 2e-3, 3.5e-3}) {
    for (bool down : {true, false}) {
      const auto run = side_cut(s, ae, down);
      const double boundary = down ? std::acos(ae / s.radius - 1) : std::acos(1 - ae / s.radius);
      for (std::size_t k = 40; k < 100; ++k) {
        const CutterEngagement& e = run[k];
        ASSERT_FALSE(e.empty());
        const double tol = s.wall_end(boundary);
        if (down) {
          EXPECT_NEAR(e.entry_rad, boundary, tol) << ae << " down, sample " << k;
          EXPECT_NEAR(e.exit_rad, kPi, s.side_end());
        } else {
          EXPECT_NEAR(e.entry_rad, 0.0, s.side_end());
          EXPECT_NEAR(e.exit_rad, boundary, tol) << ae << " up, sample " << k;
        }
        EXPECT_NEAR(e.radial_width_m, ae, s.radius * std::sin(boundary) * tol + s.radius * 0.01);
        EXPECT_NEAR(e.axial_depth_m, 3e-3, s.grid().slice_height_m);
      }
    }
  }
}

TEST(CutterEngagement, CrossingAnEarlierSlotSplitsTheArc) {
  // A slot along y (deeper) crossed by one along x: with the tool's centre a
  // gap g before the first slot's wall, the front half is in material on
  // [0, asin(g/R)] and [π − asin(g/R), π] (two arcs); inside the first slot,
  // beyond its far wall at distance g' ahead: [asin(g'/R), π − asin(g'/R)].
  const Case s;
  DexelStock stock(box_mm(0, 0, 0, 60, 30, 10), s.res);
  follow(stock, s.flat(), line(Vector3d(30e-3, -6e-3, 5e-3), Vector3d(30e-3, 36e-3, 5e-3), s.step),
         s.grid());
  const auto path = line(Vector3d(-6e-3, 15.03e-3, 7e-3), Vector3d(50e-3, 15.03e-3, 7e-3), s.step);
  const auto run = follow(stock, s.flat(), path, s.grid());
  int two = 0, one = 0;
  for (std::size_t k = 0; k < run.size(); ++k) {
    const double x = path[k + 1].x();
    const double gap = 25e-3 - x, beyond = 35e-3 - x;
    if (run[k].slices.size() <= 6)
      continue;                                       // not engaged up there (checked below)
    const EngagementSlice& slice = run[k].slices[6];  // 1.6 mm above the tip
    if (gap > 0.5e-3 && gap < 4e-3) {
      const double phi = std::asin(gap / s.radius);
      ASSERT_EQ(slice.arc_count, 2) << "x = " << x;
      EXPECT_NEAR(slice.arcs[0].entry_rad, 0.0, s.side_end());
      EXPECT_NEAR(slice.arcs[0].exit_rad, phi, s.wall_end(kPi / 2 - phi));
      EXPECT_NEAR(slice.arcs[1].entry_rad, kPi - phi, s.wall_end(kPi / 2 - phi));
      EXPECT_NEAR(slice.arcs[1].exit_rad, kPi, s.side_end());
      ++two;
    } else if (gap < -0.5e-3 && beyond > 1e-3 && beyond < 4.5e-3) {
      const double phi = std::asin(beyond / s.radius);
      ASSERT_EQ(slice.arc_count, 1) << "x = " << x;
      EXPECT_NEAR(slice.arcs[0].entry_rad, phi, s.wall_end(kPi / 2 - phi));
      EXPECT_NEAR(slice.arcs[0].exit_rad, kPi - phi, s.wall_end(kPi / 2 - phi));
      ++one;
    }
  }
  EXPECT_GT(two, 4);
  EXPECT_GT(one, 4);
}

TEST(CutterEngagement, InnerCornerArcFollowsTheConcentricWallLaw) {
  // A tool of radius R moving counter-clockwise on a circle of radius rc
  // about O, inside a concentric wall of radius rw = rc + R − ae that an
  // earlier pass left: an edge point at angle θ from the outward radial
  // direction is at distance² rc² + R² + 2 rc R cos θ from O, so it is in
  // material for cos θ ≥ (rw² − rc² − R²) / (2 rc R). The points behind the
  // outward direction were cut by this pass's earlier positions (rc > R), so
  // the engagement is down-milling from π − φc to π (outward = −y) with
  // φc = acos((rw² − rc² − R²) / (2 rc R)), more than the straight cut's
  // acos(1 − ae/R) (rc → ∞).
  const Case s;
  const double rc = 6e-3, ae = 2e-3, rw = rc + s.radius - ae;
  const double phi_c = std::acos((rw * rw - rc * rc - s.radius * s.radius) / (2 * rc * s.radius));
  ASSERT_GT(phi_c - std::acos(1 - ae / s.radius), 0.25);  // 70.5° against 53.1°
  DexelStock stock(box_mm(0, 0, 0, 40, 40, 10), s.res);
  const Vector3d centre(20.02e-3, 19.97e-3, 7e-3);
  stock.remove(CutterShape{rw, 0.0, 30e-3}, centre, kUp);
  std::vector<Vector3d> path, tangents;
  const double dtheta = s.step / rc;
  for (double theta = 0.0; theta < 2 * kPi; theta += dtheta) {
    path.push_back(centre + rc * Vector3d(std::cos(theta), std::sin(theta), 0.0));
    tangents.push_back(Vector3d(-std::sin(theta), std::cos(theta), 0.0));
  }
  const auto run = follow(stock, s.flat(), path, s.grid(), tangents);
  double peak = 0.0;
  int checked = 0;
  for (std::size_t k = 0; k < run.size(); ++k) {
    const double theta = (k + 1) * dtheta;
    if (theta < kPi / 3 || theta > 5 * kPi / 3)
      continue;  // away from the entry
    const CutterEngagement& e = run[k];
    ASSERT_FALSE(e.empty());
    EXPECT_NEAR(e.entry_rad, kPi - phi_c, s.wall_end(phi_c)) << theta;
    EXPECT_NEAR(e.exit_rad, kPi, s.side_end());
    peak = std::max(peak, e.engaged_rad);
    ++checked;
  }
  EXPECT_GT(checked, 30);
  EXPECT_NEAR(peak, phi_c, s.wall_end(phi_c) + s.side_end());
}

TEST(CutterEngagement, HelicalRampCutsOnePitchPerRevolution) {
  // A flat cutter descending a helix of pitch p meets, one revolution later,
  // the floor it left p higher: ap = p (the material just beside the tool,
  // at φ → 0 and π, is the previous revolution's floor at the same angle).
  const Case s;
  const double rh = 3e-3, pitch = 2e-3;
  DexelStock stock(box_mm(0, 0, 0, 30, 30, 12), s.res);
  const Vector3d centre(15.01e-3, 14.98e-3, 10e-3);
  const double dtheta = s.step / rh;
  std::vector<Vector3d> path, tangents;
  for (double theta = 0.0; theta < 3 * 2 * kPi; theta += dtheta) {
    path.push_back(
        centre + Vector3d(rh * std::cos(theta), rh * std::sin(theta), -pitch * theta / (2 * kPi)));
    tangents.push_back(Vector3d(-rh * std::sin(theta), rh * std::cos(theta), -pitch / (2 * kPi)));
  }
  // The chords (0.5 mm on a 3 mm radius) leave the bore's wall up to
  // f² / (8 rh) = 10 µm inside the true helix, more than the automatic inset:
  // the test points must sit deeper or that wall reads as material all the
  // way up (ap = the bore's depth). 1.5 × the sagitta.
  EngagementGrid grid = s.grid();
  grid.surface_inset_m = std::max(s.inset(), 1.5 * s.step * s.step / (8 * rh));
  const auto run = follow(stock, s.flat(), path, grid, tangents);
  const double dz = grid.slice_height_m;
  int checked = 0;
  for (std::size_t k = 0; k < run.size(); ++k) {
    if ((k + 1) * dtheta < 2 * 2 * kPi)
      continue;  // the third revolution
    EXPECT_NEAR(run[k].axial_depth_m, pitch, dz + s.res / 2) << k;
    ++checked;
  }
  EXPECT_GT(checked, 20);
}

TEST(CutterEngagement, BallInAFlatBottomedSlotCutsOnlyBelowTheFloor) {
  // A ball of radius R run e below the floor of a flat slot of width 2R: its
  // edge is engaged only below the floor (h < e), over the whole front half,
  // and the section is the circular segment of height e:
  // R² acos((R − e)/R) − (R − e) sqrt(2Re − e²).
  const Case s;
  const double e = 1.5e-3, floor_z = 7e-3;
  DexelStock stock(box_mm(0, 0, 0, 60, 30, 10), s.res);
  const Vector3d a(-6e-3, 15.03e-3, floor_z), b(66e-3, 15.03e-3, floor_z);
  follow(stock, s.flat(), line(a, b, s.step), s.grid());
  const Vector3d down(0, 0, -e);
  const auto run = follow(stock, s.ball(), line(a + down, b + down, s.step), s.grid());
  const double dz = s.grid().slice_height_m, r = s.radius;
  const double segment = r * r * std::acos((r - e) / r) - (r - e) * std::sqrt(2 * r * e - e * e);
  for (std::size_t k = 40; k < 100; ++k) {
    const CutterEngagement& c = run[k];
    ASSERT_FALSE(c.empty());
    EXPECT_NEAR(c.axial_depth_m, e, dz + s.res / 2);
    for (const EngagementSlice& slice : c.slices) {
      if (slice.height_m + 0.5 * dz < e - s.res / 2) {
        EXPECT_NEAR(slice.engaged_rad(), kPi, 2 * s.side_end() + s.res / slice.radius_m);
      }
    }
    // One slice of width 2R at the top and the placement of the floor.
    EXPECT_NEAR(c.section_m2, segment, 2 * r * (dz / 2 + s.res / 2));
  }
}

TEST(CutterEngagement, PlungeEngagesTheWholeTurn) {
  // Feed along the axis: the whole turn [0, 2π] of the slices below the last
  // sample's tip (ap = the step down), and the section normal to the feed is
  // the cutter's disk π R².
  const Case s;
  DexelStock stock(box_mm(0, 0, 0, 30, 30, 10), s.res);
  const double step = 0.5e-3;
  const auto run =
      follow(stock, s.flat(),
             line(Vector3d(15.01e-3, 14.98e-3, 12e-3), Vector3d(15.01e-3, 14.98e-3, 6e-3), step),
             s.grid());
  const double dz = s.grid().slice_height_m;
  int checked = 0;
  for (std::size_t k = 0; k < run.size(); ++k) {
    const double tip_z = 12e-3 - (k + 1) * step;
    if (tip_z > 9.4e-3)
      continue;
    const CutterEngagement& e = run[k];
    ASSERT_FALSE(e.empty()) << tip_z;
    EXPECT_NEAR(e.axial_depth_m, step, dz);
    EXPECT_DOUBLE_EQ(e.engaged_rad, 2 * kPi);
    EXPECT_NEAR(e.radial_width_m, 2 * s.radius, 1e-12);
    EXPECT_NEAR(e.section_m2, kPi * s.radius * s.radius, 1e-12);
    ++checked;
  }
  EXPECT_GT(checked, 5);
}

}  // namespace

}  // namespace test_cutter_engagement_cpp
