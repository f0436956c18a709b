// robomill atlas JOB: the workspace atlas of issue 11 — grid points ×
// redundancy angles, per item the job's analyses (compliance, lowest natural
// frequency, min/max stable depth over a spindle range), computed on a
// thread pool and committed in batches to a resumable SQLite store;
// `--export OUT` writes atlas.csv and summary.json from the store.
//
// Threads: workers take item ids from an atomic counter and hand results to
// the main thread, which alone owns the store connection. Every item is
// computed from the same seed posture, so the store does not depend on the
// thread count or the order in which items finish.

#include <fmt/format.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <fstream>
#include <iostream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <thread>

#include "commands.hpp"
#include "robomill/atlas/atlas.hpp"
#include "robomill/atlas/store.hpp"
#include "robomill/core/error.hpp"
#include "robomill/core/parallel.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/robot/robot_model.hpp"

namespace robomill::app {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;
constexpr double kRpmPerRadS = 60.0 / (2.0 * std::numbers::pi);

std::atomic<bool> g_interrupted{false};
extern "C" void on_interrupt(int) {
  g_interrupted.store(true);
}

}  // namespace

namespace {

std::string duration_text(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0)
    return "?";
  if (seconds < 120.0)
    return fmt::format("{:.0f} s", seconds);
  if (seconds < 7200.0)
    return fmt::format("{:.0f} min", seconds / 60.0);
  return fmt::format("{:.1f} h", seconds / 3600.0);
}

int export_store(const AtlasOptions& options, const io::Job& job,
                 const atlas::StoreIdentity& identity) {
  commands::CommandResult result = commands::compute_atlas_export(job, identity);
  commands::add_key_inputs(result, job);
  commands::write_result(options.export_dir, io::OutputSettings{}, result, !options.job.quiet);
  if (!options.job.quiet)
    std::cout << result.message << " → " << options.export_dir.string() << '\n';
  return 0;
}

}  // namespace

int run_atlas(const AtlasOptions& options) {
  const io::Job job = load(options.job);
  if (!job.atlas)
    throw InputError("atlas", 0, "required: the atlas: section (grid, analyses, store)");
  const atlas::AtlasSpec& spec = *job.atlas;
  const robot::RobotModel model(job.robot->description);
  const atlas::StoreIdentity identity = atlas_store_identity(options.job, model.dof());
  try {
    if (!options.export_dir.empty())
      return export_store(options, job, identity);

    const atlas::AtlasContext context = atlas_context(job, model);

    atlas::AtlasStore store(spec.store, identity, spec, options.restart);
    const std::vector<std::int64_t> pending = store.pending();
    const std::int64_t total = store.item_total();
    const std::int64_t already = total - static_cast<std::int64_t>(pending.size());
    const int threads = std::min<int>(core::resolve_thread_count(options.job.threads),
                                      std::max<std::size_t>(pending.size(), 1));
    const bool progress = !options.job.quiet && isatty(STDERR_FILENO);

    g_interrupted.store(false);
    auto previous_int = std::signal(SIGINT, on_interrupt);
    auto previous_term = std::signal(SIGTERM, on_interrupt);

    std::atomic<std::size_t> next{0};
    std::atomic<bool> stop{false};
    std::mutex mutex;
    std::condition_variable ready;
    std::vector<std::pair<std::int64_t, atlas::AtlasResult>> queue, batch;
    std::exception_ptr failure;
    int running = threads;
    std::vector<std::thread> pool;
    pool.reserve(static_cast<std::size_t>(threads));
    const auto start = std::chrono::steady_clock::now();
    for (int w = 0; w < threads; ++w) {
      pool.emplace_back([&] {
        try {
          for (;;) {
            if (stop.load() || g_interrupted.load())
              break;
            const std::size_t i = next.fetch_add(1);
            if (i >= pending.size())
              break;
            atlas::AtlasResult r = context.evaluate(atlas::item(spec, pending[i]));
            const std::lock_guard lock(mutex);
            queue.emplace_back(pending[i], std::move(r));
            ready.notify_one();
          }
        } catch (...) {
          const std::lock_guard lock(mutex);
          if (!failure)
            failure = std::current_exception();
          stop.store(true);
        }
        const std::lock_guard lock(mutex);
        --running;
        ready.notify_one();
      });
    }

    // The main thread: commit what the workers hand back, every quarter second
    // (or every `batch` items), and report progress.
    std::int64_t committed = 0;
    auto last_commit = std::chrono::steady_clock::now();
    auto last_report = last_commit - std::chrono::seconds(1);
    std::exception_ptr store_failure;
    for (bool workers_done = false; !workers_done;) {
      {
        std::unique_lock lock(mutex);
        ready.wait_for(lock, std::chrono::milliseconds(100), [&] {
          return running == 0 || (spec.batch > 0 && static_cast<int>(queue.size()) >= spec.batch);
        });
        workers_done = running == 0;
        batch.insert(batch.end(), std::make_move_iterator(queue.begin()),
                     std::make_move_iterator(queue.end()));
        queue.clear();
      }
      const auto now = std::chrono::steady_clock::now();
      const bool due =
          workers_done || (spec.batch > 0 ? static_cast<int>(batch.size()) >= spec.batch
                                          : now - last_commit >= std::chrono::milliseconds(250));
      if (due && !batch.empty() && !store_failure) {
        try {
          store.commit(batch);
          committed += static_cast<std::int64_t>(batch.size());
        } catch (...) {
          store_failure = std::current_exception();
          stop.store(true);
        }
        batch.clear();
        last_commit = now;
      }
      if (progress && (now - last_report >= std::chrono::milliseconds(250) || workers_done)) {
        const double elapsed = std::chrono::duration<double>(now - start).count();
        const double rate = elapsed > 0.0 ? static_cast<double>(committed) / elapsed : 0.0;
        const std::int64_t done = already + committed;
        const double left = rate > 0.0 ? static_cast<double>(total - done) / rate : NAN;
        std::cerr << fmt::format("\ratlas: {}/{} items ({:.1f} %), {:.1f} items/s, {} left   ",
                                 done, total,
                                 100.0 * static_cast<double>(done) /
                                     static_cast<double>(std::max<std::int64_t>(total, 1)),
                                 rate, duration_text(left))
                  << std::flush;
        last_report = now;
      }
    }
    for (std::thread& worker : pool)
      worker.join();
    std::signal(SIGINT, previous_int);
    std::signal(SIGTERM, previous_term);
    if (progress)
      std::cerr << '\n';
    if (store_failure)
      std::rethrow_exception(store_failure);
    if (failure)
      std::rethrow_exception(failure);
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::int64_t done = already + committed;
    if (g_interrupted.load() && done < total) {
      std::cerr << fmt::format(
          "robomill: interrupted: {} of {} items are in {}; run the same command to resume\n", done,
          total, spec.store.string());
      return 130;
    }
    if (!options.job.quiet) {
      std::cout << fmt::format(
          "atlas: {} items computed in {:.2f} s on {} threads ({:.1f} items/s); {} were already "
          "in the store; {} of {} done → {}\n",
          committed, elapsed, threads,
          elapsed > 0.0 ? static_cast<double>(committed) / elapsed : 0.0, already, done, total,
          spec.store.string());
    }
    return 0;
  } catch (const atlas::StoreMismatch& mismatch) {
    throw InputError("atlas.store", 0, mismatch.what());
  }
}

}  // namespace robomill::app
