#pragma once
// The cut along a whole program (DESIGN.md §1, the toolpath stage): the
// program's moves resampled, the material each sample removes from a
// tri-dexel stock, the cutter-workpiece engagement at each sample, and from
// it the forces, torque and power with the same force mechanism as `robomill
// forces` (cutting/milling_forces.hpp, the general-engagement constructor).
//
// Samples stream out in program order through a callback, in blocks, so the
// memory this needs grows with the stock and the program's moves, never with
// the number of samples.
//
// Air costs nothing: the stretches of a move beyond the cutter's reach of the
// stock's box (move_near_box) are timed and measured but not sampled, so a
// run's cost follows the length of path near the stock, not the program's
// (a mistyped G1 X100000000 is 100 km of air, not 400 million samples). The
// samples near the stock stay where a run that sampled everything puts them
// (the same steps along the move); only the air samples, which remove and
// engage nothing, are left out.

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "robomill/cutting/cutting_law.hpp"
#include "robomill/tool/tool.hpp"
#include "robomill/toolpath/cutter_engagement.hpp"
#include "robomill/toolpath/cutter_shape.hpp"
#include "robomill/toolpath/dexel_stock.hpp"
#include "robomill/toolpath/program.hpp"

namespace robomill::toolpath {

/// The cutters a program may call, by tool number. Key 0 (when present)
/// serves every tool number that has no entry of its own (the job's `tool`
/// without `toolpath.tools`). A move whose tool has no cutter is listed but
/// neither removes material nor is analysed.
using Tooling = std::map<int, tool::Tool>;

struct ProgramAnalysisSettings {
  /// Distance between samples along a move (m); every move's ends are
  /// sampled too. 0: a few feeds per tooth, at least half the stock resolution.
  double sample_spacing_m = 0.0;
  /// Per move (index into Program::moves): the spacing of that move where
  /// > 0, over sample_spacing_m. A re-run of a changed program (another
  /// feed or spindle speed, which move the default spacing) then samples
  /// where the first run did, so the two compare sample by sample.
  std::vector<double> move_spacing_m;
  /// Per move: the number of steps along it where > 0, over any spacing. A
  /// re-run of a program whose points moved a little (the deflection
  /// compensation) keeps the first run's samples one for one, which a
  /// spacing alone would not where a length crosses a multiple of it.
  std::vector<std::size_t> move_steps;
  double rapid_speed_m_s = 0.5;  ///< traverse speed for the air time (30 m/min)
  /// Spindle speed for moves whose program gave none (rad/s; KRL programs
  /// rarely do); 0: such a move in material is an error.
  double default_spindle_rad_s = 0.0;
  /// Sample the stretches away from the stock too (every step of every
  /// move, as before air was left out): what leaving them out is checked against.
  bool sample_air = false;
  int force_steps_per_tooth = 32;  ///< force samples per tooth period (peaks)
  EngagementGrid grid;             ///< slice_height 0: default_engagement_grid
  int threads = 0;                 ///< force evaluation (0: all cores)
  /// Compute a block's forces and hand it to the sink on a worker thread
  /// while the next block's samples are placed on the stock (the same
  /// results); false: all on the caller's thread (a sink that must run
  /// there, such as one making MPI calls).
  bool overlap_blocks = true;
  std::size_t block_samples = 4096;     ///< samples computed and handed out per block
  std::string source_name = "program";  ///< the program's name in errors
};

/// One sample along the program.
struct PathSample {
  std::size_t move = 0;        ///< index into Program::moves
  double move_fraction = 0.0;  ///< where along the move, 0 … 1
  /// Which step along the move: move_fraction = step / MoveTotals::steps. A
  /// move's samples are consecutive steps; they start after 0 or end before
  /// `steps` where the move begins or ends away from the stock (in air).
  std::size_t step = 0;
  int line = 0;  ///< program line
  int tool = 0;
  MotionKind kind = MotionKind::linear;
  double t_s = 0.0;  ///< program time at the sample
  Eigen::Vector3d tip_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d feed_direction = Eigen::Vector3d::UnitX();  ///< unit direction of travel
  /// The tool frame's x where the program fixes the rotation about the axis
  /// (Move::oriented, a KRL frame): it sets the robot's ψ at this sample.
  bool oriented = false;
  Eigen::Vector3d tool_x = Eigen::Vector3d::UnitX();
  double feed_m_s = 0.0;
  double spindle_rad_s = 0.0;
  double feed_per_tooth_m = 0.0;  ///< the lateral feed per tooth (normal to the axis)
  bool analysed = false;          ///< a cutter was known and the sample was in the stock
  bool plunge = false;            ///< feed along the tool axis: the whole turn was tested
  // Engagement (toolpath/cutter_engagement.hpp).
  double axial_depth_m = 0.0, radial_width_m = 0.0;
  double engaged_rad = 0.0, entry_rad = 0.0, exit_rad = 0.0;
  int arcs = 0;               ///< arcs of the widest slice
  double section_m2 = 0.0;    ///< engaged cross-section normal to the feed
  double chip_area_m2 = 0.0;  ///< mean uncut chip area Σ h b of all teeth over a tooth period
  // Loads on the tool over one tooth period (a revolution with runout).
  Eigen::Vector3d force_mean_n = Eigen::Vector3d::Zero();  ///< workpiece frame
  double force_mean_magnitude_n = 0.0;                     ///< |mean force|
  double force_peak_n = 0.0;                               ///< largest |F| over the period
  double torque_mean_nm = 0.0, torque_peak_nm = 0.0;
  double power_w = 0.0;  ///< mean torque × spindle speed
};

/// What one program line's moves added up to.
struct MoveTotals {
  std::size_t move = 0;
  int line = 0;
  int tool = 0;
  MotionKind kind = MotionKind::linear;
  double length_m = 0.0, time_s = 0.0;
  double feed_m_s = 0.0, spindle_rad_s = 0.0;
  double spacing_m = 0.0;  ///< sample spacing used along the move (0: not sampled)
  /// Steps along it (0: not sampled): step k at move fraction k / steps. A
  /// move near the stock throughout has steps + 1 samples; fewer where part
  /// of it is air.
  std::size_t steps = 0;
  /// The move's length away from the stock (beyond the cutter's reach of the
  /// box): timed, not sampled.
  double unsampled_length_m = 0.0;
  bool tool_described = true;
  int samples = 0, engaged_samples = 0;
  double removed_m3 = 0.0;  ///< section × feed integrated over the move
  double max_axial_depth_m = 0.0, max_radial_width_m = 0.0, max_engaged_rad = 0.0;
  double max_force_n = 0.0, max_torque_nm = 0.0, max_power_w = 0.0;
};

struct ProgramAnalysis {
  std::vector<MoveTotals> moves;
  std::size_t samples = 0, engaged_samples = 0;
  double cutting_time_s = 0.0;  ///< feed moves
  double air_time_s = 0.0;      ///< rapids
  double dwell_time_s = 0.0;
  /// Path away from the stock, in the times above but not sampled.
  double unsampled_length_m = 0.0, unsampled_time_s = 0.0;
  double volume_removed_m3 = 0.0;  ///< the stock's volume before − after
  double max_force_n = 0.0, max_torque_nm = 0.0, max_power_w = 0.0;
  int max_force_line = 0, max_torque_line = 0, max_power_line = 0;
  /// Things the user should know (a rapid through material, moves of tools
  /// that are not described, M4 rotation, a plunge of a flat end mill …),
  /// each with the first program line it happened on and how often.
  struct Warning {
    int line = 0;
    std::string text;
    std::size_t count = 1;
  };
  std::vector<Warning> warnings;
};

/// Called with each block of samples, in program order, one block at a time;
/// on a worker thread unless ProgramAnalysisSettings::overlap_blocks is off.
using SampleSink = std::function<void(std::span<const PathSample>)>;
/// Called after each block with the fraction of the program done.
using ProgressSink = std::function<void(double fraction)>;

/// Runs the program over the stock (which it cuts), sample by sample. Throws
/// InputError naming the program line when a feed move cuts material with no
/// spindle speed, and std::invalid_argument for inconsistent settings.
ProgramAnalysis analyse_program(const Program& program, const Tooling& tooling,
                                const cutting::CuttingLaw& law, DexelStock& stock,
                                const ProgramAnalysisSettings& settings, const SampleSink& sink,
                                const ProgressSink& progress = {});

/// The stretch of a move whose tip comes within `distance_m` of the box along
/// every axis (the box grown by distance_m): the move fractions [from_u,
/// to_u], exact for a straight move (its tip moves on a line); an arc is
/// taken whole when its circle's bounding box comes that close. Empty (from_u
/// > to_u) when the move stays farther away.
struct MoveStretch {
  double from_u = 0.0, to_u = 1.0;
  bool empty() const noexcept { return from_u > to_u; }
};
MoveStretch move_near_box(const Move& move, const StockBox& box, double distance_m) noexcept;

/// How far from its tip a cutter reaches, in any direction: √(R² + L²).
double cutter_reach_m(const CutterShape& shape) noexcept;

/// A move longer than this (m) is reported: no machine or robot travels that
/// far in one block, so it is a mistyped coordinate or unit.
inline constexpr double kImplausibleMoveM = 1000.0;

/// The sample spacing used for a tool when none is set: three feeds per tooth
/// at the program's largest feed and speed for that tool, but never below
/// half the stock resolution (the engagement cannot change faster than the
/// dexel grid resolves).
double default_sample_spacing_m(double feed_per_tooth_m, double resolution_m) noexcept;

}  // namespace robomill::toolpath
