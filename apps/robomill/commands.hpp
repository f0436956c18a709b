#pragma once
// The command-line tool's commands. Each is thin: load and validate the job,
// call the library, hand results to the writers. Each command is split into
// compute_<name> (job in, CommandResult out; no files, no printing), shared
// by the command line and the Python module, and run_<name> (load, compute,
// write_result, print).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "robomill/atlas/atlas.hpp"
#include "robomill/atlas/store.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/job.hpp"

namespace robomill::app {

/// Everything one command produces, before anything is written.
struct CommandResult {
  /// CSV tables in the order they are written, by file name without ".csv"
  /// ("sld", "sld_envelope"); written when the job's output.csv is on.
  std::vector<std::pair<std::string, io::CsvTable>> tables;
  /// Further JSON documents by file name without ".json" ("advice");
  /// written when output.json is on.
  std::vector<std::pair<std::string, nlohmann::json>> documents;
  /// Other files by full name ("modes.yaml", "frf.uff"); always written.
  std::vector<std::pair<std::string, std::string>> texts;
  /// Files the computation already streamed to a hidden temporary in the
  /// output folder (`samples.csv` of a whole program), by final name; renamed
  /// into place with the rest when output.csv is on, removed otherwise.
  std::vector<std::pair<std::string, std::filesystem::path>> streamed;
  /// summary.json; written when output.json is on.
  nlohmann::json summary;
  /// What the command prints (unless --quiet) before its "written to" line.
  std::string message;

