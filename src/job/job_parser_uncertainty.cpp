// The `uncertainty:` section of a job (docs/uncertainty.md, "From a job"):
// variables, each setting one or several job fields (`path`, in --set syntax
// with list indices) to a drawn value or by a common drawn factor, the
// distribution each is drawn from with its parameters read in the field's
// own units (bare numbers in the unit the field reads them in) and converted
// to SI here; the number of draws, the seed, the point set, the correlation
// by names and a posterior file that replaces the drawing.
//
// Every path is resolved against the job: it must hold a number that the job
// schema lists as a quantity (its unit gives the dimension and the unit of
// bare numbers), and that number is the nominal value the defaults (mean,
// median) and the scale factors refer to. check_uncertainty_round_trip then
// reads the job once more with every such field written back in SI, as the
// draws will be, so a path the job does not read as that number is refused
// here rather than at the first draw.

#include "job_parser_uncertainty.hpp"

#include <fmt/format.h>

#include <Eigen/Core>
#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "job_overrides.hpp"
#include "quantity_fields.hpp"
#include "robomill/core/error.hpp"
#include "robomill/core/text.hpp"
#include "robomill/job/job_schema.hpp"
#include "robomill/job/units.hpp"
#include "robomill/uncertainty/distribution.hpp"
#include "robomill/uncertainty/draws.hpp"

