#pragma once
// The feed of a better program (issue 19 item 5, `robomill toolpath JOB
// --optimize` with `robot_path.feed_limits`): for every program line that
// feeds the cutter, the feed rate that keeps the loads the line puts on the
// cell under the job's caps — the peak force on the tool and the peak spindle
// torque over a tooth period (the forces of program_analysis.hpp), the static
// tool-tip deflection (robot compliance at the posture plus the tool, 000 Eq
// 1 and 3, robot_along_path.hpp) and the robot's joint speeds — inside the
// job's feed range.
//
// Why a measured search and not a formula. The force of a tooth is
// K_c(h) h b + K_e b (001 Eq 11, 004 Appendix A) with h = f_z sin φ: the edge
// part does not scale with the feed, and a size-dependent K_c(h) bends the
// rest, so "force ∝ feed" under-corrects. The feed does not move the path,
// so the engagement, the posture and the compliance are the same at every
// feed; only the chip changes. Each line's largest load ratio r(s) (load /
// cap, the worst of the caps) is a monotone function of the line's feed
// scale s alone, and the lines are independent. The search runs the whole
// program at trial scales (the caller's measurement, sample positions held
// where the first run put them), takes a secant step per line towards
// r = target, and stops when every line's last measured r is at most 1 and
// either within `tolerance` of the target or at a bound of its feed range.
// The last run measured every line at its final scale: the loads reported are
// measured, not predicted. Joint speeds scale exactly with s (the same path
// in less or more time), so they bound s directly.
//
// The stability margin does not depend on the feed in the regenerative
// model (the zero-order limit, 003 §3.2; process damping depends on the
// cutting speed), so a feed change never raises the chatter risk.

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "robomill/cutting/cutting_law.hpp"
#include "robomill/robot_path/robot_along_path.hpp"
#include "robomill/toolpath/dexel_stock.hpp"
#include "robomill/toolpath/program.hpp"
#include "robomill/toolpath/program_analysis.hpp"

namespace robomill::robot_path {

/// The caps (0: none) and the feed range of the schedule.
struct FeedLimits {
  double force_max_n = 0.0;            ///< peak |F| on the tool over a tooth period
  double torque_max_nm = 0.0;          ///< peak spindle torque
  double deflection_max_m = 0.0;       ///< |static tool-tip deflection| (robot + tool)
  double joint_speed_max_rad_s = 0.0;  ///< every joint's speed along the path
  double feed_min_m_s = 0.0;           ///< no line is slowed below this
  double feed_max_m_s = 0.0;           ///< no line runs faster (0: than programmed)
  /// Aim for this fraction of the binding cap (headroom for the program's
  /// rounding of the feed word); a line is done once its ratio lies in
  /// [target − tolerance, 1].
  double target = 0.995;
  double tolerance = 0.02;
  int max_runs = 8;  ///< whole-program measurements at most (the first included)
  /// Without feed_min: the slowest a line may be made, as a fraction of its
  /// programmed feed (a cap that needs less is reported, not met).
  double min_scale = 0.01;
  int job_line = 0;  ///< the job line of the limits, for errors

  bool any_cap() const noexcept {
    return force_max_n > 0.0 || torque_max_nm > 0.0 || deflection_max_m > 0.0 ||
           joint_speed_max_rad_s > 0.0;
  }
};

/// The largest loads a run measured along one move.
struct MoveLoads {
  bool measured = false;  ///< the move was sampled in the cut (force and deflection apply)
  double force_peak_n = 0.0;
  double torque_peak_nm = 0.0;
  double deflection_m = 0.0;
  double joint_speed_rad_s = 0.0;  ///< fastest joint between two of its samples
};

/// Runs the whole program with every move's feed multiplied by
/// `feed_scale[move]` and returns the loads per move (size: the moves).
using FeedMeasurement =
    std::function<std::vector<MoveLoads>(const std::vector<double>& feed_scale)>;

/// The feed chosen for one program line.
struct LineFeed {
  int line = 0;
  std::vector<std::size_t> moves;                ///< the feed moves of the line
  double programmed_m_s = 0.0;                   ///< the line's (slowest) programmed feed
  double scale = 1.0;                            ///< chosen feed / programmed feed
  MoveLoads before, after;                       ///< the line's largest loads, measured
  double ratio_before = 0.0, ratio_after = 0.0;  ///< worst load / its cap
  std::string binding;  ///< the cap (or bound) that set the feed: "force", "torque",
                        ///< "deflection", "joint_speed", "feed_max", "" (unchanged)
  bool changed() const noexcept { return scale != 1.0; }
};

struct FeedSchedule {
  std::vector<LineFeed> lines;      ///< every line with feed moves, in program order
  int runs = 0;                     ///< whole-program measurements made
  MoveLoads max_before, max_after;  ///< over the program
};

/// The schedule. Lines whose moves the measurement never sees in the cut are
/// bounded by the joint speed alone. Throws InputError (field
/// `robot_path.feed_limits`, the program line) when a line exceeds a cap even
/// at `feed_min_m_s` (or at the feed the joint-speed bound allows), and
/// std::invalid_argument for inconsistent limits (no cap, min > max).
FeedSchedule schedule_feeds(const toolpath::Program& program, const FeedLimits& limits,
                            const FeedMeasurement& measure);

/// One measurement for schedule_feeds: `program` with every move's feed
/// scaled, run over `stock` (a fresh copy each call) with `settings` (give
/// `move_spacing_m` from the first run, so the samples fall where they fell
/// then), and, when `make_robot` is given, the robot along it (a fresh
/// analysis each call; its stability may be switched off, as the feed does
/// not change it) for the deflection and the joint speeds.
std::vector<MoveLoads> measure_move_loads(
    const toolpath::Program& program, const std::vector<double>& feed_scale,
    const toolpath::Tooling& tooling, const cutting::CuttingLaw& law, toolpath::DexelStock stock,
    const toolpath::ProgramAnalysisSettings& settings,
    const std::function<std::unique_ptr<RobotAlongPath>()>& make_robot);

}  // namespace robomill::robot_path
