#pragma once
// `robomill optimize` of a job: where to put the workpiece (004 §3.3, Eq
// 8-9). The job's path is placed on the table at a pose p = (xp, yp, θp),
// the robot's posture found at every point, the steady-state tool offset
// computed from the periodic milling force (Eq 1-2 in the frequency domain)
// and averaged (Eq 6); NLopt searches the job's bounds for the smallest d_m.
// Also evaluates the job's listed poses (004 Table 2) and, with
// optimize.landscape, a grid of (xp, yp) for each θp (004 Figure 7d). SI
// units.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "robomill/job/job.hpp"
#include "robomill/planning/path_performance.hpp"
#include "robomill/planning/pose_optimization.hpp"

namespace robomill::analysis {

/// A pose the job lists (004 Table 2), evaluated; it reaches every path point.
struct ListedPose {
  std::string field;  ///< "workpiece.pose" or "optimize.poses[i]"
  planning::PathPerformance path;
};

/// One path point at one evaluated pose (a row of path.csv).
struct PathPointFigures {
  int pose = 0;   ///< 0: the best pose; k: the k-th listed pose
  int point = 0;  ///< 1-based, along the path
  /// The point placed at the pose (004 Eq 7), cell frame.
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  bool reachable = false;
  double offset_m = 0.0;            ///< d_i: the offset in the job's measure
  planning::OffsetResponse offset;  ///< every measure of the offset (zero when unreachable)
  /// The posture q, one angle per joint (the best attempt when unreachable).
  std::vector<double> posture_rad;
  /// The robot's natural frequencies at q, one per joint; 0 when unreachable.
  std::vector<double> natural_frequencies_hz;
};

/// optimize.check_time_domain: the harmonic offset at the best pose's first
/// path point against Eq 1 integrated in time.
struct TimeDomainCheck {
  double harmonic_m = 0.0;           ///< the frequency-domain steady state, the job's measure
  double time_domain_m = 0.0;        ///< the time-domain steady state, the same measure
  double relative_difference = 0.0;  ///< (harmonic − time domain) / time domain
  int periods = 0;                   ///< periods integrated to the steady state
};

struct WorkpiecePoseOptimization {
  /// NLopt's search over optimize.bounds (Eq 9): the best pose, its d_m and
  /// every pose evaluated, in order.
  planning::PoseOptimizationResult search;
  planning::PathPerformance best;  ///< the path at the best pose
  std::vector<ListedPose> listed;  ///< workpiece.pose, then optimize.poses, in order
  /// Every point at the best pose, then at each listed pose in order.
  std::vector<PathPointFigures> point_figures;
  int joints = 0;  ///< the robot's joints (the posture and frequency count of a point)
  planning::OffsetMeasure measure = planning::OffsetMeasure::peak;  ///< d_i (optimize.measure)
  std::size_t path_points = 0;                                      ///< points on the job's path
  /// The mean milling force c_0 (N, tool frame).
  Eigen::Vector3d force_mean_n = Eigen::Vector3d::Zero();
  std::optional<TimeDomainCheck> time_domain_check;  ///< with optimize.check_time_domain
  /// 004 Figure 7d: the grid over the bounds for each θp of the job, θ-major
  /// then y then x; empty without optimize.landscape.
  std::vector<planning::PathPerformance> landscape;
  int landscape_reachable = 0;  ///< landscape cells that reach every point
  double elapsed_s = 0.0;       ///< from the robot model to the landscape
};

/// The search, the listed poses, the check and the landscape on up to
/// `threads` threads (0: all cores). Needs the optimize section (InputError
/// naming `optimize`); throws InputError naming the pose's field when a
/// listed pose misses a path point, and `optimize.bounds` when no pose within
/// the bounds reaches every point (with why the bounds' centre does not).
WorkpiecePoseOptimization workpiece_pose_optimization(const job::Job& job, int threads = 0);

/// A pose in words, "[x mm, y mm, θ deg]", as the errors and the command's
/// message write it.
std::string pose_in_words(const planning::WorkpiecePose& pose);

}  // namespace robomill::analysis