namespace robomill::job::detail {
namespace {

using UncertainMode = UncertaintySettings::Mode;
using UncertainTarget = UncertaintySettings::Target;
using UncertainVariable = UncertaintySettings::Variable;

constexpr int kMaxUncertaintySamples = 10'000'000;
/// Nominal values of one value-mode variable's fields count as equal within this.
constexpr double kSameNominal = 1e-12;

/// How a field a variable sets reads bare numbers (from the job schema).
struct UncertainFieldUnit {
  Dimension dimension;
  std::string_view unit;  ///< the schema's unit of bare numbers ("mm"), "" when none
  double unit_si = 1.0;   ///< the SI value of one `unit`
};

/// One path as written, and where (for errors).
struct UncertainPathItem {
  std::string text;
  std::string field;  ///< uncertainty.variables[0].path, or ...path[1] in a list
  int line = 0;
};

/// A target with the unit its field reads bare numbers in.
struct ResolvedTarget {
  UncertainTarget target;
  UncertainFieldUnit unit;
};

/// How a variable's parameters are read, and the default mean or median.
struct ParameterScale {
  QuantityField field;            ///< the field's dimension and unit; dimensionless for scale
  std::optional<double> nominal;  ///< the default mean or median (SI, or 1 for scale)
  std::string no_nominal;         ///< why there is none (the fields' values differ)
};

/// "8.1e+06 N/m": an SI value for messages.
std::string si_text(double value_si, const Dimension& dimension) {
  const std::string number = fmt::format("{:.6g}", value_si);
  return dimension == dimensions::none ? number : number + " " + si_unit(dimension);
}

/// A number as analysis::job_of_draw writes it into the job: 17 significant
/// digits and the SI unit of its dimension, which parse_quantity reads back
/// exactly (SI units have the factor 1).
std::string si_override_value(double value_si, const Dimension& dimension) {
  const std::string number = fmt::format("{:.17g}", value_si);
  return dimension == dimensions::none ? number : number + " " + si_unit(dimension);
}

std::string joined(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& word : words)
    out += (out.empty() ? "" : ", ") + word;
  return out;
}

// "dynamics.postures[1].modes[0].k" → "dynamics.postures[].modes[].k".
std::string without_indices(std::string_view path) {
  std::string pattern;
  for (std::size_t i = 0; i < path.size(); ++i) {
    pattern += path[i];
    if (path[i] == '[') {
      while (i + 1 < path.size() && path[i + 1] != ']')
        ++i;
    }
  }
  return pattern;
}

// The schema section a part of the job is read with where the two names
// differ: the modes of a posture library are read as dynamics.modes[], the
// cutters of toolpath.tools as tool.
std::string schema_section_of(const std::string& section) {
  constexpr std::string_view kPostureModes = "dynamics.postures[].modes[]";
  if (section.starts_with(kPostureModes))
    return "dynamics.modes[]" + section.substr(kPostureModes.size());
  constexpr std::string_view kTools = "toolpath.tools.";
  if (section.starts_with(kTools)) {
    const std::size_t dot = section.find('.', kTools.size());
    return "tool" + (dot == std::string::npos ? std::string() : section.substr(dot));
  }
  return section;
}

/// The schema field at a bracket-form job path (nullptr when the schema has
/// none); `element`: the path ends with an index, an item of a list field.
const schema::Field* schema_field_at(const std::string& path, bool& element) {
  std::string pattern = without_indices(path);
  element = pattern.ends_with("[]");
  if (element)
    pattern.resize(pattern.size() - 2);
  const std::size_t dot = pattern.rfind('.');
  const std::string section =
      dot == std::string::npos ? std::string("job") : schema_section_of(pattern.substr(0, dot));
  const std::string key = dot == std::string::npos ? pattern : pattern.substr(dot + 1);
  for (const schema::Field& f : schema::fields()) {
    std::string_view id = f.section;
    if (const auto variant = id.find("[law="); variant != std::string_view::npos)
      id = id.substr(0, variant);  // cutting[law=linear] → cutting
    if (id == section && f.key == key)
      return &f;
  }
  return nullptr;
}

/// Why a field of this kind is no number a variable can set; "" when it is one.
std::string not_a_number(const schema::Field& f, bool element) {
  using schema::Kind;
  if (element ? f.kind == Kind::quantities
              : (f.kind == Kind::quantity || f.kind == Kind::quantities || f.kind == Kind::variant))
    return "";
  switch (f.kind) {
    case Kind::integer:
    case Kind::integers:
      return "a whole number (a count), which is not drawn";
    case Kind::boolean:
      return "true or false";
    case Kind::choice:
    case Kind::choices:
      return "a word (" + std::string(f.values) + ")";
    case Kind::text:
      return "text";
    default:
      return "not a number";
  }
}

/// The job's value of a field from its YAML scalar, read as the parser reads
/// the field (a bare number in the schema's unit); "" or why not in `problem`.
double nominal_value(const std::string& text, const UncertainFieldUnit& unit,
                     std::string& problem) {
  Quantity quantity;
  try {
    quantity = parse_quantity(text);
  } catch (const std::invalid_argument& error) {
    problem = fmt::format("holds '{}', not a number ({})", text, error.what());
    return 0.0;
  }
  if (unit_part(text).empty())
    return quantity.value_si * unit.unit_si;
  if (!(quantity.dimension == unit.dimension)) {
    problem = fmt::format("holds '{}', which is not a {}", text, dimension_name(unit.dimension));
    return 0.0;
  }
  return quantity.value_si;
}

/// The target at a scalar node, after checking that the schema lists the
/// field as a number.
ResolvedTarget scalar_target(const UncertainPathItem& item, const std::string& path,
                             const YAML::Node& node) {
  const auto refuse = [&](const std::string& message) {
    throw InputError(item.field, item.line, message);
  };
  bool element = false;
  const schema::Field* f = schema_field_at(path, element);
  if (f == nullptr)
    refuse(fmt::format("{} is not a field of the job schema (docs/job-reference.md)", path));
  if (const std::string why = not_a_number(*f, element); !why.empty())
    refuse(fmt::format("{} is {}; a variable sets a number field (a quantity)", path, why));
  ResolvedTarget resolved;
  const Quantity unit = parse_unit(f->unit);
  resolved.unit = {unit.dimension, f->unit, unit.value_si};
  std::string problem;
  resolved.target.nominal_si = nominal_value(node.Scalar(), resolved.unit, problem);
  if (!problem.empty())
    refuse(path + " " + problem + "; a variable sets a number field");
  resolved.target.path = path;
  resolved.target.dimension = unit.dimension;
  resolved.target.line = item.line;
  return resolved;
}

/// Resolves one written path against the job: one target, or one per entry
/// of a list of quantities under mode scale.
void resolve_path(const UncertainPathItem& item, const YAML::Node& tree, UncertainMode mode,
                  std::vector<ResolvedTarget>& out) {
  const auto refuse = [&](const std::string& message) {
    throw InputError(item.field, item.line, message);
  };
  if (item.text == "uncertainty" || item.text.starts_with("uncertainty.") ||
      item.text.starts_with("uncertainty["))
    refuse("a variable cannot set the uncertainty: section itself");
  const FoundNode found = find_node(tree, item.text);
  if (!found.node)
    refuse(fmt::format("'{}' is not a field of this job: {}", item.text, found.problem));
  const YAML::Node& node = *found.node;
  bool element = false;
  const schema::Field* f = schema_field_at(found.path, element);
  if (node.IsSequence() && f != nullptr && !element && f->kind == schema::Kind::quantities) {
    if (mode != UncertainMode::scale)
      refuse(
          fmt::format("{} is a list of {} values; give one entry ({}[0]) or use mode: scale, "
                      "whose factor multiplies every entry",
                      found.path, node.size(), found.path));
    std::size_t k = 0;
    for (auto it = node.begin(); it != node.end(); ++it, ++k) {
      const YAML::Node entry = *it;
      if (!entry.IsScalar())
        refuse(fmt::format("{}[{}] is {}, not a number", found.path, k, describe_node(entry)));
      out.push_back(scalar_target(item, found.path + "[" + std::to_string(k) + "]", entry));
    }
    return;
  }
  if (!node.IsScalar())
    refuse(fmt::format("{} is {}, not a number", found.path, describe_node(node)));
  out.push_back(scalar_target(item, found.path, node));
}

/// The `path` of a variable: one text or a list of them.
std::vector<UncertainPathItem> path_items(SectionReader& r) {
  std::vector<UncertainPathItem> items;
  if (r.is_list("path")) {
    // Held here: a range-for over `*r.texts(...)` would iterate a vector
    // inside a temporary optional that is gone before the loop starts.
    const auto texts = r.texts("path");
    for (const SectionReader::Item& item : *texts)
      items.push_back({item.text, item.path, item.line});
    if (items.empty())
      r.fail("path", "an empty list; give the job field(s) the variable sets");
  } else if (const auto written = r.optional_text("path")) {
    items.push_back({std::string(text::trim(*written)), r.path_of("path"), r.line_of("path")});
  } else {
    r.fail("path",
           "required: the job field the variable sets, in --set syntax "
           "(dynamics.modes[0].k), or a list of them");
  }
  return items;
}

/// The parameters' units and the default mean or median of a variable.
ParameterScale parameter_scale(SectionReader& r, const std::vector<ResolvedTarget>& targets,
                               UncertainMode mode) {
  ParameterScale scale;
  if (mode == UncertainMode::scale) {
    scale.field = dimensionless();
    scale.nominal = 1.0;
    return scale;
  }
  const ResolvedTarget& first = targets.front();
  for (const ResolvedTarget& t : targets) {
    if (!(t.unit.dimension == first.unit.dimension) || t.unit.unit != first.unit.unit)
      r.fail("path", fmt::format("{} and {} are read in different units ({} and {}); one value "
                                 "cannot set both (mode: scale can)",
                                 first.target.path, t.target.path,
                                 first.unit.unit.empty() ? "a number" : first.unit.unit,
                                 t.unit.unit.empty() ? "a number" : t.unit.unit));
  }
  scale.field = field(first.unit.dimension, first.unit.unit_si, first.unit.unit);
  scale.nominal = first.target.nominal_si;
  for (const ResolvedTarget& t : targets) {
    const double a = first.target.nominal_si, b = t.target.nominal_si;
    if (std::abs(a - b) > kSameNominal * std::max(std::abs(a), std::abs(b))) {
      scale.nominal.reset();
      scale.no_nominal =
          fmt::format("{} is {} but {} is {}", first.target.path, si_text(a, t.unit.dimension),
                      t.target.path, si_text(b, t.unit.dimension));
      break;
    }
  }
  return scale;
}

/// `mean` or `median`: given, else the job's value (1 for scale).
double centre(SectionReader& r, std::string_view key, const ParameterScale& scale) {
  if (const auto value = r.optional_quantity(key, scale.field))
    return *value;
  if (!scale.nominal)
    r.fail(key, fmt::format("required: the fields' own values differ ({}), so none is the default",
                            scale.no_nominal));
  return *scale.nominal;
}

std::string units_of(const ParameterScale& scale) {
  return scale.field.unit.empty() ? std::string("a bare number")
                                  : "bare numbers in " + std::string(scale.field.unit);
}

/// `sd`: absolute (in the field's unit), or relative to the mean ("12 %").
double standard_deviation_of(SectionReader& r, const ParameterScale& scale, double mean,
                             std::string_view family) {
  const std::optional<std::string> written = r.optional_text("sd");
  if (!written)
    r.fail("sd", fmt::format("required for {}: the standard deviation, absolute ({}) or "
                             "relative to the mean ('12 %')",
                             family, units_of(scale)));
  if (unit_part(*written) == "%") {
    double fraction = 0.0;
    try {
      fraction = parse_quantity(*written).value_si;
    } catch (const std::invalid_argument& error) {
      r.fail("sd", error.what());
    }
    if (!(fraction > 0.0))
      r.fail("sd", fmt::format("must be positive, got '{}'", text::trim(*written)));
    if (mean == 0.0)
      r.fail("sd", "a relative sd needs a mean other than 0; give it absolute");
    return fraction * std::abs(mean);
  }
  QuantityField positive = scale.field;
  positive.min = kPositive;
  return *r.optional_quantity("sd", positive);
}

double required_parameter(SectionReader& r, std::string_view key, const QuantityField& field,
                          std::string_view family, std::string_view what) {
  if (const auto value = r.optional_quantity(key, field))
    return *value;
  r.fail(key, fmt::format("required for {}: {}", family, what));
}

/// The family's parameters, read and resolved (not yet validated).
uncertainty::Distribution::Parameters family_parameters(SectionReader& r, const std::string& family,
                                                        const ParameterScale& scale) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  if (family == "normal") {
    uncertainty::Normal normal;
    normal.mean = centre(r, "mean", scale);
    normal.sd = standard_deviation_of(r, scale, normal.mean, "normal");
    return normal;
  }
  if (family == "lognormal") {
    uncertainty::Lognormal lognormal;
    lognormal.median = centre(r, "median", scale);
    lognormal.sigma = required_parameter(r, "sigma", dimensionless(kPositive), "lognormal",
                                         "the standard deviation of ln X, a bare number "
                                         "(0.22 is about ±25 %)");
    return lognormal;
  }
  if (family == "uniform") {
    uncertainty::Uniform uniform;
    uniform.min = required_parameter(r, "min", scale.field, family, "the lowest value");
    uniform.max = required_parameter(r, "max", scale.field, family, "the highest value");
    return uniform;
  }
  uncertainty::TruncatedNormal truncated;
  truncated.mean = centre(r, "mean", scale);
  truncated.sd = standard_deviation_of(r, scale, truncated.mean, "truncated_normal");
  const auto min = r.optional_quantity("min", scale.field);
  const auto max = r.optional_quantity("max", scale.field);
  if (!min && !max)
    r.fail("min", "truncated_normal needs min, max or both: the interval the normal is kept in");
  truncated.min = min.value_or(-kInfinity);
  truncated.max = max.value_or(kInfinity);
  return truncated;
}

