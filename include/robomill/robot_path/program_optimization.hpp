#pragma once
// A better program (issue 19 item 5, `robomill toolpath JOB --optimize`):
// the spindle speed of each stretch of the program that one S word governs,
// chosen inside the job's speed range for the postures and engagements of
// that stretch (robot_along_path.hpp's zero-order limits at every candidate
// speed), so that its smallest stability margin grows and no sample that was
// safe becomes at risk. The programmed speed is kept unless a candidate is
// better; the chosen speeds are written back by io/program_writer.hpp and
// the command re-runs the whole analysis on the written program, so the
// after-numbers are measured, not predicted.

#include <cstddef>
#include <span>
#include <utility>
#include <vector>

#include "robomill/robot_path/robot_along_path.hpp"
#include "robomill/toolpath/program.hpp"

namespace robomill::robot_path {

/// Consecutive moves run with one tool at one spindle speed (rapids and
/// dwells included); a change of either, or the spindle stopping, ends it.
struct SpindleRegion {
  std::size_t first_move = 0, last_move = 0;  ///< into Program::moves, inclusive
  int first_line = 0, last_line = 0;          ///< program lines of those moves
  int tool = 0;
  double spindle_rad_s = 0.0;  ///< as programmed (negative: M4)
};

std::vector<SpindleRegion> spindle_regions(const toolpath::Program& program);

/// A sample of the first pass kept for the optimization: where it is, what
/// it cuts, the posture and what the programmed speed gave there.
///
/// With draws of the uncertain inputs (issue 33) the margin is the risk-
/// bounded one: the draws' limit at the bound (RobotSample::
/// depth_limit_at_bound_m) over ap, so "at risk" reads P(chatter) over
/// RobotPathSettings::max_chatter_probability. Every candidate's limit (a
/// speed, a ψ) is the nominal limit there times `bound_ratio`, the ratio of
/// the bounded to the nominal limit measured at the programmed point: one
/// nominal solve per candidate, not one per draw. The ratio is exact for a
/// common factor on the cutting coefficients and an approximation for drawn
/// structure; the re-run of the written program measures P(chatter) with
/// every draw (docs/uncertainty.md).
struct RecordedSample {
  toolpath::PathSample sample;
  RobotSample::Joints q_rad;
  double margin = 0.0;
  double bound_ratio = 1.0;  ///< bounded / nominal limit (1: no draws)
};

struct SpindleChoice {
  std::size_t region = 0;
  double programmed_rad_s = 0.0, chosen_rad_s = 0.0;  ///< signed as programmed
  std::size_t samples = 0;                            ///< recorded samples judged
  double min_margin_before = 0.0, min_margin_after = 0.0;
  std::size_t at_risk_before = 0, at_risk_after = 0;
  bool changed() const noexcept { return chosen_rad_s != programmed_rad_s; }
};

/// For every region with recorded samples: the candidate (|speed|, the
/// programmed direction kept) with the largest smallest margin over the
/// region's samples among those that put no more samples at risk than the
/// programmed speed, and no recorded sample that was safe at risk; the
/// programmed speed unless a candidate raises the smallest margin by more
/// than `min_gain` (relative). Throws std::invalid_argument for no candidates.
std::vector<SpindleChoice> choose_spindle_speeds(const RobotAlongPath& along,
                                                 const std::vector<SpindleRegion>& regions,
                                                 std::span<const RecordedSample> samples,
                                                 const std::vector<double>& candidates_rad_s,
                                                 double min_gain = 0.02, int threads = 0);

/// One redundancy angle ψ for the whole program (001 §2.1.4, 003 §3.3: the
/// rotation about the tool axis moves the robot's modes and stiffness at the
/// tip). ψ is the cell's choice, not the program's (a G-code or APT program
/// has no word for it), so it is reported, and the re-run uses it.
struct RedundancyChoice {
  struct Candidate {
    double redundancy_rad = 0.0;
    double min_margin = 0.0;
    std::size_t at_risk = 0, unreachable = 0, joint_limit = 0;
    bool newly_at_risk = false;  ///< a recorded sample safe at the programmed ψ is not here
  };
  double programmed_rad = 0.0, chosen_rad = 0.0;
  std::size_t samples = 0;
  double min_margin_before = 0.0, min_margin_after = 0.0;
  std::size_t at_risk_before = 0, at_risk_after = 0;
  std::vector<Candidate> candidates;  ///< every angle tried, in order
  bool changed() const noexcept { return chosen_rad != programmed_rad; }
};

/// Every recorded sample's posture at each candidate ψ (the inverse
/// kinematics from the recorded posture, so the robot keeps its
/// configuration) and the limit there at the sample's own speed. The
/// candidate kept has every sample reachable and off the joint limits, no
/// safe sample at risk, no more samples at risk, and the largest smallest
/// margin, better than the programmed ψ's by more than `min_gain`; else the
/// programmed ψ. On return `samples` hold the postures and margins at the
/// chosen ψ (for the spindle choice that follows). Samples whose frames set
/// ψ (PathSample::oriented: a KRL program) take each candidate as a turn of
/// their own ψ, the programmed one being RobotPathSettings::frame_turn_rad.
RedundancyChoice choose_redundancy_angle(const RobotAlongPath& along,
                                         std::vector<RecordedSample>& samples,
                                         const std::vector<double>& candidates_rad,
                                         double min_gain = 0.02, int threads = 0);

/// A redundancy angle per program line (issue 19 item 5, the schedule ψ(s)):
/// each line with recorded samples runs at one of the candidate angles; where
/// the angle changes from one line to the next, the robot turns the tool about
/// its axis on the moves between them (a link, a retract) when there are any
/// and the turn fits, else over the later line (ψ linear in the line's
/// progress), so every joint must follow that turn (on top of the path)
/// within `joint_speed_max`.
/// Chosen by dynamic programming over the lines in program order to maximize
/// the smallest margin (a line that turns counts the smaller of its two
/// angles' margins), with every sample reachable, off the joint limits, no
/// safe sample at risk and no more samples at risk than the programmed ψ;
/// kept as the programmed ψ unless the smallest margin grows by more than
/// `min_gain`. Among equal schedules the one with fewer turns wins.
struct RedundancySchedule {
  struct Line {
    int line = 0;
    std::size_t first_move = 0, last_move = 0;  ///< into Program::moves, inclusive
    double from_rad = 0.0, to_rad = 0.0;        ///< ψ at the line's start and end
    double min_margin = 0.0;                    ///< over its samples, both angles
    double turn_joint_speed_rad_s = 0.0;        ///< the fastest joint during the turn
    /// The turn happens on the moves before the line (a link or a retract
    /// between two cuts), not during it: the line runs at to_rad alone.
    bool turn_before = false;
    std::size_t samples = 0;
  };
  std::vector<Line> lines;  ///< every line with recorded samples, in program order
  double programmed_rad = 0.0;
  double min_margin_before = 0.0, min_margin_after = 0.0;
  std::size_t at_risk_before = 0, at_risk_after = 0;
  std::size_t turns = 0;
  bool changed() const noexcept;
  /// ψ at the start and the end of every move (the lines' angles; moves
  /// between lines keep the angle before them).
  std::vector<std::pair<double, double>> by_move(std::size_t moves) const;
};

/// `program` gives the lines' moves and durations (feed moves at their
/// programmed feeds). On return `samples` hold the postures and margins at
/// their line's (final) angle. Throws std::invalid_argument for no
/// candidates or a non-positive joint speed.
RedundancySchedule schedule_redundancy(const RobotAlongPath& along,
                                       const toolpath::Program& program,
                                       std::vector<RecordedSample>& samples,
                                       const std::vector<double>& candidates_rad,
                                       double joint_speed_max_rad_s, double min_gain = 0.02,
                                       int threads = 0);

}  // namespace robomill::robot_path
