#pragma once
// `robomill toolpath` of a job (issue 19, docs/toolpath.md): the program the
// cell runs read in its dialect, run over the job's stock (engagement, force,
// torque, power at every sample), and — when the job puts the part in a
// robot cell — the robot along it: posture, chatter margin, deflection and
// form error at every sample (robot_path/robot_along_path.hpp). With
// `optimize` also a better program (program_improvement.hpp): ψ, spindle
// speeds, feeds and compensation chosen, written back in the program's
// dialect, read back and analysed again.
//
// Everything is in SI units; commands::compute_toolpath turns the run into
// samples.csv, moves.csv, stock.csv and summary.json.

#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "robomill/analysis/program_improvement.hpp"
#include "robomill/analysis/robot_path_setup.hpp"
#include "robomill/job/job.hpp"
#include "robomill/robot_path/robot_along_path.hpp"
#include "robomill/toolpath/dexel_stock.hpp"
#include "robomill/toolpath/program_analysis.hpp"

namespace robomill::analysis {

/// The robot's work along a program shared by several processes (the
/// command line's MPI ranks, apps/robomill/toolpath_mpi.cpp): block b of the
/// program's samples (toolpath::ProgramAnalysisSettings::block_samples
/// each) is computed in full by process b mod `processes`; every process
/// computes every block's postures, since each block's inverse kinematics
/// starts from the posture before it. The results are therefore the same for
/// any number of processes.
struct BlockSharing {
  int process = 0, processes = 1;
  /// Process 0: the results and shortcut checks of a block another process
  /// computed (waits for them).
  std::function<void(std::size_t block, std::span<robot_path::RobotSample> out,
                     robot_path::ShortcutChecks& checks)>
      receive;
  /// The other processes: hand a computed block to process 0.
  std::function<void(std::size_t block, std::span<const robot_path::RobotSample> out,
                     const robot_path::ShortcutChecks& checks)>
      send;
};

struct ProgramRun;

struct ProgramRunOptions {
  int threads = 0;  ///< 0: all cores
  /// Every block of samples in program order, with the robot's result for
  /// each (an empty span without a robot on the program).
  std::function<void(std::span<const toolpath::PathSample>,
                     std::span<const robot_path::RobotSample>)>
      on_samples;
  std::function<void(double fraction)> progress;  ///< after each block
  /// Once the program is read and the robot set up, before the first block
  /// (the run's program, tooling, robot_setup and robot are set).
  std::function<void(const ProgramRun& run)> on_start;
  /// A better program (needs a robot on the program); its text is read back
  /// through a scratch file in `scratch_dir` (empty: the system's temporary
  /// folder).
  bool optimize = false;
  std::filesystem::path scratch_dir;
  /// Several processes: this one's share (nullptr: all of it here). A
  /// process other than 0 returns after its share, with only `program` and
  /// `analysis` set.
  const BlockSharing* sharing = nullptr;
};

struct ProgramRun {
  toolpath::Program program;
  /// The cutters by tool number (the robot's analysis refers to them).
  std::unique_ptr<toolpath::Tooling> tooling;
  toolpath::ProgramAnalysis analysis;
  /// The stock after the program.
  std::optional<toolpath::DexelStock> stock;
  /// The widest engagement of a feed move, and its line.
  double max_engagement_rad = 0.0;
  int max_engagement_line = 0;
  /// With a robot on the program: its setup, its analysis (the model, the
  /// totals) and the totals with the worst lines' advice.
  std::optional<analysis::RobotPathSetup> robot_setup;
  std::unique_ptr<robot_path::RobotAlongPath> robot;
  /// With a robot and an uncertainty: section (issue 33): the draws, and
  /// each drawn job's setup (the robot's draws refer to their models).
  std::optional<RobotPathDraws> draws;
  std::optional<robot_path::RobotPathSummary> robot_summary;
  /// With ProgramRunOptions::optimize.
  std::optional<ProgramImprovement> improvement;
  double elapsed_s = 0.0;  ///< reading, the analysis and the robot (not the improvement)
};

/// The stock the job describes: stock.box full, or the height map an
/// earlier run left (stock.height_map: stock.csv's x_mm, y_mm, z_mm with x
/// fastest). Throws InputError naming the stock field.
toolpath::DexelStock job_stock(const job::Job& job);

/// The cutters by tool number (toolpath.tools, else the job's tool for
/// every number), checked against the program's own word on them (APT
/// CUTTER): InputError naming the program line where they disagree.
toolpath::Tooling job_tooling(const job::Job& job, const toolpath::Program& program);

/// The job's sampling and force settings for a run over a program.
toolpath::ProgramAnalysisSettings program_analysis_settings(const job::ToolpathSettings& settings,
                                                            int threads, std::string source_name);

/// How many samples the run is expected to give: the path within the largest
/// cutter's reach of the stock box at the sampling spacing (toolpath.spacing,
/// else half the stock's resolution), plus two per move. Only the path near
/// the stock is sampled (toolpath/program_analysis.hpp). Needs the run's
/// program and tooling (set when ProgramRunOptions::on_start is called).
double expected_samples(const job::Job& job, const ProgramRun& run);

/// The robot drawn at a posture: the joint origins and the tool frame, in the
/// cell (m).
struct RobotDrawing {
  std::vector<Eigen::Vector3d> joint_origins_m;
  Eigen::Isometry3d tool_pose = Eigen::Isometry3d::Identity();
};
RobotDrawing robot_drawing(const robot_path::RobotAlongPath& along, const Eigen::VectorXd& q_rad);

/// The run on up to options.threads threads. Needs the cutting, toolpath and
/// stock sections. Throws InputError naming the field and line: a program
/// its reader refuses, a cutter the program contradicts, a program that
/// touches no stock, a robot that reaches no sample (or, with `optimize`,
/// misses any), `optimize` without a robot or without a speed range or feed
/// caps to choose from; Error when a written program does not read back as
/// chosen (nothing is returned then).
ProgramRun run_program(const job::Job& job, const ProgramRunOptions& options);

}  // namespace robomill::analysis
