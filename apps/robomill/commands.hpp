#pragma once
// The command-line tool's commands: argument structs, loading the job,
// writing the result and printing. The computations are the library's
// (robomill/commands/commands.hpp, shared with the Python module); each
// run_<name> loads the job, calls compute_<name>, writes the files
// (write_result, one atomic commit) and prints the message.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "robomill/commands/command_result.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/job/job.hpp"

namespace robomill::app {

using commands::add_key_inputs;
using commands::atlas_context;
using commands::CommandResult;
using commands::job_sections;
using commands::write_result;

/// Options every job command shares (`robomill <command> JOB ...`).
struct JobCommandOptions {
  std::filesystem::path job_file;
  std::filesystem::path out_dir;  ///< empty: job's output.dir, else out/<command>
  std::vector<std::string> overrides;
  int threads = 0;
  bool quiet = false;
  bool optimize = false;  ///< `toolpath --optimize`: write a better program
};

/// Parses the `--set` assignments and loads the job (throws InputError).
job::Job load(const JobCommandOptions& options);

/// The folder a command writes into: --out, else the job's output.dir
/// (relative to the job file), else out/<command>.
std::filesystem::path output_dir(const JobCommandOptions& options, const job::Job& job,
                                 const std::string& command);

int run_validate(const JobCommandOptions& options);

/// A one-line progress bar on stderr ("label [####    ]  42%"), drawn only
/// when `enabled` and stderr is a terminal.
class ProgressBar {
 public:
  ProgressBar(bool enabled, std::string label);
  void operator()(double fraction);

 private:
  bool enabled_;
  std::string label_;
  int last_ = -1;
};

/// A computation's progress (commands::Progress) as bars on a terminal's
/// stderr, a new bar for each stage; nothing when not `enabled`.
commands::Progress progress_bars(bool enabled);

/// A job command's whole run: load the job, compute, add the key inputs,
/// write (with report.html unless --quiet), print the message and the folder.
int run_job_command(const JobCommandOptions& options, const std::string& command,
                    const std::function<CommandResult(const job::Job&)>& compute);

int run_forces(const JobCommandOptions& options);
int run_listen(const JobCommandOptions& options);
int run_learn(const JobCommandOptions& options);
int run_stability(const JobCommandOptions& options);
int run_fit_modes(const JobCommandOptions& options);
int run_robot(const JobCommandOptions& options);
int run_deflection(const JobCommandOptions& options);
int run_optimize(const JobCommandOptions& options);
int run_advise(const JobCommandOptions& options);
int run_simulate(const JobCommandOptions& options);
int run_surface(const JobCommandOptions& options);
/// With `sharing` (rank 0 of several MPI ranks, mpi.hpp) the robot's blocks
/// are shared out; the files are the same.
int run_toolpath(const JobCommandOptions& options, const analysis::BlockSharing* sharing = nullptr);

/// `robomill identify-cutting DATA`: the inputs plus where to write.
struct IdentifyOptions : commands::IdentifyCuttingInputs {
  std::filesystem::path out_dir;
  bool quiet = false;
};
int run_identify_cutting(const IdentifyOptions& options);

/// `robomill identify-stiffness DATA --job ROBOT.yaml`.
struct IdentifyStiffnessOptions : commands::IdentifyStiffnessSettings {
  JobCommandOptions job;  ///< job_file: the robot; out, overrides, quiet
};
int run_identify_stiffness(const IdentifyStiffnessOptions& options);

/// `robomill frf JOB`: FRFs synthesized from the job's modal table.
struct FrfCommandOptions : commands::FrfSettings {
  JobCommandOptions job;
};
int run_frf(const FrfCommandOptions& options);

/// `robomill atlas JOB`: the workspace atlas into its SQLite store (issue 11);
/// with `export_dir` the store's results as atlas.csv and summary.json.
struct AtlasOptions {
  JobCommandOptions job;  ///< job_file, overrides, threads, quiet
  std::filesystem::path export_dir;
  bool restart = false;  ///< discard a store written by another job
};
int run_atlas(const AtlasOptions& options);

/// The job as an atlas store records it (commands::atlas_store_identity of
/// the job file and its --set assignments).
atlas::StoreIdentity atlas_store_identity(const JobCommandOptions& options, int dof);

/// `robomill report OUTDIR`: report.html rebuilt from a command's output folder.
struct ReportOptions {
  std::filesystem::path dir;
  bool quiet = false;
};
int run_report(const ReportOptions& options);

}  // namespace robomill::app