  const io::CsvTable* table(const std::string& name) const;
};

/// Stages every file of a result in one io::OutputBundle under `out` and
/// commits it (all files or none). With `report` (the commands' default,
/// off under --quiet) and the job's output.formats allowing html, adds
/// report.html rendered from the staged files (report::render_html).
void write_result(const std::filesystem::path& out, const io::OutputSettings& output,
                  const CommandResult& result, bool report = false);

/// Adds the job's key inputs (report/key_inputs.hpp) to a result as the
/// document "inputs" (inputs.json; the report's inputs table).
void add_key_inputs(CommandResult& result, const io::Job& job);

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
io::Job load(const JobCommandOptions& options);

/// The folder a command writes into: --out, else the job's output.dir
/// (relative to the job file), else out/<command>.
std::filesystem::path output_dir(const JobCommandOptions& options, const io::Job& job,
                                 const std::string& command);

int run_validate(const JobCommandOptions& options);

/// The sections a job has, in `robomill validate`'s order and names.
std::vector<std::string> job_sections(const io::Job& job);

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

/// A job command's whole run: load the job, compute, add the key inputs,
/// write (with report.html unless --quiet), print the message and the folder.
int run_job_command(const JobCommandOptions& options, const std::string& command,
                    const std::function<CommandResult(const io::Job&)>& compute);

// The computations behind the commands (the command line and the Python
// module call these; they throw what the commands report).
CommandResult compute_forces(const io::Job& job, int threads);
CommandResult compute_stability(const io::Job& job, int threads);
CommandResult compute_fit_modes(const io::Job& job);
CommandResult compute_simulate(const io::Job& job);
CommandResult compute_robot(const io::Job& job, int threads);
/// Takes a copy: a job without a deflection: section gets the defaults.
CommandResult compute_deflection(io::Job job, int threads);
CommandResult compute_optimize(const io::Job& job, int threads);
CommandResult compute_advise(const io::Job& job, int threads);
CommandResult compute_surface(const io::Job& job, int threads);
/// With `samples_file` the samples stream into that file (the result's
/// `streamed` names it) so memory does not grow with the program; without,
/// they are the table "samples". `progress`: a bar on a terminal's stderr.
/// With `optimize` (and a robot on the program) also the program written
/// back with better spindle speeds (program_optimized.<ext>) and the whole
/// analysis re-run on it (summary.json's `optimization`).
CommandResult compute_toolpath(const io::Job& job, int threads,
                               const std::filesystem::path& samples_file = {},
                               bool progress = false, bool optimize = false);

/// `robomill listen`: the chatter verdict of the job's recordings (issue 22,
/// docs/monitoring.md); with a stability: section also the lobes (sld) and
/// the model's prediction at each recorded cut. `progress`: a bar per file.
CommandResult compute_listen(const io::Job& job, int threads, bool progress = false);

int run_forces(const JobCommandOptions& options);
int run_listen(const JobCommandOptions& options);
int run_stability(const JobCommandOptions& options);
int run_fit_modes(const JobCommandOptions& options);
int run_robot(const JobCommandOptions& options);
int run_deflection(const JobCommandOptions& options);
int run_optimize(const JobCommandOptions& options);
int run_advise(const JobCommandOptions& options);
int run_simulate(const JobCommandOptions& options);
int run_surface(const JobCommandOptions& options);
int run_toolpath(const JobCommandOptions& options);

struct IdentifyOptions {
  std::filesystem::path data_file;
  std::filesystem::path job_file;  ///< optional: tool and process from a job
  std::string teeth, axial_depth, radial_depth, diameter;  ///< quantities as typed
  std::string direction;             ///< "down" | "up" (default down; irrelevant for slots)
  std::string measured_on = "tool";  ///< "tool" | "workpiece" (dynamometer)
  std::filesystem::path out_dir;
  bool quiet = false;
};
int run_identify_cutting(const IdentifyOptions& options);
/// Reads the data file (and the job, if any) itself; out_dir and quiet unused.
CommandResult compute_identify_cutting(const IdentifyOptions& options);

/// `robomill identify-stiffness DATA --job ROBOT.yaml`: Kq from loading tests
/// (000 §6.1), or with `synthesize` the tests' displacements on the job's robot.
struct IdentifyStiffnessOptions {
  std::filesystem::path data_file;
  JobCommandOptions job;  ///< job_file: the robot; out, overrides, quiet
  double max_condition = 1e6;
  bool synthesize = false;
  double noise = 0.0;  ///< relative displacement noise of --synthesize
  std::uint32_t seed = 1;
};
int run_identify_stiffness(const IdentifyStiffnessOptions& options);
/// The job is options.job's, loaded; with `synthesize` the result holds only
/// the loading_tests table (no summary).
CommandResult compute_identify_stiffness(const io::Job& job,
                                         const IdentifyStiffnessOptions& options);

/// `robomill frf JOB`: FRFs synthesized from the job's modal table.
struct FrfCommandOptions {
  JobCommandOptions job;
  std::string from, to, step;      ///< frequencies as typed ("10 Hz"); empty: automatic
  std::string spacing = "linear";  ///< linear (from, to, step) or log (from, to, points)
  int points = 5000;               ///< log spacing
  std::string kind = "receptance";
  std::string format = "uff58";  ///< uff58, uff58b or csv
  double noise = 0.0;            ///< relative complex noise (0.02 = 2 %)
  std::uint32_t seed = 1;
};
int run_frf(const FrfCommandOptions& options);
CommandResult compute_frf(const io::Job& job, const FrfCommandOptions& options);

/// `robomill atlas JOB`: the workspace atlas into its SQLite store (issue 11);
/// with `export_dir` the store's results as atlas.csv and summary.json.
struct AtlasOptions {
  JobCommandOptions job;  ///< job_file, overrides, threads, quiet
  std::filesystem::path export_dir;
  bool restart = false;  ///< discard a store written by another job
};
int run_atlas(const AtlasOptions& options);

/// The atlas's computation for a job with an atlas: and a robot: section
/// (the robot's posture seeds every item's inverse kinematics); `model` must
/// outlive it.
atlas::AtlasContext atlas_context(const io::Job& job, const robot::RobotModel& model);

/// The job as an atlas store records it (its hash decides whether a store may
/// be resumed): the job file's bytes, then each --set.
atlas::StoreIdentity atlas_store_identity(const JobCommandOptions& options, int dof);

/// `robomill report OUTDIR`: report.html rebuilt from a command's output folder.
struct ReportOptions {
  std::filesystem::path dir;
  bool quiet = false;
};
int run_report(const ReportOptions& options);

}  // namespace robomill::app
