#include <fmt/format.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>

#include <memory>

#include "commands.hpp"

namespace robomill::app {

ProgressBar::ProgressBar(bool enabled, std::string label)
    : enabled_(enabled && ::isatty(2)), label_(std::move(label)) {}

void ProgressBar::operator()(double fraction) {
  if (!enabled_)
    return;
  const int percent = static_cast<int>(std::lround(100.0 * std::clamp(fraction, 0.0, 1.0)));
  if (percent == last_)
    return;
  last_ = percent;
  const int filled = percent * 40 / 100;
  std::cerr << fmt::format("\r{} [{:<40}] {:3d}%", label_, std::string(filled, '#'), percent)
            << std::flush;
  if (percent >= 100)
    std::cerr << '\n';
}

commands::Progress progress_bars(bool enabled) {
  if (!enabled)
    return {};
  // One bar per stage: a new stage (the next recording) starts a new line.
  auto bar = std::make_shared<std::unique_ptr<ProgressBar>>();
  auto stage = std::make_shared<std::string>();
  return [bar, stage](const std::string& name, double fraction) {
    if (!*bar || name != *stage) {
      *stage = name;
      *bar = std::make_unique<ProgressBar>(true, name);
    }
    (**bar)(fraction);
  };
}

job::Job load(const JobCommandOptions& options) {
  std::vector<job::Override> overrides;
  overrides.reserve(options.overrides.size());
  for (const std::string& assignment : options.overrides) {
    overrides.push_back(job::parse_override(assignment));
  }
  return job::load_job(options.job_file, overrides);
}

std::filesystem::path output_dir(const JobCommandOptions& options, const job::Job& job,
                                 const std::string& command) {
  if (!options.out_dir.empty())
    return options.out_dir;
  if (!job.output.dir.empty())
    return job.resolve(job.output.dir);
  return std::filesystem::path("out") / command;
}

atlas::StoreIdentity atlas_store_identity(const JobCommandOptions& options, int dof) {
  return commands::atlas_store_identity(options.job_file, options.overrides, dof);
}

int run_job_command(const JobCommandOptions& options, const std::string& command,
                    const std::function<CommandResult(const job::Job&)>& compute) {
  const job::Job job = load(options);
  CommandResult result = compute(job);
  const std::filesystem::path out = output_dir(options, job, command);
  add_key_inputs(result, job);
  write_result(out, job.output, result, !options.quiet);
  if (!options.quiet)
    std::cout << result.message << "  written to " << out.string() << '\n';
  return 0;
}

int run_validate(const JobCommandOptions& options) {
  const job::Job job = load(options);
  if (!options.quiet) {
    std::cout << options.job_file.string() << ": valid";
    std::string sections;
    for (const std::string& name : job_sections(job))
      sections += sections.empty() ? name : ", " + name;
    if (!sections.empty())
      std::cout << " (" << sections << ")";
    std::cout << '\n';
    if (job.posture_library) {
      // What 001 Eq 16-18 made of the library at the job's posture.
      const job::PostureLibrary& library = *job.posture_library;
      std::cout << fmt::format("  dynamics.postures: {} measured postures interpolated at {}",
                               library.postures_rad.size(), library.query_source);
      if (library.exact_index >= 0)
        std::cout << fmt::format(" (= posture {})", library.exact_index + 1);
      std::cout << ":\n";
      for (const job::ModeSpec& mode : job.modes) {
        std::cout << fmt::format("    {}: fn {:.4g} Hz, zeta {:.3g} %, k {:.4g} N/m\n",
                                 mode.direction, mode.natural_frequency_hz,
                                 100.0 * mode.damping_ratio, mode.stiffness_n_per_m);
      }
    }
  }
  return 0;
}

}  // namespace robomill::app
