// The draws of a job's uncertain inputs and the job of each draw
// (analysis/job_draws.hpp; docs/uncertainty.md, "From a job").

#include "robomill/analysis/job_draws.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "robomill/core/error.hpp"
#include "robomill/core/parallel.hpp"
#include "robomill/core/text.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/job/units.hpp"
#include "robomill/uncertainty/distribution.hpp"
#include "robomill/uncertainty/draws.hpp"

namespace robomill::analysis {
namespace {

using DrawnVariable = job::UncertaintySettings::Variable;
using DrawnTarget = job::UncertaintySettings::Target;

constexpr std::string_view kFromSetNote = " (from --set)";

std::string draws_variable_field(std::size_t j) {
  return fmt::format("uncertainty.variables[{}]", j);
}

std::string draws_names_text(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names)
    out += (out.empty() ? "" : ", ") + name;
  return out;
}

/// A drawn number as the job reads it back exactly: 17 significant digits
/// and the SI unit of the field's dimension (the job parser's SI units have
/// the factor 1; job_parser_uncertainty.cpp checks the round trip).
std::string draw_override_value(double value_si, const job::Dimension& dimension) {
  const std::string number = fmt::format("{:.17g}", value_si);
  return dimension == job::dimensions::none ? number : number + " " + job::si_unit(dimension);
}

/// "-1.23457e+06 N/m" for messages.
std::string drawn_value_text(double value_si, const job::Dimension& dimension) {
  if (!std::isfinite(value_si))
    return "not a finite number";
  const std::string number = fmt::format("{:.6g}", value_si);
  return dimension == job::dimensions::none ? number : number + " " + job::si_unit(dimension);
}

/// The 1-based line of a CSV text's header: its first line that is neither
/// blank nor a '#' comment (io::parse_csv skips those).
int posterior_header_line(const std::string& text) {
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  while (std::getline(lines, line)) {
    ++number;
    const std::string_view content = text::trim(line);
    if (!content.empty() && content.front() != '#')
      return number;
  }
  return 0;
}

/// The posterior file's rows, columns in the variables' order.
Eigen::MatrixXd posterior_values(const job::UncertaintySettings& settings) {
  const std::string field = "uncertainty.posterior";
  const int line = settings.posterior_line;
  const std::string file = settings.posterior.string();
  std::ifstream in(settings.posterior, std::ios::binary);
  if (!in)
    throw InputError(field, line, fmt::format("cannot open the posterior file {}", file));
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  io::CsvTable table({"unread"});
  try {
    table = io::parse_csv(text, file);
  } catch (const InputError& error) {
    throw InputError(field, line, error.what());
  }
  const int header = posterior_header_line(text);
  std::vector<std::string> names;
  for (const DrawnVariable& v : settings.variables)
    names.push_back(v.name);
  std::vector<int> column_of(names.size(), -1);
  const auto& columns = table.columns();
  for (std::size_t c = 0; c < columns.size(); ++c) {
    const auto it = std::find(names.begin(), names.end(), columns[c]);
    if (it == names.end())
      throw InputError(field, line,
                       fmt::format("{} line {}: column '{}' is not a variable of "
                                   "uncertainty.variables ({})",
                                   file, header, columns[c], draws_names_text(names)));
    const std::size_t j = static_cast<std::size_t>(it - names.begin());
    if (column_of[j] >= 0)
      throw InputError(
          field, line,
          fmt::format("{} line {}: column '{}' is given twice", file, header, columns[c]));
    column_of[j] = static_cast<int>(c);
  }
  for (std::size_t j = 0; j < names.size(); ++j) {
    if (column_of[j] < 0)
      throw InputError(field, line,
                       fmt::format("{} line {}: no column for variable '{}' "
                                   "(uncertainty.variables[{}], line {}); the header names "
                                   "every variable",
                                   file, header, names[j], j, settings.variables[j].line));
  }
  if (table.rows() == 0)
    throw InputError(field, line, fmt::format("{}: no draws below the header", file));
  Eigen::MatrixXd values(static_cast<Eigen::Index>(table.rows()),
                         static_cast<Eigen::Index>(names.size()));
  for (std::size_t r = 0; r < table.rows(); ++r) {
    for (std::size_t j = 0; j < names.size(); ++j)
      values(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(j)) =
          table.at(r, static_cast<std::size_t>(column_of[j]));
  }
  return values;
}

/// The variable a refused field belongs to: the index of the variable with a
/// target at `field` (or inside it), or variables.size().
std::size_t drawn_variable_at(const std::vector<DrawnVariable>& variables, const std::string& field,
                              const DrawnTarget** target) {
  for (std::size_t j = 0; j < variables.size(); ++j) {
    for (const DrawnTarget& t : variables[j].targets) {
      if (field == t.path || field.starts_with(t.path + ".") || field.starts_with(t.path + "[")) {
        *target = &t;
        return j;
      }
    }
  }
  return variables.size();
}

/// The InputError of a draw the job refuses, naming the variable (or, for a
/// refusal no single field explains, every variable), the draw, the value and
/// the job's own message.
InputError refused_draw(const job::Job& nominal, const JobDraws& draws, std::size_t i,
                        const InputError& error) {
  const auto& settings = *nominal.uncertainty;
  const auto& variables = settings.variables;
  const DrawnTarget* target = nullptr;
  const std::size_t j = drawn_variable_at(variables, error.field(), &target);
  const Eigen::Index row = static_cast<Eigen::Index>(i);
  if (j == variables.size()) {
    std::string values;
    for (std::size_t k = 0; k < variables.size(); ++k)
      values += fmt::format("{}{} = {:.6g}", k == 0 ? "" : ", ", variables[k].name,
                            draws.values(row, static_cast<Eigen::Index>(k)));
    return InputError(
        "uncertainty", settings.line,
        fmt::format("draw {} ({}) is refused by the job: {}", i, values, error.what()));
  }
  std::string message = error.what();
  for (std::size_t at = message.find(kFromSetNote); at != std::string::npos;
       at = message.find(kFromSetNote))
    message.erase(at, kFromSetNote.size());
  const DrawnVariable& variable = variables[j];
  const double drawn = draws.values(row, static_cast<Eigen::Index>(j));
  const bool scale = variable.mode == job::UncertaintySettings::Mode::scale;
  const double value = scale ? target->nominal_si * drawn : drawn;
  const std::string factor = scale ? fmt::format(" (factor {:.6g})", drawn) : std::string();
  const std::string hint =
      value <= 0.0 ? "; a quantity that must stay positive is drawn from a lognormal, or a "
                     "truncated_normal with min"
                   : "";
  return InputError(
      draws_variable_field(j), variable.line,
      fmt::format("variable '{}', draw {}: {} = {}{} is refused by the job: {}{}", variable.name, i,
                  target->path, drawn_value_text(value, target->dimension), factor, message, hint));
}

void check_draws_match(const job::Job& nominal, const JobDraws& draws, std::size_t i) {
  if (!nominal.uncertainty)
    throw std::invalid_argument("job_of_draw: the job has no uncertainty: section");
  if (!nominal.yaml_text)
    throw std::invalid_argument("job_of_draw: the job was not read from text (no yaml_text)");
  const auto& variables = nominal.uncertainty->variables;
  bool same = draws.names.size() == variables.size() &&
              draws.values.cols() == static_cast<Eigen::Index>(variables.size());
  for (std::size_t j = 0; same && j < variables.size(); ++j)
    same = draws.names[j] == variables[j].name;
  if (!same)
    throw std::invalid_argument("job_of_draw: the draws' variables (" +
                                draws_names_text(draws.names) + ") are not the job's");
  if (i >= static_cast<std::size_t>(draws.values.rows()))
    throw std::invalid_argument(fmt::format("job_of_draw: draw {} of {}", i, draws.values.rows()));
}

}  // namespace