/// `distribution` and its parameters; nullopt only with a posterior.
std::optional<uncertainty::Distribution::Parameters> read_distribution(SectionReader& r,
                                                                       const ParameterScale& scale,
                                                                       bool posterior) {
  static const std::vector<std::string> kAll = {"mean", "sd", "median", "sigma", "min", "max"};
  if (!r.has("distribution")) {
    if (!posterior)
      r.fail("distribution",
             "required: normal, lognormal, uniform or truncated_normal (or a posterior file)");
    for (const std::string& key : kAll) {
      if (r.has(key))
        r.fail(key, "a parameter without a distribution; give distribution:");
    }
    return std::nullopt;
  }
  const std::string family =
      r.choice("distribution", {"normal", "lognormal", "uniform", "truncated_normal"});
  const std::vector<std::string> takes =
      family == "normal"      ? std::vector<std::string>{"mean", "sd"}
      : family == "lognormal" ? std::vector<std::string>{"median", "sigma"}
      : family == "uniform"   ? std::vector<std::string>{"min", "max"}
                              : std::vector<std::string>{"mean", "sd", "min", "max"};
  for (const std::string& key : kAll) {
    if (r.has(key) && std::find(takes.begin(), takes.end(), key) == takes.end())
      r.fail(key, fmt::format("is not a parameter of {}, which takes {}", family, joined(takes)));
  }
  uncertainty::Distribution::Parameters parameters = family_parameters(r, family, scale);
  try {
    std::visit([](const auto& p) { (void)uncertainty::Distribution(p); }, parameters);
  } catch (const std::invalid_argument& error) {
    const Dimension& dimension = scale.field.dimension;
    r.fail("distribution",
           std::string(error.what()) +
               (dimension == dimensions::none ? "" : " (values in " + si_unit(dimension) + ")"));
  }
  return parameters;
}

