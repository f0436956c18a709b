// Job parsing: YAML text → validated Job in SI units (DESIGN.md §3).
//
// This file reads the document and calls one reader per section, each in its
// own file (job_parser_<section>.cpp), reading fields in the order they are
// documented; the SectionReader (typed, strict field access with path + line
// errors) is yaml_reader.cpp, the --set machinery job_overrides.cpp.

#include <fmt/format.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "job_overrides.hpp"
#include "job_parser_atlas.hpp"
#include "job_parser_cutting.hpp"
#include "job_parser_deflection.hpp"
#include "job_parser_dynamics.hpp"
#include "job_parser_learning.hpp"
#include "job_parser_monitoring.hpp"
#include "job_parser_planning.hpp"
#include "job_parser_robot.hpp"
#include "job_parser_simulation.hpp"
#include "job_parser_stability.hpp"
#include "job_parser_surface.hpp"
#include "job_parser_toolpath.hpp"
#include "job_parser_uncertainty.hpp"
#include "quantity_fields.hpp"
#include "robomill/core/error.hpp"
#include "robomill/core/text.hpp"
#include "robomill/job/job.hpp"
#include "robomill/job/job_schema.hpp"
#include "robomill/job/units.hpp"
#include "yaml_reader.hpp"

namespace robomill::job {
namespace {

using detail::Bound;
using detail::Provenance;
using detail::QuantityField;
using detail::SectionReader;
// Units and field builders shared with the section parsers in their own files.
using detail::dimensionless;
using detail::field;
using detail::kDeg;
using detail::kMm;
using detail::kNonNegative;
using detail::kPositive;
using detail::kRpm;
using detail::length_mm;

OutputSettings read_output(SectionReader& root) {
  OutputSettings output;
  auto section = root.section("output");
  if (!section)
    return output;
  SectionReader& r = *section;
  r.allow_schema("output");
  output.dir = r.optional_text("dir").value_or("");
  if (auto formats = r.texts("formats")) {
    output.csv = output.json = output.html = false;
    for (const auto& item : *formats) {
      if (item.text == "csv") {
        output.csv = true;
      } else if (item.text == "json") {
        output.json = true;
      } else if (item.text == "html") {
        output.html = true;
      } else {
        throw InputError(item.path, item.line,
                         "unknown format '" + item.text + "'; expected one of: csv, json, html");
      }
    }
  }
  r.finish();
  return output;
}

// Records where documents start; builds nothing.
class DocumentCounter : public YAML::EventHandler {
 public:
  void OnDocumentStart(const YAML::Mark& mark) override { starts.push_back(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t,
                const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}

  std::vector<YAML::Mark> starts;
};

// A job is one YAML document. YAML::LoadAll is not used to find out: on a
// stray flow indicator (a leading ',') yaml-cpp 0.7 yields empty documents
// forever without consuming input, so LoadAll never returns (found by
// fuzzing). Documents are counted here with a bound instead, and a document
// that starts where the previous one started is that stuck state: reported
// as the syntax error it is.
void check_single_document(const std::string& text, const std::string& source) {
  std::istringstream stream(text);
  YAML::Parser parser(stream);
  DocumentCounter counter;
  while (counter.starts.size() < 2 && parser.HandleNextDocument(counter)) {
  }
  if (counter.starts.size() < 2)
    return;
  const YAML::Mark first = counter.starts[0];
  const YAML::Mark second = counter.starts[1];
  const int line = second.line >= 0 ? second.line + 1 : 0;
  if (second.pos == first.pos) {
    const std::size_t pos = static_cast<std::size_t>(std::max(0, second.pos));
    const std::string found =
        pos < text.size() ? fmt::format("'{}'", text[pos]) : std::string("end of input");
    throw InputError(source, line, "YAML syntax error: unexpected " + found);
  }
  throw InputError(source, line, "a second YAML document starts here; a job is a single document");
}

Job read_job(const YAML::Node& root_node, const std::filesystem::path& source,
             const Provenance& provenance) {
  const int root_line = provenance.line(root_node, "") > 0 ? provenance.line(root_node, "") : 1;
  SectionReader root(root_node, "", root_line, provenance);
  root.allow_schema("job");
  Job job;
  job.source = source;
  job.name = root.optional_text("name").value_or("");
  job.tool = detail::read_tool(root);
  job.cutting = detail::read_cutting(root);
  job.process = detail::read_process(root, job.tool);
  job.forces = detail::read_forces(root, job.tool);
  detail::read_dynamics(root, job);
  if (auto robot = root.section("robot"))
    job.robot = detail::read_robot_section(*robot, source);
  detail::resolve_posture_library(job);
  job.stability = detail::read_stability(root, job.tool, job.modes, job.dynamics_source);
  job.experiments = detail::read_experiments(root, job);  // job_parser_learning.cpp
  detail::read_planning(root, job);    // workpiece, path, optimize (job_parser_planning.cpp)
  detail::read_simulation(root, job);  // simulation (job_parser_simulation.cpp)
  detail::read_deflection(root, job);  // 000 §2-4 (job_parser_deflection.cpp)
  detail::read_atlas(root, job);       // issue 11 (job_parser_atlas.cpp)
  detail::read_surface(root, job);     // 001 §2.4 (job_parser_surface.cpp)
  detail::read_toolpath(root, job);    // program and stock (job_parser_toolpath.cpp)
  detail::read_monitoring(root, job);  // recordings (job_parser_monitoring.cpp)
  detail::read_uncertainty(root, root_node, job);  // issue 33 (job_parser_uncertainty.cpp)
  detail::read_learn(root, job);                   // issue 35 (job_parser_learning.cpp)
  job.output = read_output(root);
  root.finish();
  return job;
}

/// Line `index` (0-based) of `text`, "" when there is none.
std::string_view line_of(std::string_view text, int index) {
  for (int i = 0; i < index && !text.empty(); ++i) {
    const std::size_t end = text.find('\n');
    text = end == std::string_view::npos ? std::string_view() : text.substr(end + 1);
  }
  return text.substr(0, text.find('\n'));
}

}  // namespace

Job parse_job(std::string_view yaml_text, const std::filesystem::path& source_name,
              const std::vector<Override>& overrides) {
  const std::string source = source_name.empty() ? std::string("job") : source_name.string();
  detail::guard_input(yaml_text, source);

  const std::string text(yaml_text);
  YAML::Node root;
  try {
    check_single_document(text, source);
    root = YAML::Load(text);
  } catch (const YAML::ParserException& error) {
    throw InputError(source, error.mark.line >= 0 ? error.mark.line + 1 : 0,
                     "YAML syntax error: " + error.msg +
                         detail::flow_index_hint(line_of(text, error.mark.line)));
  } catch (const YAML::Exception& error) {
    throw InputError(source, error.mark.line >= 0 ? error.mark.line + 1 : 0,
                     "cannot read YAML: " + error.msg);
  }
  if (!root.IsDefined() || root.IsNull()) {
    throw InputError(source, 0,
                     "job is empty; expected sections such as tool:, cutting:, process:");
  }
  if (!root.IsMap()) {
    throw InputError(source, root.Mark().line + 1,
                     "expected a map of sections (tool:, cutting:, process:, ...) at the top "
                     "level, got " +
                         detail::describe_node(root));
  }

  try {
    Provenance provenance;
    for (const Override& override_ : overrides)
      detail::apply_override(root, override_, provenance);
    Job job = read_job(root, source_name, provenance);
    // What rebuilds the job with more overrides (the draws of uncertainty:).
    job.yaml_text = std::make_shared<const std::string>(text);
    job.overrides = overrides;
    detail::check_uncertainty_round_trip(job);
    return job;
  } catch (const YAML::Exception& error) {
    // The reader avoids conversions that throw; this is a safety net so that
    // a yaml-cpp surprise is still reported as bad input, not as a crash.
    throw InputError(source, error.mark.line >= 0 ? error.mark.line + 1 : 0,
                     "cannot read the job: " + error.msg);
  }
}

}  // namespace robomill::job