JobDraws draw_job_inputs(const job::Job& job) {
  if (!job.uncertainty)
    throw InputError("uncertainty", 0, "the job has no uncertainty: section (variables to draw)");
  const job::UncertaintySettings& settings = *job.uncertainty;
  JobDraws draws;
  for (const DrawnVariable& v : settings.variables)
    draws.names.push_back(v.name);
  if (!settings.posterior.empty()) {
    draws.values = posterior_values(settings);
    draws.source = settings.posterior.string();
    const auto rows = draws.values.rows();
    if (settings.samples_given && settings.samples < rows) {
      // `samples` of the file's rows, evenly spaced (a sampler's posterior
      // rows are exchangeable: any even subset is a sample of it).
      Eigen::MatrixXd kept(settings.samples, draws.values.cols());
      for (Eigen::Index i = 0; i < settings.samples; ++i)
        kept.row(i) = draws.values.row(i * rows / settings.samples);
      draws.values = std::move(kept);
      draws.source += fmt::format(" ({} of its {} rows)", settings.samples, rows);
    }
    return draws;
  }
  std::vector<uncertainty::Distribution> distributions;
  for (std::size_t j = 0; j < settings.variables.size(); ++j) {
    const DrawnVariable& v = settings.variables[j];
    if (!v.distribution)
      throw InputError(draws_variable_field(j), v.line, "no distribution (and no posterior file)");
    try {
      distributions.push_back(
          std::visit([](const auto& p) { return uncertainty::Distribution(p); }, *v.distribution));
    } catch (const std::invalid_argument& error) {
      throw InputError(draws_variable_field(j) + ".distribution", v.line, error.what());
    }
  }
  uncertainty::DrawSettings draw_settings;
  draw_settings.samples = settings.samples;
  draw_settings.seed = settings.seed;
  draw_settings.sampling = settings.sampling;
  draw_settings.correlation = settings.correlation;
  try {
    draws.values = uncertainty::draw(distributions, draw_settings);
  } catch (const std::invalid_argument& error) {
    throw InputError("uncertainty", settings.line, error.what());
  }
  draws.source =
      settings.sampling == uncertainty::DrawSettings::Sampling::random ? "random" : "sobol";
  return draws;
}

