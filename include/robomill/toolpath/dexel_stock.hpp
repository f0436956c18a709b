#pragma once
// The stock as a tri-dexel model: three orthogonal grids of rays (along x, y
// and z), each ray holding the sorted intervals of material it crosses.
// Removal subtracts the cutter's solid from every ray it crosses, exactly
// along the ray and to the grid spacing across it, for any tool axis — the
// representation 5-axis material removal needs (a height map cannot hold an
// undercut). DESIGN.md §1, toolpath stage.
//
// Immutable description (StockBox, resolution) and mutable state (the rays)
// live in one class because removal is sequential along the program; queries
// are const and thread-safe.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "robomill/toolpath/cutter_shape.hpp"

namespace robomill::toolpath {

/// An axis-aligned box in the workpiece frame (m).
struct StockBox {
  Eigen::Vector3d min_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d max_m = Eigen::Vector3d::Zero();
};

/// One interval of material along a ray, [from, to] in the ray's coordinate.
struct DexelInterval {
  float from_m = 0.0f, to_m = 0.0f;
};

class DexelStock {
 public:
  /// A full box sampled every `resolution_m` in each direction (ray centres at
  /// half-cell offsets). Throws std::invalid_argument for an empty box, a
  /// non-positive resolution, or more than `max_rays` rays in all.
  DexelStock(const StockBox& box, double resolution_m, std::size_t max_rays = 50'000'000);

  /// A stock whose top is the height map an earlier program left: cell (i, j)
  /// of a grid of nx × ny cells over the box's x-y extent holds material from
  /// box.min z up to heights_m[j * nx + i] (clamped to the box).
  static DexelStock from_height_map(const StockBox& box, double resolution_m, int nx, int ny,
                                    const std::vector<double>& heights_m);

  /// Removes the cutter's solid placed with its tip at `tip_m` and its axis
  /// (unit, tip → spindle) along `axis`. Returns the number of ray intervals
  /// changed (0: the cutter touched nothing).
  std::size_t remove(const CutterShape& cutter, const Eigen::Vector3d& tip_m,
                     const Eigen::Vector3d& axis);

  /// Removes the volume swept by the cutter from (tip0, axis0) to (tip1,
  /// axis1) along a straight line. When the axis stays +z (3-axis motion,
  /// ramps included) the swept solid is intersected with every ray exactly
  /// (a stadium and a capsule, no instances); otherwise as instances no
  /// further apart than a quarter of the resolution at any point of the
  /// cutter (the scallop between instances is then below resolution² / (128 R)).
  std::size_t remove_sweep(const CutterShape& cutter, const Eigen::Vector3d& tip0_m,
                           const Eigen::Vector3d& axis0, const Eigen::Vector3d& tip1_m,
                           const Eigen::Vector3d& axis1);

  /// Whether `point_m` is in material: material_depth_m(point, normal) > 0.
  /// `normal` (unit) is the direction across which the caller needs the
  /// answer sharp (the cutter surface's normal at the point): the ray grid
  /// most nearly along it answers, since it is exact along its own direction.
  bool contains(const Eigen::Vector3d& point_m, const Eigen::Vector3d& normal) const noexcept;

  /// Signed depth of `point_m` in the material, measured along the rays of
  /// the grid most nearly along `normal`: on each of the four rays around the
  /// point, the distance from the point's coordinate to the nearest end of
  /// the material (positive inside an interval, negative outside, clamped to
  /// ±3 cells), interpolated bilinearly across the rays. For a boundary
  /// surface the interpolation is exact where the surface is plane and off by
  /// about 0.35 resolution² × curvature where it is curved, instead of the
  /// half-cell snapping of the nearest ray alone.
  double material_depth_m(const Eigen::Vector3d& point_m,
                          const Eigen::Vector3d& normal) const noexcept;

  /// The stretch of material through a point along a direction, from the
  /// ray nearest the point of the grid most nearly along `direction` (or,
  /// where that ray holds no material there, the nearest of the four around
  /// the point that does): how far
  /// (measured along `direction`, unit) the material goes on before and
  /// after the point. Exact where the material ends in a face normal to
  /// that ray (a flat floor or top under a tilted axis too: the ray's
  /// distance is divided by |direction · ray|); to the grid spacing across
  /// the ray. Empty when that ray holds no material at the point.
  struct MaterialRun {
    double before_m = 0.0;  ///< back along −direction to the material's end
    double after_m = 0.0;   ///< on along +direction to the material's end
  };
  std::optional<MaterialRun> material_run(const Eigen::Vector3d& point_m,
                                          const Eigen::Vector3d& direction) const noexcept;

  /// Material volume (m³), from the z rays (each ray's length × cell area).
  double volume_m3() const noexcept;

  /// Top of the material in each z ray (the height map), row-major with x
  /// fastest: count_x × count_y values; box.min z where a ray is empty.
  std::vector<double> top_heights_m() const;

  const StockBox& box() const noexcept { return box_; }
  double resolution_m() const noexcept { return resolution_m_; }
  /// Cells along x, y, z.
  const std::array<int, 3>& counts() const noexcept { return counts_; }
  /// Cell size along axis a: the box's extent over counts()[a], at most the
  /// resolution (the cells tile the box exactly).
  double cell_size_m(int axis) const noexcept { return cell_m_[axis]; }
  /// Centre of cell index i along axis a.
  double cell_centre_m(int axis, int index) const noexcept;

  /// Bytes held by the rays (for the benchmark's memory figure).
  std::size_t memory_bytes() const noexcept;

 private:
  // One grid of parallel rays: rays along `axis`, indexed by the cells of the
  // two other axes (u fastest). A ray's intervals are in metres from the box's
  // min along `axis`. Rays with at most one interval (most of them) keep it in
  // `first` (from > to: empty); a ray split into more moves all its intervals
  // to a pooled overflow vector (`slot` = index + 1), and back when it is down
  // to one, so memory grows with the stock's complexity, not with the
  // program's length.
  struct Grid {
    int axis = 2, u = 0, v = 1;
    int count_u = 0, count_v = 0;
    std::vector<DexelInterval> first;
    std::vector<std::uint32_t> slot;
    std::vector<std::vector<DexelInterval>> overflow;
    std::vector<std::uint32_t> free_slots;
  };
  friend struct DexelAccess;

  StockBox box_;
  double resolution_m_ = 0.0;
  std::array<int, 3> counts_{0, 0, 0};
  std::array<double, 3> cell_m_{0.0, 0.0,
                                0.0};  ///< cell size per axis (≤ resolution, tiles the box)
  std::array<Grid, 3> grids_;
};

}  // namespace robomill::toolpath
