// `robomill report OUTDIR`: rebuilds report.html from the files a command
// wrote (summary.json names the command). Every command's own report comes
// from write_result (common.cpp), with the same renderer.

#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/output_bundle.hpp"
#include "robomill/report/report.hpp"

namespace robomill::app {

int run_report(const ReportOptions& options) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::is_directory(options.dir, error))
    throw InputError(options.dir.string(), 0,
                     "is not a folder (expected a command's --out folder)");
  if (!fs::is_regular_file(options.dir / "summary.json", error))
    throw InputError(options.dir.string(), 0,
                     "has no summary.json: not the output folder of a robomill command");
  report::Files files;
  for (const fs::directory_entry& entry : fs::directory_iterator(options.dir)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file() || name.empty() || name.front() == '.' || name == "report.html")
      continue;
    // A whole program's samples.csv can be hundreds of MB; its page is drawn
    // from samples_preview.csv, as when the command wrote it.
    if (name == "samples.csv" && fs::is_regular_file(options.dir / "samples_preview.csv", error))
      continue;
    std::ifstream stream(entry.path(), std::ios::binary);
    std::ostringstream content;
    content << stream.rdbuf();
    if (!stream)
      throw Error("cannot read " + entry.path().string());
    files[name] = content.str();
  }
  const fs::path target = options.dir / "report.html";
  io::write_file_atomically(target, report::render_html(files));
  if (!options.quiet)
    std::cout << fmt::format("report → {}\n", target.string());
  return 0;
}

}  // namespace robomill::app