job::Job job_of_draw(const job::Job& nominal, const JobDraws& draws, std::size_t i) {
  check_draws_match(nominal, draws, i);
  const auto& variables = nominal.uncertainty->variables;
  const Eigen::Index row = static_cast<Eigen::Index>(i);
  std::vector<job::Override> overrides = nominal.overrides;
  for (std::size_t j = 0; j < variables.size(); ++j) {
    const DrawnVariable& v = variables[j];
    const double drawn = draws.values(row, static_cast<Eigen::Index>(j));
    const bool scale = v.mode == job::UncertaintySettings::Mode::scale;
    for (const DrawnTarget& t : v.targets) {
      const double value = scale ? t.nominal_si * drawn : drawn;
      if (!std::isfinite(value))
        throw InputError(draws_variable_field(j), v.line,
                         fmt::format("variable '{}', draw {}: {} would be {}", v.name, i, t.path,
                                     drawn_value_text(value, t.dimension)));
      overrides.push_back({t.path, draw_override_value(value, t.dimension)});
    }
  }
  // The drawn job is one point of the uncertain job: without the section.
  overrides.push_back({"uncertainty", "null"});
  try {
    return job::parse_job(*nominal.yaml_text, nominal.source, overrides);
  } catch (const InputError& error) {
    throw refused_draw(nominal, draws, i, error);
  }
}

