#pragma once
// The job commands of DESIGN.md §3 as library calls: each takes a loaded
// job (job::load_job) and returns its CommandResult (tables, documents,
// summary.json) without writing or printing anything. The numerical work is
// the typed modules' (analysis/, toolpath/, monitoring/ ...); these turn
// their SI results into the public output files' columns and keys. The
// command line (apps/robomill: arguments, writing, printing) and the Python
// module share them, so both give the same files. All throw what the
// commands report: InputError naming the field and line, NumericalError.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "robomill/analysis/frf_synthesis.hpp"
#include "robomill/atlas/atlas.hpp"
#include "robomill/atlas/store.hpp"
#include "robomill/commands/command_result.hpp"
#include "robomill/job/job.hpp"
#include "robomill/robot/robot_model.hpp"

namespace robomill::analysis {
struct BlockSharing;      // analysis/program_run.hpp
struct RecordingVerdict;  // analysis/recording_verdicts.hpp
struct StabilityDiagram;  // analysis/stability_diagram.hpp
}  // namespace robomill::analysis

namespace robomill::commands {

/// `threads`: up to that many threads, 0 for all cores.
CommandResult compute_forces(const job::Job& job, int threads);
CommandResult compute_stability(const job::Job& job, int threads);
/// What `stability` writes (sld.csv, summary.json, ...) for a diagram
/// computed already (analysis::stability_diagram of the same job).
CommandResult stability_result(const job::Job& job, const analysis::StabilityDiagram& diagram);
CommandResult compute_fit_modes(const job::Job& job);
CommandResult compute_simulate(const job::Job& job);
CommandResult compute_robot(const job::Job& job, int threads);
/// Takes a copy: a job without a deflection: section gets the defaults.
CommandResult compute_deflection(job::Job job, int threads);
CommandResult compute_optimize(const job::Job& job, int threads);
CommandResult compute_advise(const job::Job& job, int threads);
CommandResult compute_surface(const job::Job& job, int threads);

/// `robomill toolpath`: the program on the stock (and the robot along it).
/// With `samples_file` the samples stream into that file (the result's
/// `streamed` names it) so memory does not grow with the program; without,
/// they are the table "samples". With `optimize` (and a robot on the
/// program) also the program written back with better spindle speeds, ψ,
/// feeds and compensation (program_optimized.<ext>) and the whole analysis
/// re-run on it (summary.json's `optimization`); its scratch files go next
/// to `samples_file`, else into the system's temporary folder. With
/// `sharing` (process 0 of several: the command line's MPI ranks) the
/// robot's blocks are shared out (analysis::BlockSharing); the result is the
/// same.
CommandResult compute_toolpath(const job::Job& job, int threads,
                               const std::filesystem::path& samples_file = {},
                               const Progress& progress = {}, bool optimize = false,
                               const analysis::BlockSharing* sharing = nullptr);

/// `robomill listen`: the chatter verdict of the job's recordings (issue 22,
/// docs/monitoring.md); with a stability: section also the lobes (sld) and
/// the model's prediction at each recorded cut.
CommandResult compute_listen(const job::Job& job, int threads, const Progress& progress = {});
/// One judged recording's keys as `listen` writes them in summary.json (its
/// "recordings" entries); Python's analyze_signal returns the same keys.
nlohmann::json listen_recording_json(const analysis::RecordingVerdict& recording);

/// `robomill learn`: the posterior of the job's uncertain inputs given its
/// experiments, the prior and posterior bands, and the next test to run
/// (issue 35, docs/learning.md).
CommandResult compute_learn(const job::Job& job, int threads);

/// `robomill identify-cutting DATA`: the test's setup as typed on the
/// command line (quantities with units), else from a job's tool and process.
struct IdentifyCuttingInputs {
  std::filesystem::path data_file;
  std::filesystem::path job_file;  ///< optional: tool and process from a job
  std::string teeth, axial_depth, radial_depth, diameter;  ///< quantities as typed
  std::string direction;             ///< "down" | "up" (default down; irrelevant for slots)
  std::string measured_on = "tool";  ///< "tool" | "workpiece" (dynamometer)
};
/// Reads the data file (and the job, if any) itself.
CommandResult compute_identify_cutting(const IdentifyCuttingInputs& inputs);

/// `robomill identify-stiffness DATA --job ROBOT.yaml`: Kq from loading tests
/// (000 §6.1), or with `synthesize` the tests' displacements on the job's robot.
struct IdentifyStiffnessSettings {
  std::filesystem::path data_file;
  double max_condition = 1e6;
  bool synthesize = false;
  double noise = 0.0;  ///< relative displacement noise of --synthesize
  std::uint32_t seed = 1;
};
/// With `synthesize` the result holds only the loading_tests table (no summary).
CommandResult compute_identify_stiffness(const job::Job& job,
                                         const IdentifyStiffnessSettings& settings);

/// `robomill frf JOB`: FRFs synthesized from the job's modal table
/// (analysis/frf_synthesis.hpp: the grid, kind and noise), written as
/// `format`.
struct FrfSettings : analysis::FrfSynthesisSettings {
  std::string format = "uff58";  ///< uff58, uff58b or csv
};
CommandResult compute_frf(const job::Job& job, const FrfSettings& settings);

/// The atlas's computation for a job with an atlas: and a robot: section
/// (the robot's posture seeds every item's inverse kinematics); `model` must
/// outlive it.
atlas::AtlasContext atlas_context(const job::Job& job, const robot::RobotModel& model);

/// The job as an atlas store records it (its hash decides whether a store may
/// be resumed): the job file's bytes, then each --set.
atlas::StoreIdentity atlas_store_identity(const std::filesystem::path& job_file,
                                          const std::vector<std::string>& overrides, int dof);

/// The same identity for a job given as text (a job built in memory).
atlas::StoreIdentity atlas_store_identity_of_text(std::string job_text,
                                                  const std::vector<std::string>& overrides,
                                                  int dof);

/// Where an atlas run stands, reported from the thread that commits.
struct AtlasProgress {
  std::int64_t done = 0;   ///< items in the store, this run's included
  std::int64_t total = 0;  ///< items of the atlas
  double items_per_s = 0.0;
  double seconds_left = 0.0;  ///< NaN until the first commit
};

struct AtlasRunOptions {
  int threads = 0;       ///< 0: all cores
  bool restart = false;  ///< discard a store written by another job or version
  /// Called every quarter second and once at the end (optional).
  std::function<void(const AtlasProgress&)> progress;
  /// Set from outside (a signal handler) to stop after the items in flight.
  const std::atomic<bool>* interrupt = nullptr;
};

struct AtlasRun {
  std::int64_t computed = 0;  ///< items this run computed and committed
  std::int64_t already = 0;   ///< items the store held when it started
  std::int64_t done = 0;      ///< items the store holds now
  std::int64_t total = 0;
  int threads = 0;
  double elapsed_s = 0.0;
  bool interrupted = false;  ///< stopped by `interrupt` with items left
};

/// `robomill atlas JOB`: every pending item of the job's atlas (atlas: and
/// robot: sections) computed on a thread pool and committed in batches to the
/// resumable SQLite store `atlas.store`. Workers take item ids from an atomic
/// counter and hand results to the calling thread, which alone owns the store
/// connection. Every item is computed from the same seed posture, so the
/// store does not depend on the thread count or the order in which items
/// finish. A store of another job or version is an InputError naming
/// atlas.store unless `restart`.
AtlasRun run_atlas(const job::Job& job, const atlas::StoreIdentity& identity,
                   const AtlasRunOptions& options = {});

/// `robomill atlas JOB --export`: the store's finished items as the table
/// "atlas" and summary.json.
CommandResult compute_atlas_export(const job::Job& job, const atlas::StoreIdentity& identity);

}  // namespace robomill::commands
