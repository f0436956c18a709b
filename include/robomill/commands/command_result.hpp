#pragma once
// What one job command produces (DESIGN.md §4's output files), before
// anything is written: its CSV tables, JSON documents, other texts and
// summary.json. The commands (robomill/commands/commands.hpp) fill it from
// their typed results; the command line and the Python module write it with
// write_result, in one atomic commit.

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "robomill/io/csv.hpp"
#include "robomill/job/job.hpp"

namespace robomill::commands {

/// Everything one command produces, before anything is written.
struct CommandResult {
  /// CSV tables in the order they are written, by file name without ".csv"
  /// ("sld", "sld_envelope"); written when the job's output.csv is on.
  std::vector<std::pair<std::string, io::CsvTable>> tables;
  /// Further JSON documents by file name without ".json" ("advice");
  /// written when output.json is on.
  std::vector<std::pair<std::string, nlohmann::json>> documents;
  /// Other files by full name ("modes.yaml", "frf.uff"); always written.
  std::vector<std::pair<std::string, std::string>> texts;
  /// Files the computation already streamed to a hidden temporary in the
  /// output folder (`samples.csv` of a whole program), by final name; renamed
  /// into place with the rest when output.csv is on, removed otherwise.
  std::vector<std::pair<std::string, std::filesystem::path>> streamed;
  /// summary.json; written when output.json is on.
  nlohmann::json summary;
  /// What the command prints (unless --quiet) before its "written to" line.
  std::string message;

  const io::CsvTable* table(const std::string& name) const;
};

/// Progress of a long computation: what is running ("toolpath", "listen
/// 2/3") and the fraction of it done, in [0, 1]. Called from the thread
/// that started the computation.
using Progress = std::function<void(const std::string& stage, double fraction)>;

/// Stages every file of a result in one io::OutputBundle under `out` and
/// commits it (all files or none). With `report` and the job's
/// output.formats allowing html, adds report.html rendered from the staged
/// files (report::render_html); a report that cannot be rendered is a
/// warning on stderr, never a lost result. Without a new report, an earlier
/// run's report.html in `out` is removed (it would describe other results).
void write_result(const std::filesystem::path& out, const job::OutputSettings& output,
                  const CommandResult& result, bool report = false);

/// Adds the job's key inputs (report/key_inputs.hpp) to a result as the
/// document "inputs" (inputs.json; the report's inputs table).
void add_key_inputs(CommandResult& result, const job::Job& job);

/// The sections a job has, in `robomill validate`'s order and names.
std::vector<std::string> job_sections(const job::Job& job);

}  // namespace robomill::commands
