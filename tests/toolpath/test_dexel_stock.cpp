// Tri-dexel stock (toolpath/dexel_stock.hpp): volumes removed against closed
// forms. The z rays carry the volume; a ray stands for its whole cell, so a
// removed solid's volume is off by the cells its boundary crosses, each
// counted in or out whole by its centre. Those errors have either sign and
// cancel along a boundary; a systematic shift of the boundary by a quarter
// cell would not. The tolerances below are that quarter cell over the
// boundary's projected length (perimeter × depth × res / 4), which is what
// the resolution allows and what a missing row or column would break.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "robomill/tool/tool.hpp"
#include "robomill/toolpath/cutter_shape.hpp"
#include "robomill/toolpath/dexel_stock.hpp"

namespace test_dexel_stock_cpp {

namespace {

using namespace robomill::toolpath;
using Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

StockBox box_mm(double x0, double y0, double z0, double x1, double y1, double z1) {
  StockBox box;
  box.min_m = Vector3d(x0, y0, z0) * 1e-3;
  box.max_m = Vector3d(x1, y1, z1) * 1e-3;
  return box;
}

CutterShape flat(double radius_m, double length_m = 30e-3) {
  return {radius_m, 0.0, length_m};
}
CutterShape ball(double radius_m, double length_m = 30e-3) {
  return {radius_m, radius_m, length_m};
}

TEST(CutterShape, RadiusAlongTheAxis) {
  robomill::tool::ToolSpec spec;
  spec.type = robomill::tool::ToolType::ball;
  spec.diameter_m = 8e-3;
  spec.teeth = 2;
  spec.overhang_m = 25e-3;
  const CutterShape shape = cutter_shape(robomill::tool::Tool(spec));
  EXPECT_TRUE(shape.is_ball());
  EXPECT_DOUBLE_EQ(shape.radius_m, 4e-3);
  EXPECT_DOUBLE_EQ(shape.length_m, 25e-3);
  // Ball: r(h) = sqrt(h (2R − h)) below the equator, R above.
  EXPECT_NEAR(shape.radius_at(1e-3), std::sqrt(1e-3 * 7e-3), 1e-15);
  EXPECT_DOUBLE_EQ(shape.radius_at(4e-3), 4e-3);
  EXPECT_DOUBLE_EQ(shape.radius_at(10e-3), 4e-3);
  EXPECT_DOUBLE_EQ(flat(5e-3).radius_at(0.0), 5e-3);
}

TEST(DexelStock, FullBoxVolumeIsExact) {
  // Cells tile the box (a resolution that does not divide it is shrunk to
  // one that does), so the full box's volume is exact to the float rounding
  // of a ray's length (relative 6e-8).
  const DexelStock stock(box_mm(-3, 2, 1, 27, 22, 11), 0.7e-3);
  EXPECT_NEAR(stock.volume_m3(), 30e-3 * 20e-3 * 10e-3, 1e-7 * 6e-6);
  EXPECT_LE(stock.cell_size_m(0), 0.7e-3);
  EXPECT_EQ(stock.counts()[0], 43);  // ceil(30 / 0.7)
}

TEST(DexelStock, RejectsEmptyBoxAndBadResolution) {
  EXPECT_THROW(DexelStock(box_mm(0, 0, 0, 0, 10, 10), 1e-3), std::invalid_argument);
  EXPECT_THROW(DexelStock(box_mm(0, 0, 0, 10, 10, 10), 0.0), std::invalid_argument);
  EXPECT_THROW(DexelStock(box_mm(0, 0, 0, 1000, 1000, 1000), 1e-5, 1000), std::invalid_argument);
}

TEST(DexelStock, VerticalFlatPlungeRemovesACylinder) {
  // V = π R² d, the circle's boundary crossing 2πR d / res cells.
  const double radius = 5e-3, depth = 4e-3, res = 0.25e-3;
  DexelStock stock(box_mm(0, 0, 0, 40, 40, 20), res);
  const double before = stock.volume_m3();
  EXPECT_GT(stock.remove(flat(radius), Vector3d(20.1e-3, 19.93e-3, 16e-3), Vector3d::UnitZ()), 0u);
  const double removed = before - stock.volume_m3();
  EXPECT_NEAR(removed, kPi * radius * radius * depth, 2 * kPi * radius * depth * res / 4);
}

TEST(DexelStock, StraightSlotRemovesRectanglePlusTwoHalfDisks) {
  // V = L D ap + π R² ap, R/20 resolution, within 1 % (the quarter-cell
  // boundary bound is 0.6 % here).
  const double radius = 5e-3, length = 30e-3, ap = 3e-3, res = radius / 20;
  DexelStock stock(box_mm(0, 0, 0, 50, 30, 10), res);
  const double before = stock.volume_m3();
  const Vector3d start(10.03e-3, 15.07e-3, 7e-3), end = start + Vector3d(length, 0, 0);
  stock.remove_sweep(flat(radius), start, Vector3d::UnitZ(), end, Vector3d::UnitZ());
  const double expected = length * 2 * radius * ap + kPi * radius * radius * ap;
  EXPECT_NEAR(before - stock.volume_m3(), expected, 0.01 * expected);
  EXPECT_NEAR(before - stock.volume_m3(), expected, (2 * length + 2 * kPi * radius) * ap * res / 4);
}

TEST(DexelStock, DiagonalRampedSlotMatchesInstances) {
  // The exact sweep (stadium + capsule) and instances a quarter cell apart
  // cut the same volume, to the instances' scallops (res² / (128 R) deep
  // along the two walls) and the boundary cells.
  const double radius = 4e-3, res = 0.25e-3;
  for (const CutterShape& cutter : {flat(radius), ball(radius)}) {
    DexelStock exact(box_mm(0, 0, 0, 40, 40, 15), res), instances = exact;
    const Vector3d start(8e-3, 9e-3, 12e-3), end(30e-3, 27e-3, 9e-3);
    exact.remove_sweep(cutter, start, Vector3d::UnitZ(), end, Vector3d::UnitZ());
    // A vanishing tilt sends the sweep down the instances path.
    const Vector3d tilted = Vector3d(1e-7, 0, 1).normalized();
    instances.remove_sweep(cutter, start, tilted, end, tilted);
    const double v0 = DexelStock(box_mm(0, 0, 0, 40, 40, 15), res).volume_m3();
    const double removed = v0 - exact.volume_m3();
    const double length = (end - start).norm();
    EXPECT_GT(removed, 0.0);
    EXPECT_NEAR(v0 - instances.volume_m3(), removed,
                (2 * length + 2 * kPi * radius) * 3e-3 * res / 4)
        << (cutter.is_ball() ? "ball" : "flat");
  }
}

TEST(DexelStock, BallGrooveIsACircularSegmentTimesLength) {
  // A ball of radius R sunk e below the top cuts a groove whose section is
  // the circular segment R² acos((R − e)/R) − (R − e) sqrt(2Re − e²), plus at
  // the two ends half a spherical cap each: π e² (3R − e) / 3 in all.
  const double radius = 4e-3, e = 2e-3, length = 30e-3, res = radius / 20;
  DexelStock stock(box_mm(0, 0, 0, 50, 20, 10), res);
  const double before = stock.volume_m3();
  const Vector3d start(10e-3, 10.05e-3, 8e-3), end = start + Vector3d(length, 0, 0);
  stock.remove_sweep(ball(radius), start, Vector3d::UnitZ(), end, Vector3d::UnitZ());
  const double section = radius * radius * std::acos((radius - e) / radius) -
                         (radius - e) * std::sqrt(2 * radius * e - e * e);
  const double expected = section * length + kPi * e * e * (3 * radius - e) / 3;
  EXPECT_NEAR(before - stock.volume_m3(), expected, 0.01 * expected);
}

TEST(DexelStock, TiltedCutterRemovesTheSameVolume) {
  // A cutter buried in the stock removes its own volume whatever its axis:
  // π R² L (flat), π R² (L − R) + 2/3 π R³ (ball). Tolerance: a quarter cell
  // over the solid's surface.
  const double radius = 3e-3, length = 8e-3, res = 0.2e-3;
  const Vector3d tip(20.02e-3, 19.97e-3, 10.01e-3);
  for (const CutterShape& cutter : {flat(radius, length), ball(radius, length)}) {
    const double expected = cutter.is_ball() ? kPi * radius * radius * (length - radius) +
                                                   2.0 / 3.0 * kPi * std::pow(radius, 3)
                                             : kPi * radius * radius * length;
    const double surface = 2 * kPi * radius * length + 2 * kPi * radius * radius;
    for (const Vector3d& axis :
         {Vector3d(0, 0, 1), Vector3d(1, 0, 0), Vector3d(0.3, -0.5, 0.8).normalized(),
          Vector3d(-0.6, 0.7, 0.2).normalized()}) {
      DexelStock stock(box_mm(0, 0, 0, 40, 40, 40), res);
      const double before = stock.volume_m3();
      stock.remove(cutter, tip, axis);
      EXPECT_NEAR(before - stock.volume_m3(), expected, surface * res / 4)
          << axis.transpose() << (cutter.is_ball() ? " ball" : " flat");
    }
  }
}

TEST(DexelStock, HeightMapRoundTrips) {
  // On the stock's own x-y grid the height map is the z rays' tops exactly
  // (to float rounding of a ray coordinate, 1e-9 m on a 10 mm box).
  const StockBox box = box_mm(0, 0, -5, 20, 10, 5);
  const double res = 0.5e-3;
  const int nx = 40, ny = 20;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> height(-6e-3, 6e-3);  // some beyond the box: clamped
  std::vector<double> heights(nx * ny);
  for (double& h : heights)
    h = height(rng);
  const DexelStock stock = DexelStock::from_height_map(box, res, nx, ny, heights);
  const std::vector<double> tops = stock.top_heights_m();
  ASSERT_EQ(tops.size(), heights.size());
  double volume = 0.0;
  for (std::size_t k = 0; k < tops.size(); ++k) {
    const double clamped = std::clamp(heights[k], -5e-3, 5e-3);
    EXPECT_NEAR(tops[k], clamped, 1e-9);
    volume += (clamped + 5e-3) * res * res;
  }
  EXPECT_NEAR(stock.volume_m3(), volume, 1e-7 * volume);  // float ray ends
  // The vertical rays answer a quarter cell below and above each top; the
  // horizontal rays, parallel to the tops, hold a column's material where
  // the column reaches above the ray (asked at the ray itself: across its own
  // direction a grid cannot place a surface parallel to it).
  for (int j = 1; j < ny - 1; j += 3) {
    for (int i = 1; i < nx - 1; i += 3) {
      const double top = std::clamp(heights[j * nx + i], -5e-3, 5e-3);
      const Vector3d centre(stock.cell_centre_m(0, i), stock.cell_centre_m(1, j), 0.0);
      if (top > -4.8e-3) {
        EXPECT_TRUE(stock.contains(centre + Vector3d(0, 0, top - 0.25 * res), Vector3d::UnitZ()));
      }
      if (top < 4.8e-3) {
        EXPECT_FALSE(stock.contains(centre + Vector3d(0, 0, top + 0.25 * res), Vector3d::UnitZ()));
      }
      for (int k = 0; k < stock.counts()[2]; ++k) {
        const Vector3d at(centre.x(), centre.y(), stock.cell_centre_m(2, k));
        EXPECT_EQ(stock.contains(at, Vector3d::UnitX()), top > at.z());
        EXPECT_EQ(stock.contains(at, Vector3d::UnitY()), top > at.z());
      }
    }
  }
}

TEST(DexelStock, ContainsOnTheBoxFaces) {
  // Along its own rays a grid is exact; across them the interpolation between
  // the last row and the air beyond puts the face at the box too. A point a
  // tenth of a cell inside a face is material, a tenth outside is not, for
  // every grid answering.
  const StockBox box = box_mm(0, 0, 0, 10, 8, 6);
  const double res = 0.5e-3;
  const DexelStock stock(box, res);
  const Vector3d centre = 0.5 * (box.min_m + box.max_m);
  for (int axis = 0; axis < 3; ++axis) {
    for (double side : {-1.0, 1.0}) {
      Vector3d face = centre;
      face[axis] = side > 0 ? box.max_m[axis] : box.min_m[axis];
      Vector3d outward = Vector3d::Zero();
      outward[axis] = side;
      for (int g = 0; g < 3; ++g) {
        Vector3d normal = Vector3d::Zero();
        normal[g] = 1.0;
        EXPECT_TRUE(stock.contains(face - 0.1 * res * outward, normal)) << axis << side << g;
        EXPECT_FALSE(stock.contains(face + 0.1 * res * outward, normal)) << axis << side << g;
      }
    }
  }
  EXPECT_TRUE(stock.contains(centre, Vector3d::UnitZ()));
  EXPECT_FALSE(stock.contains(centre + Vector3d(1, 0, 0), Vector3d::UnitZ()));
}

TEST(DexelStock, ThroughSlotSplitsRaysAndReadsAsAir) {
  // A slot across the stock splits the x rays below the top into two
  // intervals; inside the slot is air, beside it material, for any grid.
  const double radius = 3e-3, res = 0.25e-3;
  DexelStock stock(box_mm(0, 0, 0, 30, 20, 10), res);
  stock.remove_sweep(flat(radius), Vector3d(15e-3, -5e-3, 6e-3), Vector3d::UnitZ(),
                     Vector3d(15e-3, 25e-3, 6e-3), Vector3d::UnitZ());
  for (const Vector3d& normal : {Vector3d(1, 0, 0), Vector3d(0, 1, 0), Vector3d(0, 0, 1)}) {
    EXPECT_FALSE(stock.contains(Vector3d(15e-3, 10e-3, 8e-3), normal));
    EXPECT_FALSE(stock.contains(Vector3d(17.5e-3, 3e-3, 6.5e-3), normal));
    EXPECT_TRUE(stock.contains(Vector3d(18.5e-3, 10e-3, 8e-3), normal));
    EXPECT_TRUE(stock.contains(Vector3d(15e-3, 10e-3, 5.5e-3), normal));
  }
  const double expected = 20e-3 * 2 * radius * 4e-3;
  EXPECT_NEAR(DexelStock(box_mm(0, 0, 0, 30, 20, 10), res).volume_m3() - stock.volume_m3(),
              expected, 2 * 20e-3 * 4e-3 * res / 4);
}

TEST(DexelStock, MemoryGrowsWithTheStockNotTheProgram) {
  // A fresh stock holds 12 bytes per ray (one float interval and an overflow
  // index); re-cutting the same raster many times adds nothing, since split
  // rays come back from the pool.
  const double res = 0.5e-3;
  DexelStock stock(box_mm(0, 0, 0, 40, 30, 10), res);
  const std::size_t rays = 60 * 20 + 80 * 20 + 80 * 60;
  EXPECT_EQ(stock.memory_bytes(), 12 * rays);
  auto raster = [&](double depth_m) {
    for (int pass = 0; pass < 6; ++pass) {
      const double y = (4 + 4 * pass) * 1e-3;
      stock.remove_sweep(flat(3e-3), Vector3d(5e-3, y, 10e-3 - depth_m), Vector3d::UnitZ(),
                         Vector3d(35e-3, y, 10e-3 - depth_m), Vector3d::UnitZ());
      // A tilted plunge beside each pass splits x and y rays too.
      stock.remove(flat(1e-3), Vector3d(20e-3, y, 5e-3), Vector3d(0.3, 0.2, 1).normalized());
    }
  };
  raster(2e-3);
  const std::size_t after_one = stock.memory_bytes();
  for (int repeat = 0; repeat < 50; ++repeat)
    raster(2e-3);
  EXPECT_EQ(stock.memory_bytes(), after_one);
  EXPECT_LT(after_one, 2 * 12 * rays);
}

// Issue 31, point 2: a bull nose (corner r_c between 0 and R) in the stock.
// Buried at any axis it removes its own volume, π R² (L − r_c) plus the
// corner's solid of revolution π [R'² r_c + R' π r_c² / 2 + 2 r_c³ / 3]
// (R' = R − r_c), through the numerical ray-torus search; a level groove
// (the exact stadium sweep) and the same groove as instances (the search)
// remove the same volume.
CutterShape bull(double radius_m, double corner_m, double length_m = 30e-3) {
  return {radius_m, corner_m, length_m};
}

TEST(DexelStock, BuriedBullNoseRemovesItsVolumeAtAnyAxis) {
  const double radius = 5e-3, corner = 1.7e-3, length = 12e-3, res = 0.2e-3;
  const double inner = radius - corner;
  const double expected = kPi * radius * radius * (length - corner) +
                          kPi * (inner * inner * corner + inner * kPi * corner * corner / 2 +
                                 2 * corner * corner * corner / 3);
  for (const Vector3d& axis : {Vector3d(0, 0, 1), Vector3d(0.3, -0.2, 1).normalized(),
                               Vector3d(1, 0.4, 0.2).normalized()}) {
    DexelStock stock(box_mm(0, 0, 0, 40, 40, 40), res);
    const double before = stock.volume_m3();
    const Vector3d tip = Vector3d(20.03e-3, 19.91e-3, 20.07e-3) - 0.5 * length * axis;
    stock.remove(bull(radius, corner, length), tip, axis);
    const double area = 2 * kPi * radius * length + 2 * kPi * radius * radius;
    EXPECT_NEAR(before - stock.volume_m3(), expected, area * res / 4) << axis.transpose();
  }
}

TEST(DexelStock, BullNoseGrooveExactAndAsInstancesAgree) {
  // The groove's section at depth e < r_c: 2 [R' e + ∫ √(r_c² − u²) du over
  // [r_c − e, r_c]]; over a long groove the ends are a small share, bounded
  // here by the volume of a whole bull-nose end cap at each end.
  const double radius = 4e-3, corner = 1.5e-3, e = 1.1e-3, res = 0.25e-3, length = 20e-3;
  const Vector3d start(10e-3, 10.05e-3, 8e-3 - e), end = start + Vector3d(length, 0, 0);
  DexelStock exact(box_mm(0, 0, 0, 50, 20, 8), res), instances = exact;
  const double before = exact.volume_m3();
  exact.remove_sweep(bull(radius, corner), start, Vector3d::UnitZ(), end, Vector3d::UnitZ());
  const Vector3d tilted = Vector3d(1e-7, 0, 1).normalized();
  instances.remove_sweep(bull(radius, corner), start, tilted, end, tilted);
  auto antiderivative = [&](double u) {
    return 0.5 * u * std::sqrt(std::max(0.0, corner * corner - u * u)) +
           0.5 * corner * corner * std::asin(std::clamp(u / corner, -1.0, 1.0));
  };
  const double section =
      2 * ((radius - corner) * e + antiderivative(corner) - antiderivative(corner - e));
  const double removed = before - exact.volume_m3();
  EXPECT_GT(removed, section * length);
  EXPECT_LT(removed, section * length + kPi * radius * radius * e);
  EXPECT_NEAR(before - instances.volume_m3(), removed,
              (2 * length + 2 * kPi * radius) * e * res / 4);
}

// DexelStock::material_run: the z ray gives the material's ends along any
// direction through a flat top and floor, the ray's distance divided by the
// direction's z share.
TEST(DexelStock, MaterialRunAlongATiltedDirection) {
  DexelStock stock(box_mm(0, 0, 0, 30, 30, 10.37), 0.5e-3);
  const Vector3d point(15.1e-3, 14.8e-3, 4.2e-3);
  const auto up = stock.material_run(point, Vector3d::UnitZ());
  ASSERT_TRUE(up.has_value());
  EXPECT_NEAR(up->after_m, 6.17e-3, 1e-8);
  EXPECT_NEAR(up->before_m, 4.2e-3, 1e-8);
  const Vector3d tilted = Vector3d(0.3, -0.2, 1).normalized();
  const auto along = stock.material_run(point, tilted);
  ASSERT_TRUE(along.has_value());
  EXPECT_NEAR(along->after_m, 6.17e-3 / tilted.z(), 1e-8);
  EXPECT_FALSE(stock.material_run(Vector3d(15e-3, 15e-3, 11e-3), Vector3d::UnitZ()).has_value());
}

// A cutter instance removes the same material wherever the stock's box
// sits: the same tilted removal in a box at the origin and in one moved by
// (−37.3, 12.9, 101.7) mm, the cutter moved with it, leaves the same volume
// and the same top heights. (Before issue 31 the instances of a tilted axis
// were cut offset by the box's min: nothing at all was removed from a stock
// whose box lay far from the origin.)
TEST(DexelStock, TiltedRemovalDoesNotDependOnWhereTheBoxSits) {
  const Vector3d shift(-37.3e-3, 12.9e-3, 101.7e-3);
  StockBox here = box_mm(0, 0, 0, 30, 30, 20), there = here;
  there.min_m += shift;
  there.max_m += shift;
  DexelStock a(here, 0.3e-3), b(there, 0.3e-3);
  const Vector3d axis = Vector3d(0.35, -0.2, 1).normalized();
  const Vector3d tip0(8e-3, 9e-3, 16e-3), tip1(22e-3, 20e-3, 15e-3);
  for (const CutterShape& cutter : {ball(3e-3), flat(3e-3), bull(3e-3, 1e-3)}) {
    a.remove_sweep(cutter, tip0, axis, tip1, axis);
    b.remove_sweep(cutter, tip0 + shift, axis, tip1 + shift, axis);
  }
  const double full = 30e-3 * 30e-3 * 20e-3;
  EXPECT_GT(full - a.volume_m3(), 1e-7);
  EXPECT_NEAR(a.volume_m3(), b.volume_m3(), 1e-6 * full);
  const std::vector<double> ha = a.top_heights_m(), hb = b.top_heights_m();
  ASSERT_EQ(ha.size(), hb.size());
  for (std::size_t i = 0; i < ha.size(); ++i)
    EXPECT_NEAR(ha[i] + shift.z(), hb[i], 1e-7) << i;
}

}  // namespace

}  // namespace test_dexel_stock_cpp
