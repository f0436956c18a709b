// `mpirun -np N robomill atlas JOB`: the atlas over MPI ranks (issue 11).
// Rank 0 owns the store and deals item ids in small
// chunks to whichever rank asks (dynamic load balance); it also computes on a
// thread of its own. Workers send back their chunk's packed results with the
// next request. Results are bitwise those of the threaded run.

#include "mpi.hpp"

#include <fmt/format.h>
#include <mpi.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <mutex>
#include <thread>
#include <vector>

#include "robomill/atlas/atlas.hpp"
#include "robomill/atlas/store.hpp"
#include "robomill/core/error.hpp"
#include "robomill/robot/robot_model.hpp"

namespace robomill::app {
namespace {

constexpr int kTagResults = 1;  // worker → 0: [id, packed result]… (doubles); empty: ready
constexpr int kTagChunk = 2;    // 0 → worker: item ids (int64); empty: stop
constexpr std::size_t kChunk = 4;

void worker_rank(const atlas::AtlasContext& context, const atlas::AtlasSpec& spec, int dof) {
  const int stride = 1 + atlas::packed_size(dof);
  std::vector<double> out;
  std::vector<std::int64_t> ids(kChunk);
  for (;;) {
    MPI_Send(out.data(), static_cast<int>(out.size()), MPI_DOUBLE, 0, kTagResults, MPI_COMM_WORLD);
    MPI_Status status;
    MPI_Recv(ids.data(), static_cast<int>(kChunk), MPI_INT64_T, 0, kTagChunk, MPI_COMM_WORLD,
             &status);
    int count = 0;
    MPI_Get_count(&status, MPI_INT64_T, &count);
    if (count == 0)
      return;
    out.assign(static_cast<std::size_t>(count) * stride, 0.0);
    for (int i = 0; i < count; ++i) {
      const atlas::AtlasResult r = context.evaluate(atlas::item(spec, ids[i]));
      out[static_cast<std::size_t>(i) * stride] = static_cast<double>(ids[i]);
      atlas::pack(r, dof, out.data() + static_cast<std::size_t>(i) * stride + 1);
    }
  }
}

int dealer_rank(const AtlasOptions& options, const atlas::AtlasContext& context,
                const atlas::AtlasSpec& spec, atlas::AtlasStore& store, int ranks) {
  const int dof = context.model().dof();
  const int stride = 1 + atlas::packed_size(dof);
  const std::vector<std::int64_t> pending = store.pending();
  const std::int64_t total = store.item_total();
  const std::int64_t already = total - static_cast<std::int64_t>(pending.size());
  const auto start = std::chrono::steady_clock::now();
  std::atomic<std::size_t> next{0};
  std::mutex mutex;
  std::vector<std::pair<std::int64_t, atlas::AtlasResult>> local, batch;
  std::exception_ptr failure;  // set under `mutex`; `failed` tells the dealer loop
  std::atomic<bool> failed{false}, local_done{false};
  // Rank 0 computes too, one item at a time from the same counter.
  std::thread own([&] {
    try {
      for (std::size_t i; (i = next.fetch_add(1)) < pending.size();) {
        atlas::AtlasResult r = context.evaluate(atlas::item(spec, pending[i]));
        const std::lock_guard lock(mutex);
        local.emplace_back(pending[i], std::move(r));
      }
    } catch (...) {
      const std::lock_guard lock(mutex);
      failure = std::current_exception();
      failed.store(true);
    }
    local_done.store(true);
  });
  // If the dealer loop throws (a failed commit), stop and join the thread
  // before the exception leaves: a joinable std::thread would terminate.
  struct JoinOnExit {
    std::thread& thread;
    std::atomic<std::size_t>& next;
    std::size_t end;
    ~JoinOnExit() {
      if (thread.joinable()) {
        next.store(end);
        thread.join();
      }
    }
  } join_on_exit{own, next, pending.size()};
  int active = ranks - 1;
  std::vector<double> in;
  std::vector<std::int64_t> chunk;
  std::int64_t committed = 0;
  auto last_commit = std::chrono::steady_clock::now();
  while (active > 0 || !local_done.load()) {
    int flag = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, kTagResults, MPI_COMM_WORLD, &flag, &status);
    if (flag) {
      int count = 0;
      MPI_Get_count(&status, MPI_DOUBLE, &count);
      in.resize(static_cast<std::size_t>(count));
      MPI_Recv(in.data(), count, MPI_DOUBLE, status.MPI_SOURCE, kTagResults, MPI_COMM_WORLD,
               MPI_STATUS_IGNORE);
      for (int k = 0; k + stride <= count; k += stride)
        batch.emplace_back(static_cast<std::int64_t>(in[static_cast<std::size_t>(k)]),
                           atlas::unpack(in.data() + k + 1, dof));
      chunk.clear();
      for (std::size_t c = 0; c < kChunk && !failed.load(); ++c) {
        const std::size_t i = next.fetch_add(1);
        if (i >= pending.size())
          break;
        chunk.push_back(pending[i]);
      }
      MPI_Send(chunk.data(), static_cast<int>(chunk.size()), MPI_INT64_T, status.MPI_SOURCE,
               kTagChunk, MPI_COMM_WORLD);
      if (chunk.empty())
        --active;
    } else {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    {
      const std::lock_guard lock(mutex);
      batch.insert(batch.end(), std::make_move_iterator(local.begin()),
                   std::make_move_iterator(local.end()));
      local.clear();
    }
    const auto now = std::chrono::steady_clock::now();
    if (!batch.empty() && now - last_commit >= std::chrono::milliseconds(250)) {
      store.commit(batch);
      committed += static_cast<std::int64_t>(batch.size());
      batch.clear();
      last_commit = now;
    }
  }
  own.join();
  batch.insert(batch.end(), std::make_move_iterator(local.begin()),
               std::make_move_iterator(local.end()));
  store.commit(batch);
  committed += static_cast<std::int64_t>(batch.size());
  if (failure)
    std::rethrow_exception(failure);
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!options.job.quiet) {
    std::cout << fmt::format(
        "atlas: {} items computed in {:.2f} s on {} MPI ranks ({:.1f} items/s); {} were already "
        "in the store; {} of {} done → {}\n",
        committed, elapsed, ranks, elapsed > 0.0 ? static_cast<double>(committed) / elapsed : 0.0,
        already, already + committed, total, spec.store.string());
  }
  return 0;
}

}  // namespace

