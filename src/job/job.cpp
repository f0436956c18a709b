// Job helpers that do not touch YAML: file loading, --set syntax, path
// resolution and section requirements. The parser itself is job_parser.cpp.

#include <cmath>
#include <fstream>
#include <iterator>
#include <numbers>
#include <string>
#include <system_error>

#include "job_overrides.hpp"
#include "robomill/core/error.hpp"
#include "robomill/core/text.hpp"
#include "robomill/job/job.hpp"

namespace robomill::job {
namespace {

using text::trim;

// Why `path` is not a key path, "" when it is one (detail::split_key_path:
// process.ae, dynamics.modes[0].fn, dynamics.modes.0.fn).
std::string override_path_problem(std::string_view path) {
  const detail::KeyPath split = detail::split_key_path(path);
  if (!split.error_at)
    return "";
  if (!split.negative_index.empty())
    return "list indices count from 0, got " + split.negative_index;
  return "expected dotted names of letters, digits and '_', such as process.ae, "
         "dynamics.modes.0.fn or dynamics.modes[0].fn";
}

}  // namespace

std::filesystem::path Job::resolve(const std::filesystem::path& relative) const {
  if (relative.is_absolute())
    return relative;
  return source.parent_path() / relative;
}

Override parse_override(std::string_view assignment) {
  const std::size_t equals = assignment.find('=');
  if (equals == std::string_view::npos) {
    throw InputError("--set", 0,
                     "expected key.path=value (e.g. --set process.ae=\"2 mm\"), got '" +
                         std::string(assignment) + "'");
  }
  const std::string_view path = trim(assignment.substr(0, equals));
  const std::string_view value = trim(assignment.substr(equals + 1));
  if (const std::string problem = override_path_problem(path); !problem.empty()) {
    throw InputError("--set", 0, "invalid key path '" + std::string(path) + "'; " + problem);
  }
  if (value.empty()) {
    throw InputError("--set", 0, "missing value after '=' in '" + std::string(assignment) + "'");
  }
  return Override{std::string(path), std::string(value)};
}

Job load_job(const std::filesystem::path& file, const std::vector<Override>& overrides) {
  std::error_code error;
  if (!std::filesystem::exists(file, error)) {
    throw InputError(file.string(), 0, "job file not found");
  }
  if (std::filesystem::is_directory(file, error)) {
    throw InputError(file.string(), 0, "is a directory, not a job file");
  }
  std::ifstream in(file, std::ios::binary);
  if (!in)
    throw InputError(file.string(), 0, "cannot open job file for reading");
  // Read at most one byte more than parse_job accepts, so that pointing the
  // tool at a huge file (or a device) fails fast instead of exhausting memory.
  constexpr std::size_t kLimit = (1u << 20) + 1;
  std::string text;
  char buffer[65536];
  while (text.size() < kLimit && in.read(buffer, sizeof buffer).gcount() > 0) {
    text.append(buffer, static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad())
    throw InputError(file.string(), 0, "error while reading the job file");
  return parse_job(text, file, overrides);
}

void require(const Job& job, std::initializer_list<Section> sections) {
  for (const Section section : sections) {
    switch (section) {
      case Section::tool:
        if (!job.tool)
          throw InputError("tool", 0, "section required by this command is missing");
        break;
      case Section::cutting:
        if (!job.cutting) {
          throw InputError("cutting", 0, "section required by this command is missing");
        }
        break;
      case Section::process:
        if (!job.process) {
          throw InputError("process", 0, "section required by this command is missing");
        }
        break;
      case Section::modes:
        if (job.modes.empty()) {
          throw InputError("dynamics.modes", 0, "section required by this command is missing");
        }
        break;
      case Section::stability:
        if (!job.stability) {
          throw InputError("stability", 0, "section required by this command is missing");
        }
        break;
      case Section::robot:
        if (!job.robot)
          throw InputError("robot", 0, "section required by this command is missing");
        break;
    }
  }
}

dynamics::ModalModel modal_model(const Job& job) {
  if (job.modes.empty())
    throw InputError("dynamics.modes", 0, "no modes in the job");
  std::vector<dynamics::Mode> modes;
  modes.reserve(job.modes.size());
  for (const ModeSpec& spec : job.modes) {
    // Mass-normalized shape e ωn/√k: the mode's modal stiffness k along its
    // unit direction e (001 Eq 19-22 with φφᵀ = e eᵀ/m).
    dynamics::Mode mode;
    mode.natural_frequency_hz = spec.natural_frequency_hz;
    mode.damping_ratio = spec.damping_ratio;
    mode.shape = spec.direction_vector * (2.0 * std::numbers::pi * spec.natural_frequency_hz /
                                          std::sqrt(spec.stiffness_n_per_m));
    modes.push_back(mode);
  }
  return dynamics::ModalModel(std::move(modes));
}

const char* dynamics_source_name(Job::DynamicsSource source) {
  switch (source) {
    case Job::DynamicsSource::table:
      return "table";
    case Job::DynamicsSource::fit:
      return "fit";
    case Job::DynamicsSource::frf:
      return "frf";
    case Job::DynamicsSource::robot:
      return "robot";
    case Job::DynamicsSource::postures:
      return "postures";
  }
  return "table";
}

}  // namespace robomill::job
