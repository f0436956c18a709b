// robomill atlas JOB: the workspace atlas of issue 11 — grid points ×
// redundancy angles, per item the job's analyses (compliance, lowest natural
// frequency, min/max stable depth over a spindle range), computed by the
// library's commands::run_atlas (threads, batches committed to a resumable
// SQLite store); this file adds the signals that stop it, its progress line
// and its message. `--export OUT` writes atlas.csv and summary.json from the
// store.

#include <fmt/format.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <iostream>
#include <numbers>

#include "commands.hpp"
#include "robomill/atlas/atlas.hpp"
#include "robomill/atlas/store.hpp"
#include "robomill/core/error.hpp"
#include "robomill/robot/robot_model.hpp"

namespace robomill::app {
namespace {

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

int export_store(const AtlasOptions& options, const job::Job& job,
                 const atlas::StoreIdentity& identity) {
  commands::CommandResult result = commands::compute_atlas_export(job, identity);
  commands::add_key_inputs(result, job);
  commands::write_result(options.export_dir, job::OutputSettings{}, result, !options.job.quiet);
  if (!options.job.quiet)
    std::cout << result.message << " → " << options.export_dir.string() << '\n';
  return 0;
}

}  // namespace

int run_atlas(const AtlasOptions& options) {
  const job::Job job = load(options.job);
  if (!job.atlas)
    throw InputError("atlas", 0, "required: the atlas: section (grid, analyses, store)");
  const robot::RobotModel model(job.robot->description);
  const atlas::StoreIdentity identity = atlas_store_identity(options.job, model.dof());
  if (!options.export_dir.empty()) {
    try {
      return export_store(options, job, identity);
    } catch (const atlas::StoreMismatch& mismatch) {
      throw InputError("atlas.store", 0, mismatch.what());
    }
  }

  commands::AtlasRunOptions run_options;
  run_options.threads = options.job.threads;
  run_options.restart = options.restart;
  run_options.interrupt = &g_interrupted;
  if (!options.job.quiet && isatty(STDERR_FILENO)) {
    run_options.progress = [](const commands::AtlasProgress& p) {
      std::cerr << fmt::format("\ratlas: {}/{} items ({:.1f} %), {:.1f} items/s, {} left   ",
                               p.done, p.total,
                               100.0 * static_cast<double>(p.done) /
                                   static_cast<double>(std::max<std::int64_t>(p.total, 1)),
                               p.items_per_s, duration_text(p.seconds_left))
                << std::flush;
    };
  }
  g_interrupted.store(false);
  auto previous_int = std::signal(SIGINT, on_interrupt);
  auto previous_term = std::signal(SIGTERM, on_interrupt);
  commands::AtlasRun run;
  try {
    run = commands::run_atlas(job, identity, run_options);
  } catch (...) {
    std::signal(SIGINT, previous_int);
    std::signal(SIGTERM, previous_term);
    throw;
  }
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  if (run_options.progress)
    std::cerr << '\n';
  if (run.interrupted) {
    std::cerr << fmt::format(
        "robomill: interrupted: {} of {} items are in {}; run the same command to resume\n",
        run.done, run.total, job.atlas->store.string());
    return 130;
  }
  if (!options.job.quiet) {
    std::cout << fmt::format(
        "atlas: {} items computed in {:.2f} s on {} threads ({:.1f} items/s); {} were already "
        "in the store; {} of {} done → {}\n",
        run.computed, run.elapsed_s, run.threads,
        run.elapsed_s > 0.0 ? static_cast<double>(run.computed) / run.elapsed_s : 0.0, run.already,
        run.done, run.total, job.atlas->store.string());
  }
  return 0;
}

}  // namespace robomill::app
