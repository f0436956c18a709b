// The atlas's job-level pieces (robomill/commands/commands.hpp): its
// computation from a job, the job's identity in a store, the run over a store
// (threads, batches committed as they finish) and the export of a store's
// finished items. The command line adds signals, progress text and MPI ranks
// (apps/robomill); Python calls the same run (robomill.atlas).

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "robomill/commands/commands.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"
#include "robomill/core/parallel.hpp"
#include "robomill/io/csv.hpp"

namespace robomill::commands {

atlas::AtlasContext atlas_context(const job::Job& job, const robot::RobotModel& model) {
  std::optional<tool::Tool> tool;
  if (job.tool)
    tool.emplace(*job.tool);
  return atlas::AtlasContext(
      *job.atlas, model,
      Eigen::Map<const Eigen::VectorXd>(job.robot->posture_rad.data(), model.dof()), tool,
      job.cutting, job.process);
}

atlas::StoreIdentity atlas_store_identity(const std::filesystem::path& job_file,
                                          const std::vector<std::string>& overrides, int dof) {
  std::ifstream in(job_file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return atlas_store_identity_of_text(text.str(), overrides, dof);
}

atlas::StoreIdentity atlas_store_identity_of_text(std::string job_text,
                                                  const std::vector<std::string>& overrides,
                                                  int dof) {
  std::string canonical = std::move(job_text);
  for (const std::string& o : overrides)
    canonical += "\n# --set " + o;
  atlas::StoreIdentity identity;
  identity.job_text = canonical;
  identity.job_hash = atlas::fnv1a_hex(canonical);
  identity.dof = dof;
  return identity;
}

AtlasRun run_atlas(const job::Job& job, const atlas::StoreIdentity& identity,
                   const AtlasRunOptions& options) {
  if (!job.atlas)
    throw InputError("atlas", 0, "required: the atlas: section (grid, analyses, store)");
  if (!job.robot)
    throw InputError("robot", 0, "required by the atlas: the robot whose workspace it maps");
  const atlas::AtlasSpec& spec = *job.atlas;
  const robot::RobotModel model(job.robot->description);
  const atlas::AtlasContext context = atlas_context(job, model);
  const auto interrupted = [&] { return options.interrupt && options.interrupt->load(); };
  try {
    atlas::AtlasStore store(spec.store, identity, spec, options.restart);
    const std::vector<std::int64_t> pending = store.pending();
    AtlasRun run;
    run.total = store.item_total();
    run.already = run.total - static_cast<std::int64_t>(pending.size());
    run.threads = std::min<int>(core::resolve_thread_count(options.threads),
                                std::max<std::size_t>(pending.size(), 1));

    std::atomic<std::size_t> next{0};
    std::atomic<bool> stop{false};
    std::mutex mutex;
    std::condition_variable ready;
    std::vector<std::pair<std::int64_t, atlas::AtlasResult>> queue, batch;
    std::exception_ptr failure;
    int running = run.threads;
    std::vector<std::thread> pool;
    pool.reserve(static_cast<std::size_t>(run.threads));
    const auto start = std::chrono::steady_clock::now();
    for (int w = 0; w < run.threads; ++w) {
      pool.emplace_back([&] {
        try {
          for (;;) {
            if (stop.load() || interrupted())
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

    // The calling thread: commit what the workers hand back, every quarter
    // second (or every `batch` items), and report progress.
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
          run.computed += static_cast<std::int64_t>(batch.size());
        } catch (...) {
          store_failure = std::current_exception();
          stop.store(true);
        }
        batch.clear();
        last_commit = now;
      }
      if (options.progress &&
          (now - last_report >= std::chrono::milliseconds(250) || workers_done)) {
        AtlasProgress p;
        const double elapsed = std::chrono::duration<double>(now - start).count();
        p.items_per_s = elapsed > 0.0 ? static_cast<double>(run.computed) / elapsed : 0.0;
        p.done = run.already + run.computed;
        p.total = run.total;
        p.seconds_left = p.items_per_s > 0.0
                             ? static_cast<double>(run.total - p.done) / p.items_per_s
                             : std::nan("");
        options.progress(p);
        last_report = now;
      }
    }
    for (std::thread& worker : pool)
      worker.join();
    if (store_failure)
      std::rethrow_exception(store_failure);
    if (failure)
      std::rethrow_exception(failure);
    run.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    run.done = run.already + run.computed;
    run.interrupted = interrupted() && run.done < run.total;
    return run;
  } catch (const atlas::StoreMismatch& mismatch) {
    throw InputError("atlas.store", 0, mismatch.what());
  }
}

CommandResult compute_atlas_export(const job::Job& job, const atlas::StoreIdentity& identity) {
  const atlas::AtlasSpec& spec = *job.atlas;
  atlas::AtlasStore store(spec.store, identity);
  const std::int64_t total = store.item_total();
  const std::vector<atlas::StoredItem> rows = store.finished();
  const int dof = store.dof();
  std::vector<std::string> columns = {"item",
                                      "x_mm",
                                      "y_mm",
                                      "z_mm",
                                      "redundancy_deg",
                                      "reachable",
                                      "lowest_fn_hz",
                                      "compliance_feed_um_per_N",
                                      "compliance_normal_um_per_N",
                                      "compliance_axial_um_per_N",
                                      "condition_number",
                                      "depth_min_mm",
                                      "speed_at_min_rpm",
                                      "depth_max_mm",
                                      "speed_at_max_rpm"};
  for (int j = 0; j < dof; ++j)
    columns.push_back(fmt::format("q{}_deg", j + 1));
  io::CsvTable table(columns);
  int reachable = 0;
  double fn_low = INFINITY, fn_high = 0.0, dmin_low = INFINITY, dmin_high = 0.0;
  for (const atlas::StoredItem& s : rows) {
    const atlas::AtlasResult& r = s.result;
    std::vector<double> row = {static_cast<double>(s.item.id),
                               s.item.position_m.x() * 1e3,
                               s.item.position_m.y() * 1e3,
                               s.item.position_m.z() * 1e3,
                               s.item.redundancy_rad * kDegPerRad,
                               r.reachable ? 1.0 : 0.0,
                               r.lowest_frequency_hz,
                               r.compliance_feed_m_per_n * 1e6,
                               r.compliance_normal_m_per_n * 1e6,
                               r.compliance_axial_m_per_n * 1e6,
                               r.condition_number,
                               r.depth_min_m * 1e3,
                               r.speed_at_min_rad_s * kRpmPerRadS,
                               r.depth_max_m * 1e3,
                               r.speed_at_max_rad_s * kRpmPerRadS};
    for (int j = 0; j < dof; ++j)
      row.push_back(r.reachable && r.q.size() == dof ? r.q[j] * kDegPerRad : 0.0);
    table.add_row(row);
    if (r.reachable) {
      ++reachable;
      if (spec.frequency) {
        fn_low = std::min(fn_low, r.lowest_frequency_hz);
        fn_high = std::max(fn_high, r.lowest_frequency_hz);
      }
      if (spec.stability) {
        dmin_low = std::min(dmin_low, r.depth_min_m);
        dmin_high = std::max(dmin_high, r.depth_min_m);
      }
    }
  }
  nlohmann::json summary = {{"command", "atlas"},
                            {"job", job.source.string()},
                            {"store", spec.store.string()},
                            {"job_hash", identity.job_hash},
                            {"code_version", identity.code_version},
                            {"items", total},
                            {"finished", rows.size()},
                            {"complete", static_cast<std::int64_t>(rows.size()) == total},
                            {"reachable", reachable}};
  if (reachable > 0 && spec.frequency)
    summary["lowest_fn_hz"] = {{"min", fn_low}, {"max", fn_high}};
  if (reachable > 0 && spec.stability)
    summary["depth_min_mm"] = {{"min", dmin_low * 1e3}, {"max", dmin_high * 1e3}};
  CommandResult result;
  result.tables.emplace_back("atlas", std::move(table));
  result.summary = std::move(summary);
  result.message =
      fmt::format("atlas: {} of {} items finished ({} reachable)", rows.size(), total, reachable);
  return result;
}

}  // namespace robomill::commands