bool is_identifier(std::string_view name) {
  const auto letter = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
  };
  if (name.empty() || name.size() > 64 || !letter(name.front()))
    return false;
  return std::all_of(name.begin(), name.end(),
                     [&](char c) { return letter(c) || text::is_digit(c); });
}

/// One entry of `variables`. `seen_paths`: the fields earlier variables set
/// (path → which variable), so that no field is set twice.
UncertainVariable read_variable(SectionReader& r, const YAML::Node& tree, bool posterior,
                                std::map<std::string, std::string>& seen_paths) {
  r.allow_schema("uncertainty.variables[]");
  UncertainVariable variable;
  variable.line = r.line();
  const auto name = r.optional_text("name");
  if (!name)
    r.fail("name", "required: the variable's name, as results and posterior files call it");
  variable.name = std::string(text::trim(*name));
  if (!is_identifier(variable.name))
    r.fail("name", fmt::format("'{}' is not a name: letters, digits and _, not starting with a "
                               "digit, at most 64",
                               variable.name));
  variable.mode = r.choice("mode", {"value", "scale"}, "value") == "scale" ? UncertainMode::scale
                                                                           : UncertainMode::value;
  std::vector<ResolvedTarget> targets;
  for (const UncertainPathItem& item : path_items(r))
    resolve_path(item, tree, variable.mode, targets);
  for (const ResolvedTarget& t : targets) {
    const auto [at, inserted] = seen_paths.emplace(
        t.target.path, fmt::format("variable '{}' (line {})", variable.name, variable.line));
    if (!inserted)
      throw InputError(r.path_of("path"), t.target.line,
                       fmt::format("{} is already set by {}; a field takes one variable",
                                   t.target.path, at->second));
  }
  const ParameterScale scale = parameter_scale(r, targets, variable.mode);
  variable.distribution = read_distribution(r, scale, posterior);
  for (ResolvedTarget& t : targets)
    variable.targets.push_back(std::move(t.target));
  r.finish();
  return variable;
}

