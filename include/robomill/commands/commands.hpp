#pragma once
// The job commands of DESIGN.md §3 as library calls: each takes a loaded
// job (io::load_job) and returns its CommandResult (tables, documents,
// summary.json) without writing or printing anything. The numerical work is
// the typed modules' (analysis/, toolpath/, monitoring/ ...); these turn
// their SI results into the public output files' columns and keys. The
// command line (apps/robomill: arguments, writing, printing) and the Python
// module share them, so both give the same files. All throw what the
// commands report: InputError naming the field and line, NumericalError.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "robomill/atlas/atlas.hpp"
#include "robomill/atlas/store.hpp"
#include "robomill/commands/command_result.hpp"
#include "robomill/io/job.hpp"
#include "robomill/robot/robot_model.hpp"

namespace robomill::analysis {
struct BlockSharing;  // analysis/program_run.hpp
}

namespace robomill::commands {

/// `threads`: up to that many threads, 0 for all cores.
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
CommandResult compute_toolpath(const io::Job& job, int threads,
                               const std::filesystem::path& samples_file = {},
                               const Progress& progress = {}, bool optimize = false,
                               const analysis::BlockSharing* sharing = nullptr);

/// `robomill listen`: the chatter verdict of the job's recordings (issue 22,
/// docs/monitoring.md); with a stability: section also the lobes (sld) and
/// the model's prediction at each recorded cut.
CommandResult compute_listen(const io::Job& job, int threads, const Progress& progress = {});

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
CommandResult compute_identify_stiffness(const io::Job& job,
                                         const IdentifyStiffnessSettings& settings);

/// `robomill frf JOB`: FRFs synthesized from the job's modal table.
struct FrfSettings {
  std::string from, to, step;      ///< frequencies as typed ("10 Hz"); empty: automatic
  std::string spacing = "linear";  ///< linear (from, to, step) or log (from, to, points)
  int points = 5000;               ///< log spacing
  std::string kind = "receptance";
  std::string format = "uff58";  ///< uff58, uff58b or csv
  double noise = 0.0;            ///< relative complex noise (0.02 = 2 %)
  std::uint32_t seed = 1;
};
CommandResult compute_frf(const io::Job& job, const FrfSettings& settings);

/// The atlas's computation for a job with an atlas: and a robot: section
/// (the robot's posture seeds every item's inverse kinematics); `model` must
/// outlive it.
atlas::AtlasContext atlas_context(const io::Job& job, const robot::RobotModel& model);

/// The job as an atlas store records it (its hash decides whether a store may
/// be resumed): the job file's bytes, then each --set.
atlas::StoreIdentity atlas_store_identity(const std::filesystem::path& job_file,
                                          const std::vector<std::string>& overrides, int dof);

/// `robomill atlas JOB --export`: the store's finished items as the table
/// "atlas" and summary.json.
CommandResult compute_atlas_export(const io::Job& job, const atlas::StoreIdentity& identity);

}  // namespace robomill::commands
