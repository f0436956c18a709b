#pragma once
// Workpiece pose optimization (004 §3.3 Eq 8, §4.3 Eq 9): minimize d_m(xp,
// yp, θp) over a box, every path point reachable within the joint limits.
//
// 004 solves Eq 9 with OQNLP (scatter search + local NLP). robomill uses
// NLopt: a global, derivative-free method over the box (DIRECT-L by default;
// CRS2 or MLSL) and then a local polish (BOBYQA by default, or COBYLA,
// Nelder-Mead) from the best point found. Reachability is a hidden
// constraint: an unreachable pose scores 1 m plus the IK residuals (far above
// any offset), so both phases are steered back into the reachable set, and
// only reachable poses can be the result. DIRECT-L is deterministic; CRS2 and
// MLSL draw from NLopt's generator seeded with `seed`.

#include <array>
#include <string>
#include <vector>

#include "robomill/planning/path_performance.hpp"

namespace robomill::planning {

enum class GlobalMethod { direct_l, crs2, mlsl, none };
enum class LocalMethod { bobyqa, cobyla, nelder_mead, none };

/// Box of Eq 9 on (xp, yp, θp); a variable with `free` false stays at
/// `fixed`'s value.
struct PoseBounds {
  WorkpiecePose lower, upper, fixed;
  std::array<bool, 3> free{true, true, true};
};

struct PoseOptimizationOptions {
  GlobalMethod global = GlobalMethod::direct_l;
  LocalMethod local = LocalMethod::bobyqa;
  int global_evaluations = 600;
  int local_evaluations = 200;
  /// Local phase stops when a step changes every variable by less than this
  /// fraction of its bound range.
  double relative_x_tolerance = 1e-5;
  unsigned seed = 1;
  int threads = 1;  ///< per evaluation (path points)
};

struct PoseEvaluation {
  WorkpiecePose pose;
  double objective_m = 0.0;  ///< d_m, or the penalty when unreachable
  double dm_m = 0.0;         ///< 0 when unreachable
  bool reachable = false;
  int phase = 0;  ///< 0 global, 1 local
};

struct PoseOptimizationResult {
  bool found = false;  ///< some evaluated pose was reachable
  WorkpiecePose best;
  double dm_m = 0.0;
  std::vector<PoseEvaluation> evaluations;  ///< in order
  int global_evaluations = 0;
  std::string global_status, local_status;  ///< NLopt's return codes, as words
  double elapsed_s = 0.0;
};

/// Runs the optimization. Throws std::invalid_argument for an empty or
/// inverted box, NumericalError if NLopt fails outright.
PoseOptimizationResult optimize_workpiece_pose(const robot::RobotModel& robot,
                                               const PlacementProblem& problem,
                                               const PoseBounds& bounds,
                                               const PoseOptimizationOptions& options);

/// d_m on a grid (004 Figure 7d): every (x, y) for every θ, θ-major then y
/// then x. Grid cells are independent and run on `threads` threads.
std::vector<PathPerformance> pose_landscape(const robot::RobotModel& robot,
                                            const PlacementProblem& problem,
                                            const std::vector<double>& x_m,
                                            const std::vector<double>& y_m,
                                            const std::vector<double>& theta_rad, int threads);

}  // namespace robomill::planning
