#pragma once
// The commands that run over MPI ranks (`mpirun -np N robomill ...`):
// `atlas JOB` (issue 11: items dealt to the ranks, results gathered into rank
// 0's store) and `toolpath JOB` (issue 19: the robot's blocks along a long
// program shared out, analysis::BlockSharing). Compiled into the robomill
// executable only when MPI was found (ROBOMILL_WITH_MPI); the library and the
// Python module never link MPI.

#include "commands.hpp"

namespace robomill::app {

/// MPI for the lifetime of the program, initialized only when an MPI launcher
/// started it (so that `robomill` alone never touches MPI). One per process.
class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  int rank() const noexcept { return rank_; }
  int ranks() const noexcept { return ranks_; }

  /// The program's exit code; a non-zero one over several ranks aborts them
  /// all (MPI_Abort), since the others may be waiting for this one.
  int exit(int code);

 private:
  bool initialized_ = false;
  int rank_ = 0, ranks_ = 1;
};

/// The atlas over `ranks` MPI ranks: rank 0 owns the store (resumable, the
/// same rows as `run_atlas` for any rank count) and computes too; the other
/// ranks ask it for chunks of item ids and send back results.
int run_atlas_mpi(const AtlasOptions& options, int rank, int ranks);

/// `robomill toolpath` over `ranks` MPI ranks: every rank reads the program
/// and runs it over the stock; block b of the samples is computed in full by
/// rank b mod ranks (the others walk its postures only) and sent to rank 0,
/// which writes everything and, with --optimize, improves the program alone.
/// The files are those of the single-process run, bit for bit.
int run_toolpath_mpi(const JobCommandOptions& options, int rank, int ranks);

}  // namespace robomill::app
