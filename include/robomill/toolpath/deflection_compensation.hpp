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
// on the samples' corrections). The cut on the moved path is a little
// deeper and its force a little larger: the command runs the whole analysis
// again on the written program and reports the residual against the path the
// CAM wrote, measured, not assumed.

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "robomill/toolpath/program.hpp"
#include "robomill/toolpath/program_analysis.hpp"
#include "robomill/toolpath/robot_along_path.hpp"

namespace robomill::toolpath {

struct CompensationSettings {
  bool floor = false;          ///< also move points along the axis by the floor error
  double min_offset_m = 1e-6;  ///< a line whose corrections all stay under this is kept
  double tolerance_m = 2e-6;   ///< the polyline follows the samples' corrections within this
  int max_points = 50;         ///< at most this many points added inside one line
};

/// The correction of one sample (workpiece frame): e w at a wall sample (plus
/// the floor's along the axis with `floor`); nullopt where the sample finishes
/// no surface the analysis judged (not reachable, not in the cut, a plunge).
std::optional<Eigen::Vector3d> sample_correction(const PathSample& sample, const RobotSample& robot,
                                                 const CompensationSettings& settings);

/// A point added inside a line: at the fraction u of the programmed line,
/// moved by offset_m.
struct CorrectionPoint {
  double u = 0.0;
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();  ///< workpiece frame
};

/// One program line's correction: its end point's offset and the points
/// added before it (u ascending, inside (0, 1)).
struct LineCorrection {
  std::size_t move = 0;
  int line = 0;
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();  ///< the end point's, workpiece frame
  std::vector<CorrectionPoint> points;
};

/// Collects, in program order, every sample's correction move by move.
class PathCorrections {
 public:
  PathCorrections(std::size_t moves, CompensationSettings settings);

  /// Every sample of the analysis in program order (a move's samples at
  /// u = k / steps, k = 0 … steps).
  void add(const PathSample& sample, const RobotSample& robot);

  /// The lines to write: straight feed moves alone on their program line
  /// with a correction of at least `min_offset_m` somewhere, except a move
  /// followed by an arc (its centre is programmed relative to the start, so
  /// a moved start would bend the arc). A line starts where the line before
  /// was written to end (moved or not).
  std::vector<LineCorrection> corrections(const Program& program) const;

  /// The lines with a correction of at least `min_offset_m` that
  /// corrections() leaves as programmed, and why: an arc, a line before an
  /// arc, a line of several moves (a KRL loop, a canned cycle).
  struct Kept {
    int line = 0;
    std::string reason;
  };
  std::vector<Kept> kept(const Program& program) const;

 private:
  CompensationSettings settings_;
  std::vector<std::vector<Eigen::Vector3d>> samples_;  // per move; zero where none
};

/// The corrected path's point at which a written move ends, for checks:
/// every move of `program` with its line's correction applied, a corrected
/// line as its points then its end (workpiece frame).
std::vector<Eigen::Vector3d> corrected_ends(const Program& program,
                                            const std::vector<LineCorrection>& corrections);

}  // namespace robomill::toolpath