int run_atlas_mpi(const AtlasOptions& options, int rank, int ranks) {
  const job::Job job = load(options.job);
  if (!job.atlas)
    throw InputError("atlas", 0, "required: the atlas: section (grid, analyses, store)");
  const atlas::AtlasSpec& spec = *job.atlas;
  const robot::RobotModel model(job.robot->description);
  const atlas::AtlasContext context = atlas_context(job, model);
  if (rank != 0) {
    worker_rank(context, spec, model.dof());
    return 0;
  }
  try {
    atlas::AtlasStore store(spec.store, atlas_store_identity(options.job, model.dof()), spec,
                            options.restart);
    return dealer_rank(options, context, spec, store, ranks);
  } catch (const atlas::StoreMismatch& mismatch) {
    throw InputError("atlas.store", 0, mismatch.what());
  }
}

namespace {

/// Open MPI, MPICH (Hydra) and PMIx launchers set these in every rank.
bool launched_by_mpirun() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"}) {
    if (std::getenv(name) != nullptr)
      return true;
  }
  return false;
}

}  // namespace

MpiSession::MpiSession(int& argc, char**& argv) {
  if (!launched_by_mpirun())
    return;
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks_);
  initialized_ = true;
}

MpiSession::~MpiSession() {
  if (initialized_)
    MPI_Finalize();
}

int MpiSession::exit(int code) {
  // A failing rank would leave the others waiting for messages: end them all.
  if (initialized_ && ranks_ > 1 && code != 0)
    MPI_Abort(MPI_COMM_WORLD, code);
  return code;
}

}  // namespace robomill::app
