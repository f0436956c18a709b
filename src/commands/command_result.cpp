// The command result's writing (robomill/commands/command_result.hpp).

#include "robomill/commands/command_result.hpp"

#include <iostream>

#include "robomill/io/output_bundle.hpp"
#include "robomill/io/summary.hpp"
#include "robomill/report/key_inputs.hpp"
#include "robomill/report/report.hpp"

namespace robomill::commands {

const io::CsvTable* CommandResult::table(const std::string& name) const {
  for (const auto& [table_name, table] : tables) {
    if (table_name == name)
      return &table;
  }
  return nullptr;
}

void add_key_inputs(CommandResult& result, const job::Job& job) {
  result.documents.emplace_back("inputs", nlohmann::json::parse(report::key_inputs_json(job)));
}

void write_result(const std::filesystem::path& out, const job::OutputSettings& output,
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
  bool reported = false;
  if (report && output.html && !result.summary.is_null()) {
    report::Files files;
    files["summary.json"] = io::summary_text(result.summary);
    for (const auto& [name, content] : bundle.staged())
      files[name] = content;
    try {
      bundle.add("report.html", report::render_html(files));
      reported = true;
    } catch (const std::exception& error) {
      std::cerr << "robomill: warning: report.html not written: " << error.what() << '\n';
    }
  }
  bundle.commit();
  // An earlier run's report.html would describe results that are no longer
  // there (a --quiet run, html now off, a report that failed to render).
  if (!reported) {
    std::error_code ignored;
    std::filesystem::remove(out / "report.html", ignored);
  }
}

std::vector<std::string> job_sections(const job::Job& job) {
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

}  // namespace robomill::commands
