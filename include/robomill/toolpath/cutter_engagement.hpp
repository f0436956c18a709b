#pragma once
// Cutter-workpiece engagement (CWE) of a cutter at one position on a dexel
// stock: which parts of the cutting edge are in material, slice by slice along
// the tool axis (DESIGN.md §1, toolpath stage).
//
// The local tool frame is tool/tool.hpp's: z along the tool axis (tip →
// spindle), x along the feed direction's component normal to the axis, y = z ×
// x. Edge angles φ are measured clockwise (seen from the spindle) from +y, a
// point at angle φ and radius r sits at (r sin φ, r cos φ): φ = 0 is +y, 90°
// the front (+x), 180° is −y. A full slot engages [0°, 180°]; a down-milling
// side cut of width ae engages [acos(ae/R − 1), 180°] (cutting/engagement.hpp).

#include <Eigen/Core>
#include <array>
#include <vector>

#include "robomill/toolpath/cutter_shape.hpp"
#include "robomill/toolpath/dexel_stock.hpp"

namespace robomill::toolpath {

/// One engaged arc, entry ≤ exit (rad, in [0, π] on the front half; in [0, 2π) for a plunge).
struct EngagedArc {
  double entry_rad = 0.0, exit_rad = 0.0;
};

/// The engaged arcs of one axial slice of the edge. Several arcs where the
/// slice crosses a slot, a rib or an earlier pass.
struct EngagementSlice {
  static constexpr int kMaxArcs = 4;
  double height_m = 0.0;     ///< slice centre above the tip
  double thickness_m = 0.0;  ///< along the axis
  double radius_m = 0.0;     ///< cutter radius at the slice centre
  int arc_count = 0;
  std::array<EngagedArc, kMaxArcs> arcs{};
  /// Total engaged angle of the slice (rad).
  double engaged_rad() const noexcept;
};

/// How finely the engagement is sampled.
struct EngagementGrid {
  double slice_height_m = 0.0;  ///< axial slice thickness
  int angle_steps = 180;        ///< points over the front half [0, π]
  /// How far inside the cutter's surface (along its normal) the test points
  /// sit; negative: automatic, 0.5 res² / R + 1 µm. The walls the cutter
  /// itself left coincide with its surface and must read as air: the stock
  /// places a curved wall to about 0.35 res² / R, and a path sampled in
  /// chords of length f on a radius ρ leaves walls up to f² / (8ρ) inside the
  /// true arc — raise the inset above that for tightly sampled arcs (a helix
  /// of small radius). Material ahead thinner than the inset is not seen, so
  /// keep it well below the sample spacing.
  double surface_inset_m = -1.0;
};

/// A default grid for a stock and cutter: slices one dexel resolution thick
/// (at least 0.1 mm; at most 200 over the cutter's length), angle steps
/// with R Δφ ≈ resolution / 2 (between 36 and 360 over the half turn) and the
/// automatic surface inset.
EngagementGrid default_engagement_grid(const CutterShape& cutter, double resolution_m);

/// The inset the engagement's test points use: `grid.surface_inset_m`, or when
/// it is negative min(res / 2, 0.5 res² / R + 1 µm).
double surface_inset_m(const EngagementGrid& grid, const CutterShape& cutter,
                       double resolution_m) noexcept;

struct CutterEngagement {
  /// Slices from the tip up to the highest engaged one (empty: in air).
  std::vector<EngagementSlice> slices;
  double axial_depth_m = 0.0;  ///< ap: from the tip to the top of the highest engaged slice
  /// ae: width of the engaged material across the feed, r (cos φ_entry −
  /// cos φ_exit) summed over the arcs of the widest slice.
  double radial_width_m = 0.0;
  double engaged_rad = 0.0;  ///< the largest engaged angle of any slice
  /// Entry and exit of the slice with the largest engaged angle (its first
  /// arc's entry, its last arc's exit).
  double entry_rad = 0.0, exit_rad = 0.0;
  /// Cross-section of the engaged material normal to the feed (m²): Σ over
  /// slices and arcs of r (cos φ_entry − cos φ_exit) dz. Feed × section is the
  /// material removal rate. For a plunge the section normal to the (axial)
  /// feed: the engaged sectors ½ r² Σ(φ_exit − φ_entry) of the widest slice
  /// (π R² for a whole turn), and ae is the engaged points' extent along y
  /// (2R for a whole turn).
  double section_m2 = 0.0;
  bool empty() const noexcept { return slices.empty(); }
};

/// Engagement of the cutter with its tip at `tip_m`, axis `axis` (unit) and
/// moving along `feed_direction` (need not be normal to the axis; its normal
/// component sets x of the local frame; when it is along the axis — a plunge —
/// x is any normal direction and the whole turn [0, 2π) is tested instead of
/// the front half, and `plunge` is set by the caller). Test points lie on the
/// cutter's surface at each slice's centre, `grid.surface_inset_m` inside it,
/// and a point is in material by DexelStock::contains with the surface's
/// normal there. A plunge's arc through φ = 0 is returned as two arcs,
/// [0, exit] and [entry, 2π]; a whole turn as the one arc [0, 2π].
CutterEngagement engagement_at(const DexelStock& stock, const CutterShape& cutter,
                               const Eigen::Vector3d& tip_m, const Eigen::Vector3d& axis,
                               const Eigen::Vector3d& feed_direction, const EngagementGrid& grid);

}  // namespace robomill::toolpath
