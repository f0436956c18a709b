#pragma once
// A part program as robomill sees it: one sequence of moves of the tool tip,
// each with the program line it came from, in SI units and in the program's
// own frame (DESIGN.md §1, the toolpath stage). The readers (io/gcode_reader,
// io/apt_reader, io/krl_reader) build it from G-code, APT CL data or KUKA KRL;
// everything after them sees only this.
//
// Frame: the program frame is the frame the program's coordinates are written
// in (the G-code work offset, the CL file's MCS, the KRL BASE). The tool axis
// is a unit vector from the tool tip towards the spindle, as in the tool frame
// of tool/tool.hpp. toolpath.origin places the program frame in the workpiece
// frame (apply_origin).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace robomill::toolpath {

enum class MotionKind {
  rapid,   ///< positioning at traverse speed (G0, RAPID, PTP): an air move
  linear,  ///< straight feed move (G1, GOTO, LIN), tool axis interpolated
  arc,     ///< circular or helical feed move (G2/G3, CIRCLE, CIRC)
  dwell    ///< no motion for `dwell_s` (G4, G82's pause)
};

/// One move of the tool tip from `start_m` to `end_m`.
struct Move {
  MotionKind kind = MotionKind::linear;
  Eigen::Vector3d start_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d end_m = Eigen::Vector3d::Zero();
  /// Tool axis (unit, tip → spindle) at the start and the end; linear moves
  /// interpolate it (great-circle), arcs keep the start's.
  Eigen::Vector3d axis_start = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d axis_end = Eigen::Vector3d::UnitZ();
  /// The tool's rotation about its axis where the program fixes it (a KRL
  /// frame's A, B, C): the x axis of robomill's tool frame (unit, normal to
  /// the axis; z is the axis) at the start and the end, turned about the
  /// axis in between (tool_x_at). `oriented` false: the program leaves the
  /// rotation to the cell (G-code, APT), the redundancy angle ψ of the job.
  bool oriented = false;
  Eigen::Vector3d tool_x_start = Eigen::Vector3d::UnitX();
  Eigen::Vector3d tool_x_end = Eigen::Vector3d::UnitX();
  /// Arcs only: the circle's centre (in the plane of the start point), the
  /// unit normal of the arc's plane, and the signed sweep angle about that
  /// normal (right-hand rule; positive = counter-clockwise seen from the
  /// normal's tip; |sweep| may exceed 2π for full circles and multi-turn
  /// helices). A helical arc's end differs from the planar circle's end by a
  /// displacement along the normal, covered linearly with the sweep.
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double sweep_rad = 0.0;
  /// Programmed feed rate (m/s); 0 for rapids and dwells.
  double feed_m_s = 0.0;
  /// Spindle speed (rad/s) in force during the move: positive clockwise seen
  /// from the spindle (M3, SPINDL/..,CLW), negative counter-clockwise (M4),
  /// 0 when the spindle is off.
  double spindle_rad_s = 0.0;
  /// Tool number in force (T / LOAD/TOOL / LOADTL / the KRL tool index); 0
  /// when the program never named one.
  int tool = 0;
  double dwell_s = 0.0;  ///< dwells only
  int line = 0;          ///< 1-based line of the program the move came from
};

/// A tool the program calls, with what it says about the cutter (APT
/// CUTTER/d, r, ...): the analysis checks these against the job's tool.
struct ToolCall {
  int tool = 0;
  int line = 0;
  std::optional<double> diameter_m;
  std::optional<double> corner_radius_m;
};

/// Something the reader accepted but the user should know about (an
/// ignored word, a guessed unit, a modal word with no effect on the cut).
struct ProgramNote {
  int line = 0;
  std::string text;
};

/// Where a KRL program writes a frame: the `ordinal`-th Cartesian aggregate
/// (one with any of X, Y, Z, A, B, C) on 1-based `line` of the .src or the
/// .dat (comments and strings skipped), so that it can be written back
/// (io/krl_frame_turn.hpp).
struct FrameSite {
  bool in_dat = false;
  int line = 0;
  int ordinal = 0;
  auto operator<=>(const FrameSite&) const = default;
};

/// The aggregate a KRL move's end frame was read from, and the orientation
/// the move ends at (A, B, C in degrees, in the base): the aggregate's own,
/// or for one without all of A, B, C (`complete` false) the frame before's.
struct FrameSource {
  FrameSite site;
  bool complete = true;
  std::array<double, 3> abc_deg{};
  bool position_complete = true;  ///< the aggregate writes all of X, Y and Z
  /// The base in force (program frame ← the aggregate's, metres): a point
  /// p written in mm is base_rotation p·1e-3 + base_origin_m.
  Eigen::Matrix3d base_rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d base_origin_m = Eigen::Vector3d::Zero();
};

struct Program {
  std::string dialect;  ///< "gcode", "apt" or "krl"
  std::vector<Move> moves;
  /// KRL only (else empty): per move, the aggregate its end frame was read
  /// from; nullopt where the end frame was computed (a …_REL move, a CIRC
  /// with CA) or there is none (a dwell).
  std::vector<std::optional<FrameSource>> frame_sources;
  std::optional<FrameSource> first_frame;  ///< the program's first Cartesian point
  std::vector<ToolCall> tool_calls;
  std::vector<ProgramNote> notes;
  std::size_t line_count = 0;  ///< lines in the source
};

/// Length of a move's tip path (m): the chord of a linear move, the helix
/// length of an arc, 0 for dwells.
double path_length_m(const Move& move) noexcept;

/// Tip position at the fraction u ∈ [0, 1] of the move.
Eigen::Vector3d position_at(const Move& move, double u) noexcept;

/// Unit tangent of the tip path at u (direction of travel); the tool axis for
/// a zero-length move.
Eigen::Vector3d tangent_at(const Move& move, double u) noexcept;

/// Tool axis at u: spherical linear interpolation between axis_start and
/// axis_end for linear moves, axis_start otherwise.
Eigen::Vector3d axis_at(const Move& move, double u) noexcept;

/// The tool frame's x at u for an oriented move: the start's and the end's x
/// projected normal to axis_at(u), turned from the first towards the second
/// by u × the angle between them about that axis (KRL's orientation
/// interpolation about the tool axis). Unit; meaningless when !oriented.
Eigen::Vector3d tool_x_at(const Move& move, double u) noexcept;

/// Time the move takes (s): length / feed for feed moves, `rapid_m_s` for
/// rapids, dwell_s for dwells.
double duration_s(const Move& move, double rapid_m_s) noexcept;

/// Moves the whole program by a rigid transform (program frame → workpiece
/// frame): positions, centres, axes and arc normals.
void apply_transform(Program& program, const Eigen::Isometry3d& program_to_workpiece);

}  // namespace robomill::toolpath
