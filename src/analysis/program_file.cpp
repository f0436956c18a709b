// The job's program from disk: size guard, dialect dispatch, the KRL .dat,
// and the program frame placed in the workpiece frame.

#include <fmt/format.h>

#include <fstream>
#include <sstream>
#include <system_error>

#include "robomill/analysis/program_file.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"

namespace robomill::analysis {
namespace {

// The whole file, refused before reading when larger than `max_bytes` (a
// 100 MB file is far beyond a real program; the guard keeps memory bounded).
std::string read_capped_text(const std::filesystem::path& file, std::size_t max_bytes,
                             const std::string& field, int line) {
  std::error_code error;
  const auto size = std::filesystem::file_size(file, error);
  if (error || !std::filesystem::is_regular_file(file, error))
    throw InputError(field, line, fmt::format("cannot read '{}': no such file", file.string()));
  if (size > max_bytes)
    throw InputError(field, line,
                     fmt::format("'{}' is {:.1f} MiB, more than toolpath.max_size ({:.1f} MiB); "
                                 "split the program or raise max_size",
                                 file.string(), static_cast<double>(size) / (1 << 20),
                                 static_cast<double>(max_bytes) / (1 << 20)));
  std::ifstream stream(file, std::ios::binary);
  std::ostringstream text;
  text << stream.rdbuf();
  if (!stream && !stream.eof())
    throw InputError(field, line, fmt::format("cannot read '{}'", file.string()));
  return std::move(text).str();
}

}  // namespace

toolpath::Program read_program(const job::ToolpathSettings& settings) {
  const std::string text =
      read_capped_text(settings.file, settings.max_bytes, "toolpath.file", settings.file_line);
  const std::string name = settings.file.filename().string();
  toolpath::Program program;
  switch (settings.format) {
    case job::ToolpathSettings::Format::gcode: {
      io::GcodeOptions options;
      options.source_name = name;
      options.max_bytes = settings.max_bytes;
      options.work_offsets_m = settings.work_offsets_m;
      program = io::read_gcode(text, options);
      break;
    }
    case job::ToolpathSettings::Format::apt: {
      io::AptOptions options;
      options.source_name = name;
      options.max_bytes = settings.max_bytes;
      if (settings.units != job::ToolpathSettings::Units::unset)
        options.units = settings.units == job::ToolpathSettings::Units::inch
                            ? io::AptOptions::Unit::inch
                            : io::AptOptions::Unit::mm;
      program = io::read_apt(text, options);
      break;
    }
    case job::ToolpathSettings::Format::krl: {
      io::KrlOptions options;
      options.source_name = name;
      options.max_bytes = settings.max_bytes;
      options.bases = settings.bases;
      options.tool_direction = settings.tool_direction;
      std::error_code error;
      std::filesystem::path dat = settings.dat_file;
      if (!std::filesystem::exists(dat, error)) {
        // KRL files travel between Windows controllers and PCs: try .DAT too.
        std::filesystem::path upper = dat;
        upper.replace_extension(".DAT");
        if (std::filesystem::exists(upper, error))
          dat = upper;
      }
      if (std::filesystem::exists(dat, error)) {
        options.dat_text = read_capped_text(dat, settings.max_bytes, "toolpath.dat", settings.line);
        options.dat_name = dat.filename().string();
      }
      program = io::read_krl(text, options);
      if (options.dat_text.empty())
        program.notes.push_back(
            {0, fmt::format("no data file '{}': positions must be written inline",
                            settings.dat_file.filename().string())});
      break;
    }
  }
  toolpath::apply_transform(program, settings.program_to_workpiece);
  return program;
}

}  // namespace robomill::analysis
