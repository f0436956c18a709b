// `mpirun -np N robomill toolpath JOB` (issue 19 item 6): the robot's work
// along a long program shared over MPI ranks (analysis::BlockSharing). Every
// rank reads the program and runs it over its own stock — the engagement is
// sequential and cheap beside the robot — and walks every block's postures,
// since each block's inverse kinematics starts from the posture before.
// Block b's deflections, offsets and stable depths (the cost) are computed
// by rank b mod N, which sends them packed to rank 0; rank 0 records every
// block in program order, writes the files and prints. Each block is
// computed exactly as in the single-process run (the shortcut never crosses
// a block), so the files are the same bit for bit.

#include <mpi.h>

#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "mpi.hpp"
#include "robomill/analysis/program_run.hpp"
#include "robomill/core/error.hpp"
#include "robomill/robot_path/robot_along_path.hpp"

namespace robomill::app {
namespace {

// rank → 0: [block, exact, checked, max error, the draws' exact and max
// error, n draws, n draws' chattering samples, packed samples…]
constexpr int kTagBlock = 3;
constexpr std::size_t kHead = 7;

}  // namespace

int run_toolpath_mpi(const JobCommandOptions& options, int rank, int ranks) {
  const job::Job job = load(options);
  analysis::BlockSharing sharing;
  sharing.process = rank;
  sharing.processes = ranks;
  int dof = 0;
  std::vector<double> message;
  sharing.send = [&](std::size_t block, std::span<const robot_path::RobotSample> out,
                     const robot_path::ShortcutChecks& checks) {
    const std::size_t stride = robot_path::packed_size(dof);
    const std::size_t head = kHead + checks.draw_chatter_samples.size();
    message.assign(head + out.size() * stride, 0.0);
    message[0] = static_cast<double>(block);
    message[1] = static_cast<double>(checks.exact);
    message[2] = static_cast<double>(checks.checked);
    message[3] = checks.max_error;
    message[4] = static_cast<double>(checks.draw_exact);
    message[5] = checks.draw_max_error;
    message[6] = static_cast<double>(checks.draw_chatter_samples.size());
    std::copy(checks.draw_chatter_samples.begin(), checks.draw_chatter_samples.end(),
              message.begin() + kHead);
    for (std::size_t i = 0; i < out.size(); ++i)
      robot_path::pack(out[i], dof, message.data() + head + i * stride);
    MPI_Send(message.data(), static_cast<int>(message.size()), MPI_DOUBLE, 0, kTagBlock,
             MPI_COMM_WORLD);
  };
  sharing.receive = [&](std::size_t block, std::span<robot_path::RobotSample> out,
                        robot_path::ShortcutChecks& checks) {
    const int from = static_cast<int>(block % static_cast<std::size_t>(ranks));
    MPI_Status status;
    MPI_Probe(from, kTagBlock, MPI_COMM_WORLD, &status);
    int count = 0;
    MPI_Get_count(&status, MPI_DOUBLE, &count);
    message.resize(static_cast<std::size_t>(count));
    MPI_Recv(message.data(), count, MPI_DOUBLE, from, kTagBlock, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    // The stride from the message: rank 0 never builds the robot's model
    // itself (RobotSample packs its joints' count).
    const std::size_t head =
        message.size() < kHead ? kHead : kHead + static_cast<std::size_t>(message[6]);
    const std::size_t stride =
        out.empty() || message.size() < head ? 0 : (message.size() - head) / out.size();
    // Ranks send their blocks in program order and MPI keeps one sender's
    // order: anything else is a bug, not bad input.
    if (message.size() < head || message.size() != head + out.size() * stride ||
        stride < robot_path::packed_size(0) || static_cast<std::size_t>(message[0]) != block)
      throw Error(
          fmt::format("MPI rank {} sent {} values where block {} of {} samples was "
                      "expected",
                      from, message.size(), block, out.size()));
    checks.exact = static_cast<std::size_t>(message[1]);
    checks.checked = static_cast<std::size_t>(message[2]);
    checks.max_error = message[3];
    checks.draw_exact = static_cast<std::size_t>(message[4]);
    checks.draw_max_error = message[5];
    checks.draw_chatter_samples.assign(message.begin() + kHead,
                                       message.begin() + static_cast<std::ptrdiff_t>(head));
    for (std::size_t i = 0; i < out.size(); ++i)
      out[i] = robot_path::unpack(message.data() + head + i * stride,
                                  static_cast<int>(stride - robot_path::packed_size(0)));
  };

  if (rank != 0) {
    analysis::ProgramRunOptions run;
    run.threads = options.threads;
    run.sharing = &sharing;
    run.on_start = [&](const analysis::ProgramRun& r) {
      dof = r.robot ? r.robot->model().dof() : 0;
    };
    analysis::run_program(job, run);
    return 0;
  }

  return run_toolpath(options, &sharing);
}

}  // namespace robomill::app
