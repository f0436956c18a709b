#pragma once
// `robomill toolpath --optimize` (issue 19 item 5, docs/toolpath.md "A better
// program"): from the first run of a program with the robot on it, within
// the job's limits,
//
//  - the redundancy angle ψ: one for the whole program, or one per line
//    turning between lines within a joint-speed bound (robot_path.
//    redundancy_search, per_line, joint_speed_max), for the largest smallest
//    stability margin (robot_path/program_optimization.hpp);
//  - the spindle speed of each S word's stretch, in stability.speeds, for
//    the postures that stretch runs at;
//  - the feed of every line under robot_path.feed_limits' caps on force,
//    torque, deflection and joint speed (robot_path/feed_schedule.hpp);
//  - optionally a deflection compensation (robot_path.compensation): every
//    straight line moved against its samples' predicted form error
//    (robot_path/deflection_compensation.hpp);
//
// the program written back in its own dialect with a comment on every
// change, read back through its own reader and checked move by move, and
// analysed again on a fresh stock, so that every "after" is measured on the
// written program. SI units.

#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "robomill/analysis/robot_path_setup.hpp"
#include "robomill/io/krl_frame_turn.hpp"
#include "robomill/job/job.hpp"
#include "robomill/robot_path/deflection_compensation.hpp"
#include "robomill/robot_path/feed_schedule.hpp"
#include "robomill/robot_path/program_optimization.hpp"
#include "robomill/robot_path/robot_along_path.hpp"
#include "robomill/toolpath/program_analysis.hpp"

namespace robomill::analysis {

/// What the first run keeps for the improvement: the samples whose limits
/// were solved or that are at risk (the solved ones bracket every
/// interpolated run; at most kMaxRecorded), and for every sample whether it
/// was at risk (1), safe (0) or had no limit (2).
struct FirstRunRecord {
  static constexpr std::size_t kMaxRecorded = 50000;
  std::vector<robot_path::RecordedSample> recorded;
  std::vector<unsigned char> at_risk;
  void add(const toolpath::PathSample& sample, const robot_path::RobotSample& robot);
};

/// Median, 90th percentile and largest of a sample (0 for none).
struct Percentiles {
  double median = 0.0, p90 = 0.0, max = 0.0;
};
Percentiles percentiles(std::vector<double> values);

/// How ψ was chosen.
struct RedundancyDecision {
  enum class Kind {
    none,            ///< no robot_path.redundancy_search: the job's ψ is kept
    program_frames,  ///< the program's frames fix ψ (a KRL program): no search
    per_line,        ///< ψ(s), one angle per line: `schedule`
    single,          ///< one angle for the program: `choice`
  };
  Kind kind = Kind::none;
  /// On a KRL program: the candidates turn its frames about the tool axis
  /// (single: RobotPathSettings::frame_turn_rad, one turn of every frame;
  /// per_line: redundancy_by_move, each frame by the angle of the line that
  /// ends at it), and the chosen turns are written into them
  /// (io::turn_krl_frames).
  bool turns_frames = false;
  /// program_frames: why the frames cannot be turned ("pocket.src line 12:
  /// …"); empty for a dialect whose frames robomill does not write.
  std::string frames_refused;
  /// per_line on a KRL program: each frame's turn (toolpath::FrameSite, the
  /// aggregate a move ends at), written with io::turn_krl_frames.
  std::map<toolpath::FrameSite, io::KrlFrameEdit> frame_turns;
  /// per_line asked of a KRL program whose points cannot take one angle
  /// each (why); one turn of all its frames was chosen instead.
  std::string per_line_refused;
  double joint_speed_max_rad_s = 0.0;  ///< per_line: the bound on every turn
  std::optional<robot_path::RedundancySchedule> schedule;
  std::optional<robot_path::RedundancyChoice> choice;
};

/// The spindle speed of each S word's stretch.
struct SpindleDecision {
  std::vector<robot_path::SpindleRegion> regions;
  std::vector<robot_path::SpindleChoice> choices;  ///< SpindleChoice::region indexes `regions`
  /// Changed speeds written into the program (a KRL program has no spindle
  /// word: its choices are reported, not written).
  bool written = false;
  bool unwritable = false;  ///< some speed changed but the dialect cannot say it
};

/// The feeds under the job's caps.
struct FeedDecision {
  robot_path::FeedLimits limits;
  robot_path::FeedSchedule schedule;
  std::size_t lines_changed = 0, lines_slowed = 0;
};

/// The written program analysed again (before the compensation).
struct AfterRun {
  robot_path::RobotPathSummary robot;
  double max_force_n = 0.0, max_torque_nm = 0.0, max_deflection_m = 0.0;
  double cycle_time_s = 0.0;
  double redundancy_rad = 0.0;         ///< the single ψ (a schedule's: redundancy_schedule)
  double max_joint_speed_rad_s = 0.0;  ///< between neighbouring samples of a move
  /// Sample by sample against the first run (the same samples: the re-run
  /// keeps the first run's steps per move).
  std::size_t compared = 0, newly_at_risk = 0, relieved = 0;
  int first_newly_at_risk_line = 0;
};

/// The deflection compensation, measured on the compensated program.
struct CompensationOutcome {
  robot_path::CompensationSettings settings;
  std::vector<robot_path::LineCorrection> written;   ///< the lines moved
  std::vector<std::pair<int, std::string>> skipped;  ///< line, reason (ascending lines)
  std::size_t points_added = 0;
  double max_offset_m = 0.0;
  std::size_t arcs_compensated = 0;     ///< arcs whose circle moved
  double max_arc_fit_residual_m = 0.0;  ///< the largest ArcCorrection::fit_residual_m
  /// |e' − (p' − p)·w'| at every wall sample of the compensated program, and
  /// |e| at the walls before it.
  Percentiles residual_m, before_m;
  std::size_t wall_samples = 0;
  double max_form_error_before_m = 0.0;
  robot_path::RobotPathSummary compensated;
  double compensated_max_force_n = 0.0, compensated_cycle_time_s = 0.0;
};

struct ProgramImprovement {
  RedundancyDecision redundancy;
  SpindleDecision spindles;
  std::optional<FeedDecision> feeds;
  /// False: nothing in the limits improves the program; it is kept and not
  /// analysed again (`after` empty).
  bool changed = false;
  bool redundancy_changed = false;  ///< ψ (single or schedule) differs from the job's
  std::string name;                 ///< program_optimized.<ext>
  /// The written program; empty when only ψ changed (the text is the same).
  std::optional<std::string> text;
  /// A KRL program's .dat with its frames turned (program_optimized.dat).
  std::optional<std::string> dat_text;
  std::size_t frames_turned = 0;
  std::optional<AfterRun> after;
  std::optional<CompensationOutcome> compensation;
  double cycle_time_before_s = 0.0;
  std::size_t samples_before = 0, chatter_before = 0;
};

/// The improvement of a program whose first run (`first_pass`, the robot's
/// analysis `before`, `record`) is done; scratch files go to `scratch_dir`.
/// Throws Error when a written program does not read back as chosen (nothing
/// is written then).
ProgramImprovement improve_program(const job::Job& job, const toolpath::Program& program,
                                   const toolpath::Tooling& tooling,
                                   const analysis::RobotPathSetup& setup,
                                   const robot_path::RobotAlongPath& before,
                                   const FirstRunRecord& record,
                                   const toolpath::ProgramAnalysis& first_pass,
                                   const std::filesystem::path& scratch_dir, int threads);

}  // namespace robomill::analysis
