#pragma once
// Milling cutter description: an immutable, validated value.
//
// Frame (tool frame {T}, shared with every module): origin at the tool tip on
// the rotation axis, z along the tool axis pointing from the tip into the
// spindle, x along the feed, y completing a right-handed frame. Edge angles φ
// are measured clockwise (seen from the spindle) from +y, as in Altintas'
// milling model and papers 001 (§2.1.2) and 004 (Appendix A); a point of an
// edge at angle φ and radius r lies at (r sin φ, r cos φ).

#include <vector>

namespace robomill::tool {

/// flat: a cylinder with a flat end; ball: a hemispherical end of radius R;
/// bull (bull-nose, torus end mill): a flat end of radius R − r_c rounded
/// into the cylinder by a torus corner of radius r_c, 0 < r_c ≤ R.
enum class ToolType { flat, ball, bull };

/// The job file's name of a cutter type: "flat", "ball" or "bull".
const char* type_name(ToolType type) noexcept;

/// Parallel-axis runout (001 Eq 4): the tool axis is offset from the spindle
/// axis by `offset_m`, at `angle_rad` measured from the first tooth.
struct Runout {
  double offset_m = 0.0;
  double angle_rad = 0.0;
};

/// What a user states about a cutter; `Tool` validates it.
struct ToolSpec {
  ToolType type = ToolType::flat;
  double diameter_m = 0.0;
  int teeth = 0;
  double helix_rad = 0.0;            ///< helix angle β (001: β0 at the ball–shank boundary)
  double overhang_m = 0.0;           ///< length from holder to tip (cantilever length, 000 Eq 1)
  double youngs_modulus_pa = 600e9;  ///< cemented carbide by default
  Runout runout;
  /// Corner radius r_c of a bull-nose end mill (0 < r_c ≤ R; read only for
  /// ToolType::bull: a flat end has 0, a ball R).
  double corner_radius_m = 0.0;
};

/// A validated milling cutter. Construct once, share by const reference.
class Tool {
 public:
  /// Throws std::invalid_argument naming the offending member when the spec is
  /// not a physical cutter (non-positive diameter or teeth, helix outside
  /// [0°, 80°], overhang shorter than a ball radius, runout ≥ radius, ...).
  explicit Tool(const ToolSpec& spec);

  ToolType type() const noexcept { return spec_.type; }
  const ToolSpec& spec() const noexcept { return spec_; }
  double radius_m() const noexcept { return 0.5 * spec_.diameter_m; }
  /// Radius r_c of the rounded corner between the end and the side: 0 for a
  /// flat end mill, R for a ball, the spec's for a bull nose.
  double corner_radius_m() const noexcept;
  double diameter_m() const noexcept { return spec_.diameter_m; }
  int teeth() const noexcept { return spec_.teeth; }
  double helix_rad() const noexcept { return spec_.helix_rad; }
  double overhang_m() const noexcept { return spec_.overhang_m; }
  double youngs_modulus_pa() const noexcept { return spec_.youngs_modulus_pa; }
  const Runout& runout() const noexcept { return spec_.runout; }

  /// Angular position of tooth j (0-based) relative to tooth 0 for equal
  /// pitch: φp_j = 2π j / N (001 Eq 2).
  double pitch_angle_rad(int tooth) const noexcept;

  /// Radius of the cutting edge at height z above the tip: R for a flat end
  /// mill; R sin κ on the ball part of a ball-end mill, R above it; on a
  /// bull nose's corner R − r_c + r_c sin κ (the torus's tube circle).
  double edge_radius_m(double height_m) const noexcept;

  /// Axial immersion angle κ between the tool axis and the edge normal at
  /// height z: π/2 on cylindrical edges, κ = acos(1 − z/R) on the ball (001
  /// Eq 1), and on a torus corner of radius r_c the same construction with
  /// the corner's circle, κ = acos(1 − z/r_c) for z < r_c (the corner is a
  /// quarter circle of radius r_c centred at radius R − r_c, height r_c).
  double axial_immersion_rad(double height_m) const noexcept;

  /// Helix lag angle ψ of the edge at height z behind its tip (000 Eq 11,
  /// 004 Eq 3: ψ = z tan β / R). On the ball part 001 Eq 3 gives
  /// ψ = tan β0 (1 − cos κ), which is the same expression since z = R(1 − cos κ).
  /// On a bull nose's corner the same constant-lead helix (Engin & Altintas
  /// 2001's general end mill with a constant lead): ψ = z tan β / R.
  double lag_angle_rad(double height_m) const noexcept;

  /// Distance from the spindle axis to the edge of tooth j at height z, with
  /// the parallel-axis runout of 001 Eq 4: |r e(φp_j) + ρ e(λ)|.
  double edge_radius_with_runout_m(int tooth, double height_m) const noexcept;

 private:
  ToolSpec spec_;
};

/// One axial slice of the engaged edge (the "element" of 000 Eq 10-11 and of
/// the axial integration in 004 Appendix A).
struct EdgeElement {
  double height_m = 0.0;        ///< centre height above the tip
  double axial_length_m = 0.0;  ///< dz
  double chip_width_m = 0.0;    ///< db = dz / sin κ, the edge length projected on the cut
  double radius_m = 0.0;        ///< edge radius at the centre (no runout)
  double kappa_rad = 0.0;       ///< axial immersion angle κ
  double lag_rad = 0.0;         ///< helix lag ψ
};

/// Splits the edge from the tip up to `axial_depth_m` into about `count`
/// elements: equal steps of z on cylindrical edges, equal steps of κ (equal
/// arc length) on a ball nose or a bull nose's corner, the count shared in
/// proportion to edge length.
/// Throws std::invalid_argument if the depth is not positive, exceeds
/// the overhang, or count < 1.
std::vector<EdgeElement> discretize_edge(const Tool& tool, double axial_depth_m, int count);

/// The same for the edge between heights `from_m` and `to_m` above the tip
/// (0 ≤ from < to ≤ overhang): the part of the edge a cut engages when the
/// tip is below the material (a profile through a plate).
std::vector<EdgeElement> discretize_edge(const Tool& tool, double from_m, double to_m, int count);

}  // namespace robomill::tool
