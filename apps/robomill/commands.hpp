#pragma once
// The command-line tool's commands. Each is thin: load and validate the job,
// call the library, hand results to the writers.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "robomill/io/job.hpp"

namespace robomill::app {

/// Options every job command shares (`robomill <command> JOB ...`).
struct JobCommandOptions {
  std::filesystem::path job_file;
  std::filesystem::path out_dir;  ///< empty: job's output.dir, else out/<command>
  std::vector<std::string> overrides;
  int threads = 0;
  bool quiet = false;
};

/// Parses the `--set` assignments and loads the job (throws InputError).
io::Job load(const JobCommandOptions& options);

/// The folder a command writes into: --out, else the job's output.dir
/// (relative to the job file), else out/<command>.
std::filesystem::path output_dir(const JobCommandOptions& options, const io::Job& job,
                                 const std::string& command);

int run_validate(const JobCommandOptions& options);
int run_forces(const JobCommandOptions& options);
int run_stability(const JobCommandOptions& options);
int run_fit_modes(const JobCommandOptions& options);
int run_robot(const JobCommandOptions& options);
int run_deflection(const JobCommandOptions& options);
int run_optimize(const JobCommandOptions& options);
int run_advise(const JobCommandOptions& options);
int run_simulate(const JobCommandOptions& options);
int run_surface(const JobCommandOptions& options);

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

/// `robomill atlas JOB`: the workspace atlas into its SQLite store (issue 11);
/// with `export_dir` the store's results as atlas.csv and summary.json.
struct AtlasOptions {
  JobCommandOptions job;  ///< job_file, overrides, threads, quiet
  std::filesystem::path export_dir;
  bool restart = false;  ///< discard a store written by another job
};
int run_atlas(const AtlasOptions& options);

}  // namespace robomill::app
