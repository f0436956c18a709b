// The job commands' runs: load the job, call the library's computation
// (robomill/commands/commands.hpp), write the result in one commit and print
// its message.

#include <fmt/format.h>

#include <iostream>
#include <system_error>

#include "commands.hpp"
#include "robomill/analysis/program_run.hpp"
#include "robomill/io/output_bundle.hpp"

namespace robomill::app {

int run_advise(const JobCommandOptions& options) {
  const job::Job job = load(options);
  CommandResult result = commands::compute_advise(job, options.threads);
  const std::filesystem::path out = output_dir(options, job, "advise");
  add_key_inputs(result, job);
  write_result(out, job.output, result, !options.quiet);
  if (!options.quiet)
    std::cout << result.message
              << fmt::format("  {:.2f} s; written to {}\n",
                             result.summary["elapsed_s"].get<double>(), out.string());
  return 0;
}

int run_deflection(const JobCommandOptions& options) {
  return run_job_command(options, "deflection", [&](const job::Job& job) {
    return commands::compute_deflection(job, options.threads);
  });
}

int run_fit_modes(const JobCommandOptions& options) {
  return run_job_command(options, "fit-modes",
                         [&](const job::Job& job) { return commands::compute_fit_modes(job); });
}

int run_forces(const JobCommandOptions& options) {
  return run_job_command(options, "forces", [&](const job::Job& job) {
    return commands::compute_forces(job, options.threads);
  });
}

int run_frf(const FrfCommandOptions& options) {
  return run_job_command(options.job, "frf",
                         [&](const job::Job& job) { return commands::compute_frf(job, options); });
}

int run_identify_cutting(const IdentifyOptions& options) {
  const CommandResult result = commands::compute_identify_cutting(options);
  const std::filesystem::path out =
      options.out_dir.empty() ? std::filesystem::path("out/identify-cutting") : options.out_dir;
  write_result(out, job::OutputSettings{}, result, !options.quiet);
  if (!options.quiet)
    std::cout << result.message << "  written to " << out.string() << '\n';
  return 0;
}

int run_identify_stiffness(const IdentifyStiffnessOptions& options) {
  const job::Job job = load(options.job);
  CommandResult result = commands::compute_identify_stiffness(job, options);
  add_key_inputs(result, job);
  const std::filesystem::path out = output_dir(options.job, job, "identify-stiffness");
  // Written whatever the job's output: section says (the files are the result).
  write_result(out, job::OutputSettings{}, result, !options.job.quiet);
  if (!options.job.quiet) {
    if (options.synthesize)
      std::cout << result.message << " → " << (out / "loading_tests.csv").string() << '\n';
    else
      std::cout << result.message << "  written to " << out.string() << '\n';
  }
  return 0;
}

int run_listen(const JobCommandOptions& options) {
  return run_job_command(options, "listen", [&](const job::Job& job) {
    return commands::compute_listen(job, options.threads, progress_bars(!options.quiet));
  });
}

int run_learn(const JobCommandOptions& options) {
  return run_job_command(options, "learn", [&](const job::Job& job) {
    return commands::compute_learn(job, options.threads);
  });
}

int run_optimize(const JobCommandOptions& options) {
  return run_job_command(options, "optimize", [&](const job::Job& job) {
    return commands::compute_optimize(job, options.threads);
  });
}

int run_robot(const JobCommandOptions& options) {
  return run_job_command(options, "robot", [&](const job::Job& job) {
    return commands::compute_robot(job, options.threads);
  });
}

int run_simulate(const JobCommandOptions& options) {
  return run_job_command(options, "simulate",
                         [&](const job::Job& job) { return commands::compute_simulate(job); });
}

int run_stability(const JobCommandOptions& options) {
  return run_job_command(options, "stability", [&](const job::Job& job) {
    return commands::compute_stability(job, options.threads);
  });
}

int run_surface(const JobCommandOptions& options) {
  return run_job_command(options, "surface", [&](const job::Job& job) {
    return commands::compute_surface(job, options.threads);
  });
}

int run_toolpath(const JobCommandOptions& options, const analysis::BlockSharing* sharing) {
  const job::Job job = load(options);
  const std::filesystem::path out = output_dir(options, job, "toolpath");
  // samples.csv streams into the output folder while the program runs; a run
  // that fails leaves neither it nor a folder it had to create.
  std::error_code ignored;
  const bool out_existed = std::filesystem::exists(out, ignored);
  io::OutputBundle staging(out);
  const std::filesystem::path samples_file = staging.temporary_for("samples.csv");
  CommandResult result;
  try {
    result = commands::compute_toolpath(job, options.threads, samples_file,
                                        progress_bars(!options.quiet), options.optimize, sharing);
  } catch (...) {
    std::filesystem::remove(samples_file, ignored);
    if (!out_existed)
      std::filesystem::remove(out, ignored);  // only if empty
    throw;
  }
  if (sharing && sharing->processes > 1)
    result.message +=
        fmt::format("  the robot's blocks shared over {} MPI ranks\n", sharing->processes);
  add_key_inputs(result, job);
  write_result(out, job.output, result, !options.quiet);
  if (!options.quiet)
    std::cout << result.message << "  written to " << out.string() << '\n';
  return 0;
}

}  // namespace robomill::app