namespace {

/// "name = value, ..." of draw i, for messages.
std::string draw_values_text(const JobDraws& draws, std::size_t i) {
  std::string text;
  const auto row = static_cast<Eigen::Index>(i);
  for (std::size_t j = 0; j < draws.names.size(); ++j) {
    text += fmt::format("{}{} = {:.6g}", j == 0 ? "" : ", ", draws.names[j],
                        draws.values(row, static_cast<Eigen::Index>(j)));
  }
  return text;
}

/// An InputError's message without the "field (line N): " it starts with.
std::string bare_message(const InputError& error) {
  std::string prefix = error.field();
  if (error.line() > 0)
    prefix += " (line " + std::to_string(error.line()) + ")";
  if (!prefix.empty())
    prefix += ": ";
  const std::string_view text = error.what();
  return std::string(text.starts_with(prefix) ? text.substr(prefix.size()) : text);
}

/// body(i), its errors naming draw i and its values.
void run_named_draw(const JobDraws& draws, std::size_t i,
                    const std::function<void(std::size_t)>& body) {
  const auto count = draws.values.rows();
  try {
    body(i);
  } catch (const InputError& e) {
    throw InputError(e.field(), e.line(),
                     fmt::format("uncertainty draw {} of {} ({}): {}", i + 1, count,
                                 draw_values_text(draws, i), bare_message(e)));
  } catch (const NumericalError& e) {
    throw NumericalError(fmt::format("uncertainty draw {} of {} ({}): {}", i + 1, count,
                                     draw_values_text(draws, i), e.what()));
  }
}

}  // namespace

bool draws_keep_the_cut(const job::Job& job) {
  if (!job.uncertainty)
    return true;
  for (const DrawnVariable& variable : job.uncertainty->variables) {
    for (const DrawnTarget& target : variable.targets) {
      const std::string_view path = target.path;
      if (!path.starts_with("cutting.") && !path.starts_with("dynamics.") &&
          !path.starts_with("robot."))
        return false;
    }
  }
  return true;
}

void require_draws_keep_the_postures(const job::Job& job, std::string_view what) {
  if (!job.uncertainty)
    return;
  const auto keeps = [](std::string_view path) {
    if (path.starts_with("cutting.") || path.starts_with("dynamics.") ||
        path.starts_with("stability.") || path.starts_with("robot.joint_stiffness") ||
        path.starts_with("robot.links") || path == "robot.damping_ratio")
      return true;
    return path.starts_with("robot.joints[") && path.ends_with("].damping");
  };
  const auto& variables = job.uncertainty->variables;
  for (std::size_t k = 0; k < variables.size(); ++k)
    for (const DrawnTarget& target : variables[k].targets)
      if (!keeps(target.path))
        throw InputError(fmt::format("uncertainty.variables[{}].path", k),
                         target.line ? target.line : variables[k].line,
                         fmt::format("{}: variable '{}' sets {}, which moves the robot's "
                                     "postures or the cut; {} draws structure and "
                                     "coefficients only (cutting.*, dynamics.*, stability.*, "
                                     "robot.joint_stiffness, robot.joints[].damping, "
                                     "robot.links, robot.damping_ratio)",
                                     what, variables[k].name, target.path, what));
}

void for_each_draw(const JobDraws& draws, int threads,
                   const std::function<void(std::size_t)>& body) {
  const auto n = static_cast<std::size_t>(draws.values.rows());
  std::vector<std::exception_ptr> failures(n);
  std::atomic<std::size_t> first_failure{n};
  core::parallel_for(n, threads, [&](std::size_t i) {
    if (i > first_failure.load())
      return;
    try {
      run_named_draw(draws, i, body);
    } catch (...) {
      failures[i] = std::current_exception();
      std::size_t seen = first_failure.load();
      while (i < seen && !first_failure.compare_exchange_weak(seen, i)) {
      }
    }
  });
  if (first_failure.load() < n)
    std::rethrow_exception(failures[first_failure.load()]);
}

}  // namespace robomill::analysis