/// `correlation: {a: {b: 0.6, c: -0.2}}`: each pair once, by names; the
/// matrix in the variables' order, checked to be a correlation matrix.
std::optional<Eigen::MatrixXd> read_correlation(SectionReader& r,
                                                const std::vector<UncertainVariable>& variables) {
  auto section = r.section("correlation");
  if (!section)
    return std::nullopt;
  const Eigen::Index n = static_cast<Eigen::Index>(variables.size());
  std::vector<std::string> names;
  for (const UncertainVariable& v : variables)
    names.push_back(v.name);
  const auto index_of = [&](SectionReader& s, const std::string& key) {
    const auto it = std::find(names.begin(), names.end(), key);
    if (it == names.end())
      s.fail(key, fmt::format("'{}' is not a variable; the variables are {}", key, joined(names)));
    return static_cast<Eigen::Index>(it - names.begin());
  };
  Eigen::MatrixXd matrix = Eigen::MatrixXd::Identity(n, n);
  std::map<std::pair<Eigen::Index, Eigen::Index>, int> given;  // (low, high) → line
  SectionReader& c = *section;
  for (const std::string& first : c.keys()) {
    const Eigen::Index i = index_of(c, first);
    auto row = c.section(first);
    for (const std::string& second : row->keys()) {
      const Eigen::Index j = index_of(*row, second);
      if (i == j)
        row->fail(second, "a variable's correlation with itself is 1; list pairs of two variables");
      const double rho = row->quantity(second, dimensionless(Bound{-1.0, true}, Bound{1.0, true}));
      const int line = row->line_of(second);
      const auto [at, inserted] = given.emplace(std::pair{std::min(i, j), std::max(i, j)}, line);
      if (!inserted)
        row->fail(second, fmt::format("the pair {}, {} is given twice (also on line {})", first,
                                      second, at->second));
      matrix(i, j) = matrix(j, i) = rho;
    }
    row->finish();
  }
  c.finish();
  try {
    (void)uncertainty::correlation_factor(matrix, static_cast<int>(n));
  } catch (const std::invalid_argument& error) {
    r.fail("correlation", fmt::format("{} (rows and columns in the variables' order: {})",
                                      error.what(), joined(names)));
  }
  return matrix;
}

}  // namespace

