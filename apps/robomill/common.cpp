#include <fmt/format.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>

#include "commands.hpp"
#include "robomill/io/output_bundle.hpp"
#include "robomill/io/summary.hpp"
#include "robomill/report/key_inputs.hpp"
#include "robomill/report/report.hpp"

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

const io::CsvTable* CommandResult::table(const std::string& name) const {
  for (const auto& [table_name, table] : tables) {
    if (table_name == name)
      return &table;
  }
  return nullptr;
}

void add_key_inputs(CommandResult& result, const io::Job& job) {
  result.documents.emplace_back("inputs", nlohmann::json::parse(report::key_inputs_json(job)));
}

void write_result(const std::filesystem::path& out, const io::OutputSettings& output,
                  const CommandResult& result, bool report) {
  io::OutputBundle bundle(out);
  if (output.csv) {
    for (const auto& [name, table] : result.tables)
      bundle.add(name + ".csv", table.to_string());
  }
  for (const auto& [name, text] : result.texts)
    bundle.add(name, text);
  for (const auto& [name, temporary] : result.streamed) {
    if (output.csv) {
      bundle.adopt(name, temporary);
    } else {
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
    }
  }
  if (output.json) {
    for (const auto& [name, document] : result.documents)
      bundle.add(name + ".json", io::summary_text(document));
    if (!result.summary.is_null())
      bundle.add("summary.json", io::summary_text(result.summary));
  }
  // report.html from the staged files (the same function as `robomill
  // report OUTDIR` on disk), in the same atomic commit. A report that cannot
  // be rendered is a warning: the results are never lost for it.
  if (report && output.html && !result.summary.is_null()) {
    report::Files files;
    files["summary.json"] = io::summary_text(result.summary);
    for (const auto& [name, content] : bundle.staged())
      files[name] = content;
    try {
      bundle.add("report.html", report::render_html(files));
    } catch (const std::exception& error) {
      std::cerr << "robomill: warning: report.html not written: " << error.what() << '\n';
    }
  }
  bundle.commit();
}

int run_job_command(const JobCommandOptions& options, const std::string& command,
                    const std::function<CommandResult(const io::Job&)>& compute) {
  const io::Job job = load(options);
  CommandResult result = compute(job);
  const std::filesystem::path out = output_dir(options, job, command);
  add_key_inputs(result, job);
  write_result(out, job.output, result, !options.quiet);
  if (!options.quiet)
    std::cout << result.message << "  written to " << out.string() << '\n';
  return 0;
}

std::vector<std::string> job_sections(const io::Job& job) {
  std::vector<std::string> sections;
  auto add = [&](bool present, const char* name) {
    if (present)
      sections.emplace_back(name);
  };
  add(job.tool.has_value(), "tool");
  add(job.cutting.has_value(), "cutting");
  add(job.process.has_value(), "process");
  add(!job.modes.empty() || !job.frf_files.empty(), "dynamics");
  add(job.stability.has_value(), "stability");
  add(job.robot.has_value(), "robot");
  add(!job.experiments.empty(), "experiments");
  add(job.deflection.has_value(), "deflection");
  add(job.simulation.has_value(), "simulation");
  add(job.surface.has_value(), "surface");
  add(job.workpiece.has_value(), "workpiece");
  add(!job.path.empty(), "path");
  add(job.optimize.has_value(), "optimize");
  add(job.advise.has_value(), "advise");
  add(job.atlas.has_value(), "atlas");
  add(job.toolpath.has_value(), "toolpath");
  add(job.stock.has_value(), "stock");
  add(job.robot_path.has_value(), "robot_path");
  add(!job.recordings.empty() && !job.recordings_listed, "recording");
  add(job.recordings_listed, "recordings");
  add(job.listen.has_value(), "listen");
  return sections;
}

int run_validate(const JobCommandOptions& options) {
  const io::Job job = load(options);
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
      const io::PostureLibrary& library = *job.posture_library;
      std::cout << fmt::format("  dynamics.postures: {} measured postures interpolated at {}",
                               library.postures_rad.size(), library.query_source);
      if (library.exact_index >= 0)
        std::cout << fmt::format(" (= posture {})", library.exact_index + 1);
      std::cout << ":\n";
      for (const io::ModeSpec& mode : job.modes) {
        std::cout << fmt::format("    {}: fn {:.4g} Hz, zeta {:.3g} %, k {:.4g} N/m\n",
                                 mode.direction, mode.natural_frequency_hz,
                                 100.0 * mode.damping_ratio, mode.stiffness_n_per_m);
      }
    }
  }
  return 0;
}

}  // namespace robomill::app
