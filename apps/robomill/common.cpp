#include <iostream>

#include "commands.hpp"

namespace robomill::app {

io::Job load(const JobCommandOptions& options) {
  std::vector<io::Override> overrides;
  overrides.reserve(options.overrides.size());
  for (const std::string& assignment : options.overrides) {
    overrides.push_back(io::parse_override(assignment));
  }
  return io::load_job(options.job_file, overrides);
}

std::filesystem::path output_dir(const JobCommandOptions& options, const io::Job& job,
                                 const std::string& command) {
  if (!options.out_dir.empty())
    return options.out_dir;
  if (!job.output.dir.empty())
    return job.resolve(job.output.dir);
  return std::filesystem::path("out") / command;
}

int run_validate(const JobCommandOptions& options) {
  const io::Job job = load(options);
  if (!options.quiet) {
    std::cout << options.job_file.string() << ": valid";
    std::string sections;
    auto add = [&](bool present, const char* name) {
      if (present)
        sections += sections.empty() ? name : std::string(", ") + name;
    };
    add(job.tool.has_value(), "tool");
    add(job.cutting.has_value(), "cutting");
    add(job.process.has_value(), "process");
    add(!job.modes.empty() || !job.frf_files.empty(), "dynamics");
    add(job.stability.has_value(), "stability");
    add(job.robot.has_value(), "robot");
    add(!job.experiments.empty(), "experiments");
    if (!sections.empty())
      std::cout << " (" << sections << ")";
    std::cout << '\n';
  }
  return 0;
}

}  // namespace robomill::app
