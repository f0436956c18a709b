#pragma once
// The deflection compensation of `robomill toolpath JOB --optimize` (issue
// 19 item 5): the program's straight lines moved against the error the
// robot's and the tool's deflection is predicted to leave (robot_along_path.hpp:
// the static deflection, or 000's contact boundary, projected on the wall the
// sample finishes), so that the wall lands where the CAM put it.
//
// First order, as offline compensation is done on robot cells: a point moves
// by the predicted error e along the direction w from the tool towards the
// wall it finishes (and, on request, by the floor error along the tool
// axis), p' = p + e w. The error changes along a line (the posture moves,
// the engagement changes where the tool enters a wall), so a line becomes a
// polyline through points where the correction, interpolated linearly
// between them, stays within a tolerance of every sample's (Douglas-Peucker
// on the samples' corrections).
//
// An arc stays an arc: its centre moves by Δc and its radius changes by δ,
// p'(θ) = p(θ) + Δc + δ r̂(θ), the least-squares fit of that to the samples'
// corrections (a wall error that is the same all round is δ; one that keeps
// its direction in the cell is Δc). The line before the arc is written to
// end where the moved arc starts; where nothing before it can move (a rapid,
// another arc) the arc starts where the path arrives and only Δc is fitted,
// the radius following from that start. The fit's largest departure from the
// samples' corrections is reported: an error that changes along the arc more
// than a circle can follow stays in the residual.
//
// The cut on the moved path is a little deeper and its force a little
// larger: the command runs the whole analysis again on the written program
// and reports the residual against the path the CAM wrote, measured, not
// assumed.

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "robomill/robot_path/robot_along_path.hpp"
#include "robomill/toolpath/program.hpp"
#include "robomill/toolpath/program_analysis.hpp"

namespace robomill::robot_path {

struct CompensationSettings {
  bool floor = false;          ///< also move points along the axis by the floor error
  double min_offset_m = 1e-6;  ///< a line whose corrections all stay under this is kept
  double tolerance_m = 2e-6;   ///< the polyline follows the samples' corrections within this
  int max_points = 50;         ///< at most this many points added inside one line
};

/// The correction of one sample (workpiece frame): e w at a wall sample (plus
/// the floor's along the axis with `floor`); nullopt where the sample finishes
/// no surface the analysis judged (not reachable, not in the cut, a plunge).
std::optional<Eigen::Vector3d> sample_correction(const toolpath::PathSample& sample,
                                                 const RobotSample& robot,
                                                 const CompensationSettings& settings);

/// A point added inside a line: at the fraction u of the programmed line,
/// moved by offset_m.
struct CorrectionPoint {
  double u = 0.0;
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();  ///< workpiece frame
};

/// An arc's correction: the circle's centre moved and its radius changed.
struct ArcCorrection {
  Eigen::Vector3d centre_offset_m = Eigen::Vector3d::Zero();  ///< Δc, workpiece frame
  double radius_change_m = 0.0;                               ///< δ: R' = R + δ
  /// The largest distance between the moved arc's correction Δc + δ r̂ (at
  /// the samples' angles) and the samples' own: what the circle could not
  /// follow.
  double fit_residual_m = 0.0;
};

/// One program line's correction: its end point's offset and the points
/// added before it (u ascending, inside (0, 1)); an arc's circle moved.
struct LineCorrection {
  std::size_t move = 0;
  int line = 0;
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();  ///< the end point's, workpiece frame
  std::vector<CorrectionPoint> points;                 ///< lines only
  std::optional<ArcCorrection> arc;                    ///< arcs only
};

/// What a writer can change move by move where that is not "one move per
/// program line" (a KRL program: a point of the .dat serves the move that
/// ends at it, wherever a FOR loop runs the line).
struct WritableMoves {
  std::vector<char> end;            ///< per move: its end point can move on its own
  std::vector<char> points;         ///< per move: points may be added inside it
  std::vector<std::string> reason;  ///< per move: why its end cannot move
};

/// Collects, in program order, every sample's correction move by move.
class PathCorrections {
 public:
  PathCorrections(std::size_t moves, CompensationSettings settings);

  /// Every sample of the analysis in program order (a move's samples at
  /// u = k / steps, k = 0 … steps). The steps the analysis left out as air
  /// (PathSample::step) have no correction: zero.
  void add(const toolpath::PathSample& sample, const RobotSample& robot);

  /// After the run: every sampled move's corrections padded with zeros to
  /// its steps + 1 (the air steps at its end, or all of a move in air).
  void complete(const std::vector<toolpath::MoveTotals>& moves);

  /// The lines to write: straight feed moves and arcs alone on their
  /// program line with a correction of at least `min_offset_m` somewhere;
  /// the straight line before such an arc, to end where the moved arc
  /// starts; an arc that starts where the line before was moved to end (its
  /// centre is programmed from its start). A line starts where the line
  /// before was written to end (moved or not). Lines in `keep` (those the
  /// writer could not edit) stay as programmed, and so does a line before an
  /// arc that stays. With `writable`, a move may move where its end can
  /// (not "alone on its line"), and gets points only where allowed.
  std::vector<LineCorrection> corrections(const toolpath::Program& program,
                                          const std::set<int>& keep = {},
                                          const WritableMoves* writable = nullptr) const;

  /// The lines with a correction of at least `min_offset_m` that
  /// corrections() leaves as programmed, and why: a line of several moves (a
  /// KRL loop, a canned cycle, an arc in pieces), a line before an arc that
  /// stays, a line in `keep`.
  struct Kept {
    int line = 0;
    std::string reason;
  };
  std::vector<Kept> kept(const toolpath::Program& program, const std::set<int>& keep = {},
                         const WritableMoves* writable = nullptr) const;

 private:
  CompensationSettings settings_;
  std::vector<std::vector<Eigen::Vector3d>> samples_;  // per move; zero where none
};

/// The corrected path's point at which a written move ends, for checks:
/// every move of `program` with its line's correction applied, a corrected
/// line as its points then its end (workpiece frame). An arc's centre moves
/// by its ArcCorrection's centre_offset_m.
std::vector<Eigen::Vector3d> corrected_ends(const toolpath::Program& program,
                                            const std::vector<LineCorrection>& corrections);

}  // namespace robomill::robot_path