void read_uncertainty(SectionReader& root, const YAML::Node& tree, Job& job) {
  auto section = root.section("uncertainty");
  if (!section || section->keys().empty())
    return;  // `uncertainty:` left empty (or --set uncertainty=null): the nominal job
  SectionReader& r = *section;
  r.allow_schema("uncertainty");
  UncertaintySettings settings;
  settings.line = r.line();
  settings.posterior_line = r.line_of("posterior");
  if (const auto file = r.optional_text("posterior")) {
    if (text::trim(*file).empty())
      r.fail("posterior", "expected the path of a CSV file of draws");
    settings.posterior = job.resolve(std::string(text::trim(*file)));
  }
  auto items = r.sections("variables");
  if (!items || items->empty())
    r.fail("variables", "required: at least one variable {name, path, distribution, ...}");
  std::map<std::string, std::string> seen_paths;
  std::map<std::string, std::pair<std::string, int>> seen_names;  // name → (field, line)
  for (SectionReader& item : *items) {
    settings.variables.push_back(
        read_variable(item, tree, !settings.posterior.empty(), seen_paths));
    const UncertainVariable& v = settings.variables.back();
    const auto [at, inserted] = seen_names.emplace(v.name, std::pair{item.path(), v.line});
    if (!inserted)
      item.fail("name", fmt::format("'{}' is already the name of {} (line {})", v.name,
                                    at->second.first, at->second.second));
  }
  settings.samples_given = r.has("samples");
  settings.samples = r.integer_or("samples", 1, kMaxUncertaintySamples, 1000);
  settings.seed = static_cast<std::uint64_t>(r.integer_or("seed", 0, INT_MAX, 1));
  settings.sampling = r.choice("sampling", {"sobol", "random"}, "sobol") == "random"
                          ? uncertainty::DrawSettings::Sampling::random
                          : uncertainty::DrawSettings::Sampling::sobol;
  settings.correlation_line = r.line_of("correlation");
  settings.correlation = read_correlation(r, settings.variables);
  r.finish();
  job.uncertainty = std::move(settings);
}

void check_uncertainty_round_trip(const Job& job) {
  if (!job.uncertainty || !job.yaml_text)
    return;
  std::vector<Override> overrides = job.overrides;
  for (const UncertainVariable& v : job.uncertainty->variables) {
    for (const UncertainTarget& t : v.targets)
      overrides.push_back({t.path, si_override_value(t.nominal_si, t.dimension)});
  }
  overrides.push_back({"uncertainty", "null"});
  try {
    (void)parse_job(*job.yaml_text, job.source, overrides);
  } catch (const InputError& error) {
    const auto& variables = job.uncertainty->variables;
    const std::string& field = error.field();
    for (std::size_t j = 0; j < variables.size(); ++j) {
      for (const UncertainTarget& t : variables[j].targets) {
        if (field == t.path || field.starts_with(t.path + ".") || field.starts_with(t.path + "["))
          throw InputError(fmt::format("uncertainty.variables[{}].path", j), t.line,
                           fmt::format("variable '{}': the job does not read {} back as a number "
                                       "written in SI ({}): {}",
                                       variables[j].name, t.path,
                                       si_override_value(t.nominal_si, t.dimension), error.what()));
      }
    }
    throw InputError("uncertainty", job.uncertainty->line,
                     std::string("the job with its uncertain fields written back in SI is "
                                 "refused: ") +
                         error.what());
  }
}

}  // namespace robomill::job::detail
