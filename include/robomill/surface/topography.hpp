#pragma once
// Surface topography of (robotic) ball-end and flat-end milling by a Z-map
// (paper 001 §2.1, §2.3, §2.4).
//
// Frames (001 §2.1.1):
//  {T} tool: origin at the tip on the tool axis, z from the tip into the
//      spindle, edge angles φ clockwise from +y, a point of an edge at angle φ
//      and radius r at (r sin φ, r cos φ) (tool/tool.hpp). The ball centre is
//      at (0, 0, R).
//  {S} spindle: z along the spindle axis; the tool turns in it (001 Eq 4).
//  {E} engagement: origin at the ball centre of the nominal (runout-free)
//      tool, x along the feed of the pass, z the workpiece normal (001 §2.1.4).
//  {W} workpiece: x along the feed of the first pass, y the step-over, z the
//      normal; z = 0 is the nominal machined plane (the cutter-contact plane of
//      the ideal tool), the stock top is at z = ap.
//
// Edge point of tooth j at axial angle κ (ball, 001 Eq 1-3), at time t:
//   p_T = (r sin φ, r cos φ, R − R cos κ) + ρ e(ϕ + λ),  r = R sin κ,
//   φ = ϕ + φp_j − ψ(κ),  ϕ = Ω t,  ψ = tan β0 (1 − cos κ),
// i.e. 001 Eq 1 with the parallel-axis runout of Eq 4 written so that the
// offset ρ turns with the spindle (tool.hpp's convention: |r e(φp) + ρ e(λ)|).
// Then p_W = M_WE · M_ES · (p_T − ball centre) (001 Eq 10), with
//   M_ES = Rx(α) Ry(β) Rz(γ)           (001 Eq 5: tilt α, lead β, redundancy γ)
//   M_WE = translation to the ball centre (x_s + v_f t, y_0 + i·a_e, R) and,
//          for the return passes of a zig-zag raster, a half turn about z
//          (001 Eq 9; the ball centre sits R above its contact point, Eq 7),
// plus the vibration u(t) of the tool tip in {S} moved into {E} and {W}
// (001 Eq 26-28).
//
// Z-map (001 §2.4, Eq 29-31): nodes x_i = x0 + i dx, y_j = y0 + j dy; each
// discrete edge point lowers the nodes of the grid cell it lies in to the
// tool's own surface there (the ball sphere through the point, the bottom
// plane of a flat end), so that an edge sampled as finely as Eq 30-31 ask
// leaves each node the exact height of the swept surface rather than that of
// the nearest sample (docs/surface.md).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "robomill/tool/tool.hpp"

namespace robomill::surface {

/// Tool posture angles relative to the engagement frame {E} (001 §2.1.4,
/// Eq 5): the tool frame is turned about z_E by the redundancy angle γ, then
/// about y_E by the lead angle β, then about x_E by the tilt angle α.
struct ToolOrientation {
  double lead_rad = 0.0;        ///< β: the tool axis leans towards +x_E (the feed)
  double tilt_rad = 0.0;        ///< α: about x_E (the tool axis leans towards −y_E)
  double redundancy_rad = 0.0;  ///< γ: about z_E (the robot's redundant rotation)
};

/// Rotation of 001 Eq 5: v_E = M_ES v_S.
Eigen::Matrix3d spindle_to_engagement(const ToolOrientation& orientation);

enum class RasterPattern { one_way, zigzag };

/// A raster path over the workpiece plane (001 §2.1.5, Eq 8-9, Figure 6):
/// `passes` straight passes along x, `stepover_m` apart in y, each from
/// x_start to x_end (one-way) or back (zig-zag return passes), at constant
/// feed. The contact line of pass i is at y = first_pass_y_m + i · stepover.
/// The passes follow each other without pause: pass i starts at
/// t = i · (x_end − x_start) / v_f.
struct RasterPath {
  double spindle_rad_s = 0.0;
  double feed_per_tooth_m = 0.0;
  double stepover_m = 0.0;
  int passes = 1;
  double first_pass_y_m = 0.0;
  double x_start_m = 0.0;
  double x_end_m = 0.0;
  RasterPattern pattern = RasterPattern::one_way;
  /// Tooth 1's angle ϕ at t = 0 (clockwise from +y, as the simulator's
  /// start_angle), and whether ϕ starts again with every pass (each pass
  /// entering the part as the same simulated cut) or runs on.
  double start_angle_rad = 0.0;
  bool restart_each_pass = false;
};

/// The simulated patch: (cells_x + 1) × (cells_y + 1) nodes over
/// [x0, x0 + length_x] × [y0, y0 + length_y] (001 Eq 28).
struct ZMapGrid {
  double x0_m = 0.0, y0_m = 0.0;
  double length_x_m = 0.0, length_y_m = 0.0;
  int cells_x = 0, cells_y = 0;
  double dx() const noexcept { return length_x_m / cells_x; }
  double dy() const noexcept { return length_y_m / cells_y; }
  int nodes_x() const noexcept { return cells_x + 1; }
  int nodes_y() const noexcept { return cells_y + 1; }
  std::size_t node_count() const noexcept {
    return static_cast<std::size_t>(nodes_x()) * static_cast<std::size_t>(nodes_y());
  }
};

/// Heights over a grid, row-major by y: z(i, j) = z_m[j · nodes_x + i].
struct ZMap {
  ZMapGrid grid;
  std::vector<double> z_m;
  double at(int i, int j) const {
    return z_m[static_cast<std::size_t>(j) * static_cast<std::size_t>(grid.nodes_x()) +
               static_cast<std::size_t>(i)];
  }
};

/// The tool-tip vibration u(t) in the spindle frame {S} (x the feed without
/// lead and tilt, z the spindle axis), sampled every `step_s` from t = 0 of
/// the first pass; between samples linear, past the end periodic.
struct Vibration {
  double step_s = 0.0;
  std::vector<Eigen::Vector3d> displacement_m;
  /// true: the series starts again with every pass (each pass enters the
  /// part, as in 001 Figure 6's one-way raster); t counts from the pass start.
  bool per_pass = false;
  bool empty() const noexcept { return displacement_m.empty(); }
  /// u(t) (zero when empty).
  Eigen::Vector3d at(double t_s) const noexcept;
  /// Largest |u − mean u| over the samples.
  double amplitude_m() const noexcept;
};

struct ZMapOptions {
  /// Time steps per spindle revolution; 0: the smallest that satisfies 001
  /// Eq 30 on the grid.
  int steps_per_revolution = 0;
  /// Arc length between neighbouring edge points (ds of 001 Eq 31); 0: half
  /// the smaller grid step (Eq 31 asks for ds ≤ min(dx, dy)).
  double edge_spacing_m = 0.0;
  /// Only edge points at most this high above the tool's lowest point are
  /// evaluated (they alone can leave the final surface); 0: automatic
  /// (three times the kinematic scallop and feed-mark heights plus the
  /// runout and vibration ranges, at least 2 µm). A larger budget only costs
  /// time (tests/surface checks the result does not change).
  double height_budget_m = 0.0;
  int threads = 0;  ///< 0: hardware concurrency
  /// Memory the workers may take for private grids (passes shared out,
  /// grids merged by min); above it they split the grid into column strips.
  double private_grid_bytes = 256.0 * 1024 * 1024;
};

/// What a Z-map run did, for summaries and checks.
struct ZMapStats {
  int steps_per_revolution = 0;
  int edge_points = 0;  ///< per tooth, in the evaluated band (Eq 31)
  double time_step_s = 0.0;
  double edge_spacing_m = 0.0;     ///< largest distance between neighbouring edge points
  double max_edge_radius_m = 0.0;  ///< r_max of Eq 30 (with runout) over the evaluated band
  double step_travel_m = 0.0;      ///< largest travel of an edge point in one step (Eq 30)
  double height_budget_m = 0.0;
  long long point_evaluations = 0;  ///< edge points transformed into {W}
  long long node_updates = 0;       ///< nodes lowered (a node may be lowered many times)
  long long node_tests = 0;         ///< node heights compared (the Z-map "cell updates")
  double path_time_s = 0.0;         ///< duration of the whole raster
};

struct ZMapResult {
  ZMap map;
  ZMapStats stats;
};

/// The limits of 001 Eq 29-31 for a grid and a raster, and the settings
/// that satisfy them.
struct ResolutionRules {
  double max_cell_m = 0.0;           ///< Eq 29: max(dx, dy) ≤ min(fz, fp) / 5
  int min_steps_per_revolution = 0;  ///< Eq 30 at the grid's min(dx, dy)
  double max_edge_spacing_m = 0.0;   ///< Eq 31: ds ≤ min(dx, dy)
  double max_edge_radius_m = 0.0;    ///< the r_max of Eq 30 used
  /// Horizontal distance from the contact point within which the evaluated
  /// edge points lie (without runout and vibration): how far beyond the
  /// patch the path must run to finish it.
  double lateral_reach_m = 0.0;
};
ResolutionRules resolution_rules(const tool::Tool& tool, double axial_depth_m,
                                 const ToolOrientation& orientation, const RasterPath& path,
                                 const ZMapGrid& grid, double height_budget_m);

/// The automatic height budget of ZMapOptions::height_budget_m: three times
/// the scallop and once-per-revolution feed-mark heights (their spacings
/// widened by twice the lateral vibration), plus the runout's lift range,
/// twice the vertical vibration range, and 0.5 µm.
double automatic_height_budget(const tool::Tool& tool, const ToolOrientation& orientation,
                               const RasterPath& path, const Vibration& vibration);

/// Height of the tool's lowest point above its ball centre (ball) or tip
/// centre (flat) in {W} is −R resp. −R sin θ; this returns the {E} position
/// of the tool reference point (ball centre, flat-end tip centre) that puts
/// the lowest point of the runout-free tool on the contact point: (0, 0, 0)
/// for a ball (E's origin is the ball centre, 001 §2.1.4), and the lift of a
/// tilted flat end.
Eigen::Vector3d reference_offset(const tool::Tool& tool, const ToolOrientation& orientation);

/// Lowest height above the nominal plane reached by the tool's shank (the
/// cylinder above the ball, or above `flute_length_m` on a flat end) when
/// the tool's lowest point is on the plane: R (1 − sin θ) for a ball with
/// axis θ from the normal. The shank cuts when this is below ap.
double shank_clearance_m(const tool::Tool& tool, const ToolOrientation& orientation);

/// Position in {W} of the point of tooth `tooth` at axial angle κ (ball) or
/// height z (flat, `axial` is then the height above the tip; negative values
/// −r address the bottom edge at radius r) at time t of pass `pass`, without
/// vibration (001 Eq 10). For tests, plots and the documentation of frames.
Eigen::Vector3d edge_point(const tool::Tool& tool, const ToolOrientation& orientation,
                           const RasterPath& path, int pass, int tooth, double axial, double t_s);

/// Cuts the raster into the grid (001 §2.4 Steps 1-5): the nodes start at
/// the stock top `axial_depth_m` (ap above the nominal plane) and every
/// edge point lowers them. `vibration` may be empty. Parallel over strips of
/// the grid along x; allocation-free inside. Throws std::invalid_argument
/// for a non-physical input (the job parser names the field first).
ZMapResult cut_zmap(const tool::Tool& tool, double axial_depth_m,
                    const ToolOrientation& orientation, const RasterPath& path,
                    const ZMapGrid& grid, const Vibration& vibration, const ZMapOptions& options);

/// Ball-end scallop height between passes `stepover` apart: R − √(R² − (s/2)²).
double scallop_height(double radius_m, double stepover_m) noexcept;

}  // namespace robomill::surface
