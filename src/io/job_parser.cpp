// Job parsing: YAML text → validated Job in SI units (DESIGN.md §3).
//
// The file has three parts: the SectionReader (typed, strict field access
// with path + line errors), the --set override machinery, and the schema —
// one function per section, reading fields in the order they are documented.

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
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "job_parser_atlas.hpp"
#include "job_parser_deflection.hpp"
#include "job_parser_monitoring.hpp"
#include "job_parser_planning.hpp"
#include "job_parser_simulation.hpp"
#include "job_parser_surface.hpp"
#include "job_parser_toolpath.hpp"
#include "quantity_fields.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/job.hpp"
#include "robomill/io/job_schema.hpp"
#include "robomill/io/units.hpp"
#include "text.hpp"
#include "yaml_reader.hpp"

namespace robomill::io {
namespace detail {
namespace {

using text::trim;

std::string quote_text(std::string_view text) {
  // Values from a fuzzer or a binary file can be long; keep messages readable.
  constexpr std::size_t kMax = 60;
  if (text.size() > kMax)
    return "'" + std::string(text.substr(0, kMax)) + "...'";
  return "'" + std::string(text) + "'";
}

std::string join(const std::vector<std::string_view>& items) {
  std::string out;
  for (const auto& item : items) {
    if (!out.empty())
      out += ", ";
    out += item;
  }
  return out;
}

// Edit distance for "did you mean" hints; keys are short, so O(n·m) is fine,
// but bound the work for hostile keys.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  if (a.size() > 64 || b.size() > 64)
    return std::max(a.size(), b.size());
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j)
    row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + cost});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::string article(const std::string& noun) {
  const char c = noun.empty() ? 'x' : noun.front();
  return (c == 'a' || c == 'e' || c == 'i' || c == 'o' || c == 'u') ? "an " : "a ";
}

// "expected a length (mm, m, um)".
std::string expected_quantity(const QuantityField& field) {
  const std::string name = dimension_name(field.dimension);
  return "expected " + article(name) + name + " (" + typical_units(field.dimension) + ")";
}

bool in_bounds(double value, const QuantityField& field) {
  if (field.min && !(field.min->inclusive ? value >= field.min->value : value > field.min->value)) {
    return false;
  }
  if (field.max && !(field.max->inclusive ? value <= field.max->value : value < field.max->value)) {
    return false;
  }
  return true;
}

// "must be positive", "must be in the range 0 deg <= helix <= 80 deg".
std::string bounds_requirement(const QuantityField& field, std::string_view key) {
  if (field.min && !field.max && field.min->value == 0.0) {
    return field.min->inclusive ? "must not be negative" : "must be positive";
  }
  if (field.min && !field.max) {
    return std::string(field.min->inclusive ? "must be at least " : "must be greater than ") +
           format_in_unit(field.min->value, field);
  }
  if (field.max && !field.min) {
    return std::string(field.max->inclusive ? "must be at most " : "must be less than ") +
           format_in_unit(field.max->value, field);
  }
  return "must be in the range " + format_in_unit(field.min->value, field) +
         (field.min->inclusive ? " <= " : " < ") + std::string(key) +
         (field.max->inclusive ? " <= " : " < ") + format_in_unit(field.max->value, field);
}

}  // namespace

// ---------------------------------------------------------------------------
// Provenance

void Provenance::mark_overridden(std::string path) {
  paths_.push_back(std::move(path));
}

bool Provenance::overridden(std::string_view path) const {
  for (const auto& set : paths_) {
    if (path.size() < set.size() || path.substr(0, set.size()) != set)
      continue;
    if (path.size() == set.size() || path[set.size()] == '.' || path[set.size()] == '[') {
      return true;
    }
  }
  return false;
}

int Provenance::line(const YAML::Node& node, std::string_view path) const {
  if (overridden(path))
    return 0;
  const YAML::Mark mark = node.Mark();
  return mark.line >= 0 ? mark.line + 1 : 0;  // nodes created by --set have no mark
}

std::string Provenance::note(std::string_view path) const {
  return overridden(path) ? " (from --set)" : "";
}

// ---------------------------------------------------------------------------
// Formatting helpers

std::string format_in_unit(double value_si, const QuantityField& field) {
  const std::string number = fmt::format("{:g}", value_si / field.unit_si);
  return field.unit.empty() ? number : number + " " + std::string(field.unit);
}

std::string describe_node(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map:
      return "a map";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Scalar:
      return "the value " + quote_text(node.Scalar());
    case YAML::NodeType::Null:
    case YAML::NodeType::Undefined:
      break;
  }
  return "nothing";
}

// ---------------------------------------------------------------------------
// SectionReader

SectionReader::SectionReader(const YAML::Node& node, std::string path, int line,
                             const Provenance& provenance)
    : path_(std::move(path)), line_(line), provenance_(&provenance) {
  if (node.IsNull())
    return;  // `forces:` with nothing below: all defaults
  if (!node.IsMap()) {
    fail_here("expected a section of `key: value` fields, got " + describe_node(node));
  }
  std::unordered_map<std::string, std::size_t> seen;
  for (auto it = node.begin(); it != node.end(); ++it) {
    const YAML::Node key = it->first;
    if (!key.IsScalar()) {
      throw InputError(
          display_path(), provenance_->line(key, path_),
          "keys must be plain names, got " + describe_node(key) + provenance_->note(path_));
    }
    Entry entry{key.Scalar(), key, it->second, 0, false};
    entry.line = provenance_->line(key, path_of(entry.key));
    // yaml-cpp keeps duplicate keys and returns the first on lookup; a
    // repeated key is almost always an edit gone wrong, so say so. (A hash
    // set keeps this linear for hostile maps with 10^5 keys.)
    if (const auto [at, inserted] = seen.emplace(entry.key, entries_.size()); !inserted) {
      const Entry* first = &entries_[at->second];
      std::string where =
          first->line > 0 ? " (first given on line " + std::to_string(first->line) + ")" : "";
      throw InputError(path_of(entry.key), entry.line,
                       "duplicate key" + where + provenance_->note(path_of(entry.key)));
    }
    entries_.push_back(std::move(entry));
  }
}

std::string SectionReader::display_path() const {
  return path_.empty() ? "job" : path_;
}

std::string SectionReader::path_of(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

int SectionReader::line_of(std::string_view key) const {
  const Entry* entry = find(key);
  return entry != nullptr ? entry->line : line_;
}

const SectionReader::Entry* SectionReader::find(std::string_view key) const {
  for (const auto& entry : entries_) {
    if (entry.key == key)
      return &entry;
  }
  return nullptr;
}

std::vector<std::string> SectionReader::keys() const {
  std::vector<std::string> result;
  result.reserve(entries_.size());
  for (const Entry& entry : entries_)
    result.push_back(entry.key);
  return result;
}

bool SectionReader::has(std::string_view key) const {
  return find(key) != nullptr;
}

bool SectionReader::is_list(std::string_view key) const {
  const Entry* entry = find(key);
  return entry != nullptr && entry->value.IsSequence();
}

bool SectionReader::is_map(std::string_view key) const {
  const Entry* entry = find(key);
  return entry != nullptr && entry->value.IsMap();
}

void SectionReader::fail(std::string_view key, const std::string& message) const {
  const std::string field = path_of(key);
  const Entry* entry = find(key);
  const int line = entry != nullptr ? entry->line : (provenance_->overridden(field) ? 0 : line_);
  throw InputError(field, line, message + provenance_->note(field));
}

void SectionReader::fail_here(const std::string& message) const {
  throw InputError(display_path(), provenance_->overridden(path_) ? 0 : line_,
                   message + provenance_->note(path_));
}

void SectionReader::unknown_key(const Entry& entry, std::string_view message) const {
  std::string text = std::string(message);
  if (!context_.empty())
    text += " " + context_;
  if (!allowed_.empty()) {
    text += "; expected one of: " + join(allowed_);
    std::string_view best;
    std::size_t best_distance = 3;  // suggest only close misspellings
    for (const auto& candidate : allowed_) {
      const std::size_t distance = edit_distance(entry.key, candidate);
      if (distance < best_distance && distance < candidate.size()) {
        best = candidate;
        best_distance = distance;
      }
    }
    if (!best.empty())
      text += " (did you mean '" + std::string(best) + "'?)";
  }
  const std::string field = path_of(entry.key);
  throw InputError(field, entry.line, text + provenance_->note(field));
}

void SectionReader::allow_schema(std::string_view schema_section,
                                 std::initializer_list<std::string_view> unsupported,
                                 std::string_view unsupported_message, std::string_view context) {
  const std::vector<std::string_view>& keys = schema::keys(schema_section);
  schema_section_ = schema_section;
  allowed_.assign(keys.begin(), keys.end());
  context_ = std::string(context);
  for (const auto& entry : entries_) {
    if (entry.read)  // read before the schema was known (cutting.law)
      note_read(entry.key);
  }
  for (const auto& entry : entries_) {
    if (std::find(allowed_.begin(), allowed_.end(), entry.key) != allowed_.end())
      continue;
    if (std::find(unsupported.begin(), unsupported.end(), entry.key) != unsupported.end()) {
      unknown_key(entry, unsupported_message);
    }
    unknown_key(entry, "unknown key");
  }
}

void SectionReader::finish() {
  for (const auto& entry : entries_) {
    if (!entry.read)
      unknown_key(entry, "unknown key");
  }
}

void SectionReader::note_read(std::string_view key) const {
  schema::CoverageRecorder* recorder = schema::detail::active_recorder();
  if (recorder == nullptr || schema_section_.empty())
    return;
  if (std::find(allowed_.begin(), allowed_.end(), key) == allowed_.end()) {
    throw std::logic_error("the job parser reads '" + std::string(key) + "' of " + display_path() +
                           ", which job schema section '" + std::string(schema_section_) +
                           "' does not list");
  }
  recorder->note(schema_section_, key);
}

const SectionReader::Entry* SectionReader::take_value(std::string_view key) {
  note_read(key);
  auto it = std::find_if(entries_.begin(), entries_.end(),
                         [&](const Entry& entry) { return entry.key == key; });
  if (it == entries_.end())
    return nullptr;
  it->read = true;
  if (it->value.IsNull()) {
    fail(key, "no value given (remove the key to use the default)");
  }
  return &*it;
}

const std::string& SectionReader::scalar(const Entry& entry, std::string_view expected) const {
  if (!entry.value.IsScalar()) {
    fail(entry.key, std::string(expected) + ", got " + describe_node(entry.value));
  }
  return entry.value.Scalar();
}

double SectionReader::read_quantity(const Entry& entry, const QuantityField& field) const {
  const std::string& text = scalar(entry, expected_quantity(field));
  std::string problem;
  const double si = quantity_in_field(text, field, entry.key, problem);
  if (!problem.empty())
    fail(entry.key, problem);
  return si;
}

double SectionReader::quantity_in_field(const std::string& text, const QuantityField& field,
                                        std::string_view key, std::string& problem) const {
  Quantity quantity;
  try {
    quantity = parse_quantity(text);
  } catch (const std::invalid_argument& error) {
    problem = error.what();
    return 0.0;
  }
  const std::string_view unit = unit_part(text);
  double si = quantity.value_si;
  if (unit.empty()) {
    // A bare number is in the field's documented unit.
    si *= field.unit_si;
  } else if (!(quantity.dimension == field.dimension)) {
    const std::string got = dimension_name(quantity.dimension);
    problem =
        expected_quantity(field) + ", got " + quote_text(unit) + " (" + article(got) + got + ")";
    return 0.0;
  }
  if (!std::isfinite(si)) {
    problem = quote_text(text) + " is out of range";
    return 0.0;
  }
  if (!in_bounds(si, field)) {
    const std::string got = unit.empty() && !field.unit.empty()
                                ? std::string(trim(text)) + " " + std::string(field.unit)
                                : std::string(trim(text));
    problem = bounds_requirement(field, key) + ", got " + got;
    return 0.0;
  }
  return si;
}

std::optional<std::vector<double>> SectionReader::quantities(std::string_view key,
                                                             const QuantityField& field,
                                                             std::size_t count) {
  auto items = texts(key);
  if (!items)
    return std::nullopt;
  if (count > 0 && items->size() != count) {
    fail(key, "expected a list of " + std::to_string(count) + " values, got " +
                  std::to_string(items->size()));
  }
  std::vector<double> values;
  values.reserve(items->size());
  for (const Item& item : *items) {
    std::string problem;
    values.push_back(quantity_in_field(item.text, field, key, problem));
    if (!problem.empty())
      throw InputError(item.path, item.line, problem + provenance_->note(item.path));
  }
  return values;
}

Eigen::Vector3d SectionReader::unit_vector_or(std::string_view key,
                                              const Eigen::Vector3d& fallback) {
  const auto v = quantities(key, dimensionless(), 3);
  if (!v)
    return fallback;
  const Eigen::Vector3d d((*v)[0], (*v)[1], (*v)[2]);
  if (!(d.norm() > 0.0))
    fail(key, "the direction must not be zero");
  return d.normalized();
}

double SectionReader::quantity(std::string_view key, const QuantityField& field) {
  if (auto value = optional_quantity(key, field))
    return *value;
  fail(key, "required field missing (" + dimension_name(field.dimension) +
                (field.unit.empty() ? "" : ", in " + std::string(field.unit) + " by default") +
                ")");
}

std::optional<double> SectionReader::optional_quantity(std::string_view key,
                                                       const QuantityField& field) {
  const Entry* entry = take_value(key);
  if (entry == nullptr)
    return std::nullopt;
  return read_quantity(*entry, field);
}

double SectionReader::quantity_or(std::string_view key, const QuantityField& field,
                                  double default_si) {
  return optional_quantity(key, field).value_or(default_si);
}

int SectionReader::read_integer(const Entry& entry, int min, int max) const {
  const std::string_view text = trim(scalar(entry, "expected an integer"));
  std::string_view digits = text;
  if (!digits.empty() && digits.front() == '+')
    digits.remove_prefix(1);
  long long value = 0;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (digits.empty() || error != std::errc() || end != digits.data() + digits.size()) {
    if (error == std::errc::result_out_of_range) {
      fail(entry.key, fmt::format("must be an integer from {} to {}, got {}", min, max, text));
    }
    fail(entry.key, "must be an integer, got " + quote_text(text));
  }
  if (value < min && min == 1)
    fail(entry.key, "must be a positive integer, got " + std::string(text));
  if (value < min || value > max) {
    fail(entry.key, fmt::format("must be an integer from {} to {}, got {}", min, max, text));
  }
  return static_cast<int>(value);
}

int SectionReader::integer(std::string_view key, int min, int max) {
  const Entry* entry = take_value(key);
  if (entry == nullptr)
    fail(key, "required field missing (an integer)");
  return read_integer(*entry, min, max);
}

int SectionReader::integer_or(std::string_view key, int min, int max, int default_value) {
  const Entry* entry = take_value(key);
  return entry == nullptr ? default_value : read_integer(*entry, min, max);
}

bool SectionReader::read_boolean(const Entry& entry) const {
  const std::string_view text = trim(scalar(entry, "expected true or false"));
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) {
    return static_cast<char>(c >= 'A' && c <= 'Z' ? c + 32 : c);
  });
  // YAML 1.1 spellings are accepted because many YAML writers still emit them.
  if (lower == "true" || lower == "yes" || lower == "on")
    return true;
  if (lower == "false" || lower == "no" || lower == "off")
    return false;
  fail(entry.key, "expected true or false, got " + quote_text(text));
}

bool SectionReader::boolean(std::string_view key) {
  const Entry* entry = take_value(key);
  if (entry == nullptr)
    fail(key, "required field missing (true or false)");
  return read_boolean(*entry);
}

bool SectionReader::boolean_or(std::string_view key, bool default_value) {
  const Entry* entry = take_value(key);
  return entry == nullptr ? default_value : read_boolean(*entry);
}

std::string SectionReader::choice(std::string_view key,
                                  std::initializer_list<std::string_view> options,
                                  std::string_view default_value) {
  const std::vector<std::string_view> list(options);
  const std::string expected = "expected one of: " + join(list);
  const Entry* entry = take_value(key);
  if (entry == nullptr) {
    if (default_value.empty())
      fail(key, "required field missing (" + expected + ")");
    return std::string(default_value);
  }
  const std::string_view text = trim(scalar(*entry, expected));
  if (std::find(list.begin(), list.end(), text) == list.end()) {
    fail(key, expected + "; got " + quote_text(text));
  }
  return std::string(text);
}

std::optional<std::string> SectionReader::optional_text(std::string_view key) {
  const Entry* entry = take_value(key);
  if (entry == nullptr)
    return std::nullopt;
  return scalar(*entry, "expected text");
}

std::optional<SectionReader> SectionReader::section(std::string_view key) {
  note_read(key);
  auto it = std::find_if(entries_.begin(), entries_.end(),
                         [&](const Entry& entry) { return entry.key == key; });
  if (it == entries_.end())
    return std::nullopt;
  it->read = true;
  return SectionReader(it->value, path_of(key), it->line, *provenance_);
}

std::optional<std::vector<SectionReader>> SectionReader::sections(std::string_view key) {
  const Entry* entry = take_value(key);
  if (entry == nullptr)
    return std::nullopt;
  if (!entry->value.IsSequence()) {
    fail(key, "expected a list (`- ...` items or [ ... ]), got " + describe_node(entry->value));
  }
  std::vector<SectionReader> items;
  const std::string base = path_of(key);
  std::size_t index = 0;
  for (const auto& item : entry->value) {
    const std::string item_path = base + "[" + std::to_string(index++) + "]";
    int line = provenance_->line(item, item_path);
    if (line == 0 && !provenance_->overridden(item_path))
      line = entry->line;
    items.emplace_back(item, item_path, line, *provenance_);
  }
  return items;
}

std::optional<std::vector<SectionReader::Item>> SectionReader::texts(std::string_view key) {
  const Entry* entry = take_value(key);
  if (entry == nullptr)
    return std::nullopt;
  if (!entry->value.IsSequence()) {
    fail(key, "expected a list ([a, b] or `- ...` items), got " + describe_node(entry->value));
  }
  std::vector<Item> items;
  const std::string base = path_of(key);
  std::size_t index = 0;
  for (const auto& node : entry->value) {
    Item item;
    item.path = base + "[" + std::to_string(index++) + "]";
    item.line = provenance_->line(node, item.path);
    if (!node.IsScalar()) {
      throw InputError(
          item.path, item.line,
          "expected a plain value, got " + describe_node(node) + provenance_->note(item.path));
    }
    item.text = std::string(trim(node.Scalar()));
    items.push_back(std::move(item));
  }
  return items;
}

std::optional<std::vector<int>> SectionReader::integers(std::string_view key, std::size_t count,
                                                        int min, int max) {
  const auto items = texts(key);
  if (!items)
    return std::nullopt;
  if (items->size() != count)
    fail(key, fmt::format("expected {} integers, got {}", count, items->size()));
  std::vector<int> values;
  for (const Item& item : *items) {
    int value = 0;
    try {
      std::size_t used = 0;
      value = std::stoi(item.text, &used);
      if (used != item.text.size())
        throw std::invalid_argument(item.text);
    } catch (const std::exception&) {
      throw InputError(item.path, item.line, "'" + item.text + "' is not an integer");
    }
    if (value < min || value > max) {
      throw InputError(item.path, item.line,
                       fmt::format("must lie in {} … {}, got {}", min, max, value));
    }
    values.push_back(value);
  }
  return values;
}

}  // namespace detail

// ===========================================================================
// --set overrides and the schema

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
using detail::kPi;
using detail::kPositive;
using detail::kRpm;
using detail::length_mm;

// Documented units of the fields (DESIGN.md §3): bare numbers are read in them.
constexpr double kGPa = 1e9;
constexpr double kNPerMm2 = 1e6;
constexpr double kNPerMm = 1e3;
constexpr double kMmPerMin = 1e-3 / 60.0;

// Cheap guards run before yaml-cpp sees the text. yaml-cpp parses nested
// collections recursively; pathological nesting ("[[[[...", "- - - - ...")
// exhausts the stack (notably under sanitizers) before its own depth guard
// trips. No job needs more than a handful of levels, so anything beyond
// kMaxDepth is rejected. The scan is deliberately conservative: brackets are
// counted even inside quoted strings, so a name with 65 unmatched '[' is
// rejected too — a false positive nobody will meet, never a false negative.
constexpr std::size_t kMaxJobBytes = 1 << 20;
constexpr int kMaxDepth = 64;

void guard_input(std::string_view text, const std::string& source) {
  if (text.size() > kMaxJobBytes) {
    throw InputError(source, 0,
                     fmt::format("job is {} bytes; job files are limited to 1 MiB", text.size()));
  }
  int flow_depth = 0;
  std::vector<std::size_t> indents;  // indentation of the open block levels
  int line_number = 0;
  std::size_t position = 0;
  auto too_deep = [&] {
    return InputError(source, line_number,
                      fmt::format("nesting deeper than {} levels; a job never needs that many "
                                  "(rejected before parsing)",
                                  kMaxDepth));
  };
  while (position <= text.size()) {
    std::size_t end = text.find('\n', position);
    if (end == std::string_view::npos)
      end = text.size();
    const std::string_view line = text.substr(position, end - position);
    ++line_number;
    position = end + 1;

    std::size_t indent = 0;
    while (indent < line.size() && line[indent] == ' ')
      ++indent;
    std::string_view rest = line.substr(indent);
    if (!rest.empty() && rest.front() != '#' && rest.front() != '\r') {
      while (!indents.empty() && indents.back() > indent)
        indents.pop_back();
      if (indents.empty() || indents.back() < indent)
        indents.push_back(indent);
      // Compact nested sequences and complex keys ("- - - x", "? ? x") each
      // open a level on the same line.
      int inline_levels = 0;
      while (rest.size() >= 2 && (rest[0] == '-' || rest[0] == '?') &&
             (rest[1] == ' ' || rest[1] == '\t')) {
        ++inline_levels;
        rest.remove_prefix(2);
        while (!rest.empty() && (rest.front() == ' ' || rest.front() == '\t'))
          rest.remove_prefix(1);
      }
      if (static_cast<int>(indents.size()) + inline_levels > kMaxDepth)
        throw too_deep();
    }
    for (const char c : line) {
      if (c == '[' || c == '{') {
        if (++flow_depth > kMaxDepth)
          throw too_deep();
      } else if ((c == ']' || c == '}') && flow_depth > 0) {
        --flow_depth;
      }
    }
    if (end == text.size())
      break;
  }
}

// One step of an override path as written: a name (`modes`, `T3`, `0`) or a
// bracket index (`[0]`). A name of digits indexes a list when the node it
// steps into is a list (`dynamics.modes.0.zeta`) and is a key otherwise
// (`toolpath.bases.1`, a map keyed by numbers).
struct PathStep {
  std::string text;       ///< the name, or the index's digits
  bool bracket = false;   ///< written `[n]`: always an index
  bool digits = false;    ///< only digits: an index where the node is a list
  std::size_t index = 0;  ///< its value when `digits`; SIZE_MAX when it overflows
};

bool is_key_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

PathStep make_step(std::string_view text, bool bracket) {
  PathStep step{std::string(text), bracket, !text.empty(), 0};
  for (const char c : text)
    step.digits = step.digits && is_digit(c);
  if (step.digits) {
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), step.index);
    if (error != std::errc{})
      step.index = std::numeric_limits<std::size_t>::max();  // out of range of any list
  }
  return step;
}

// "dynamics.modes[0].fn" → {dynamics, modes, [0], fn}; "dynamics.modes.0.fn"
// → {dynamics, modes, 0, fn}. Malformed paths throw, naming the override.
std::vector<PathStep> split_path(const Override& override_, const std::string& where) {
  const std::string_view path = override_.path;
  const auto invalid = [&](std::size_t at) {
    // "-1" where a name or an index belongs: say that indices start at 0.
    if (at < path.size() && path[at] == '-') {
      std::size_t end = at + 1;
      while (end < path.size() && is_digit(path[end]))
        ++end;
      if (end > at + 1) {
        return InputError(override_.path, 0,
                          "invalid key path in `" + where + "`: list indices count from 0, got " +
                              std::string(path.substr(at, end - at)) + " (from --set)");
      }
    }
    return InputError(override_.path, 0,
                      "invalid key path in `" + where +
                          "`; expected dotted names such as process.ae, dynamics.modes.0.fn or "
                          "dynamics.modes[0].fn (from --set)");
  };
  std::vector<PathStep> steps;
  std::size_t i = 0;
  while (true) {
    const std::size_t start = i;
    while (i < path.size() && is_key_char(path[i]))
      ++i;
    if (i == start)
      throw invalid(i);
    steps.push_back(make_step(path.substr(start, i - start), false));
    while (i < path.size() && path[i] == '[') {
      const std::size_t digits_start = ++i;
      while (i < path.size() && is_digit(path[i]))
        ++i;
      if (i == digits_start || i >= path.size() || path[i] != ']')
        throw invalid(digits_start);
      steps.push_back(make_step(path.substr(digits_start, i - digits_start), true));
      ++i;
    }
    if (i == path.size())
      return steps;
    if (path[i] != '.')
      throw invalid(i);
    ++i;
  }
}

// The schema's kind of field `key` in the section at the job path `parent`
// ("dynamics.modes[1]" is the schema's "dynamics.modes[]"); nullopt for a
// field the schema does not list (a typo, or a key of a map keyed by the
// user such as `toolpath.tools.T3`).
std::optional<schema::Kind> schema_kind(std::string_view parent, std::string_view key) {
  std::string section;
  for (std::size_t i = 0; i < parent.size(); ++i) {
    section += parent[i];
    if (parent[i] == '[') {
      while (i + 1 < parent.size() && parent[i + 1] != ']')
        ++i;
    }
  }
  if (section.empty())
    section = "job";
  for (const schema::Field& field : schema::fields()) {
    std::string_view id = field.section;
    if (const auto variant = id.find("[law="); variant != std::string_view::npos)
      id = id.substr(0, variant);  // cutting[law=linear] → cutting
    if (id == section && field.key == key)
      return field.kind;
  }
  return std::nullopt;
}

std::string entries(std::size_t count) {
  return std::to_string(count) + (count == 1 ? " entry" : " entries");
}

// The value under `key` in a map, found by iterating rather than with
// operator[] so that odd keys (lists as keys) never reach yaml-cpp's
// key conversion.
std::optional<YAML::Node> map_child(const YAML::Node& map, const std::string& key) {
  for (auto it = map.begin(); it != map.end(); ++it) {
    if (it->first.IsScalar() && it->first.Scalar() == key)
      return it->second;
  }
  return std::nullopt;
}

// Applies one `--set`: walks the path from the root, creating missing
// sections, and replaces (or adds) the value at its end. An index steps into
// an existing list: 0 … size-1 name an entry, and `size` as the last step
// appends one. The path is recorded in the reader's bracket form
// (dynamics.modes[0].zeta) whichever form was written, so that errors in the
// value end with "(from --set)".
void apply_override(YAML::Node& root, const Override& override_, Provenance& provenance) {
  const std::string where = "--set " + override_.path + "=" + override_.value;
  const std::vector<PathStep> steps = split_path(override_, where);
  // The value meets yaml-cpp too, so it gets the same guards as a job file.
  try {
    guard_input(override_.value, override_.path);
  } catch (const InputError&) {
    throw InputError(override_.path, 0,
                     "value of `--set " + override_.path + "` rejected: nesting or size limit " +
                         "exceeded (from --set)");
  }
  YAML::Node value;
  try {
    value = YAML::Load(override_.value);
  } catch (const YAML::Exception& error) {
    throw InputError(override_.path, 0,
                     "value of `" + where + "` is not valid YAML: " + error.msg + " (from --set)");
  }
  if (!root.IsMap())
    root = YAML::Node(YAML::NodeType::Map);

  YAML::Node current = root;
  std::string parent;  // the job path of `current`, in bracket form
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const PathStep& step = steps[k];
    const bool last = k + 1 == steps.size();
    if (step.bracket || (step.digits && current.IsSequence())) {
      if (!current.IsSequence()) {
        throw InputError(parent, 0,
                         "`" + where + "` indexes " + parent + ", which is " +
                             detail::describe_node(current) + ", not a list (from --set)");
      }
      const std::size_t size = current.size();
      if (step.index > size || (step.index == size && !last)) {
        std::string message = fmt::format("`{}`: index {} is out of range; {} has {}", where,
                                          step.text, parent, entries(size));
        if (step.index == size)
          message += fmt::format(" (index {} adds an entry only as a whole: --set {}.{}=...)", size,
                                 parent, size);
        throw InputError(parent, 0, message + " (from --set)");
      }
      parent += "[" + std::to_string(step.index) + "]";
      if (last) {
        if (step.index == size)
          current.push_back(value);
        else
          current[step.index] = value;
        break;
      }
      YAML::Node child = current[step.index];
      current.reset(child);
      continue;
    }

    if (!current.IsMap()) {
      const std::string wanted = step.digits ? "a list or a section" : "a section";
      throw InputError(parent, 0,
                       "`" + where + "` needs " + parent + " to be " + wanted + ", but it is " +
                           detail::describe_node(current) + " (from --set)");
    }
    const std::string path = parent.empty() ? step.text : parent + "." + step.text;
    if (last) {
      current[step.text] = value;
      parent = path;
      break;
    }
    std::optional<YAML::Node> child = map_child(current, step.text);
    if (!child || child->IsNull()) {
      // An index needs a list that is there: a missing one is not created.
      // (A number after a map the schema keys by numbers, toolpath.bases.1,
      // is a key; after a name the schema lacks, the reader reports the
      // unknown key with its "did you mean".)
      const PathStep& next = steps[k + 1];
      const std::optional<schema::Kind> kind = schema_kind(parent, step.text);
      if (next.bracket || (next.digits && kind && *kind != schema::Kind::map)) {
        throw InputError(path, 0,
                         fmt::format("`{}`: the job has no {} list to index; give the whole "
                                     "list instead, such as --set '{}=[...]' (from --set)",
                                     where, path, path));
      }
      // Create the missing section, e.g. `--set forces.revolutions=3` in a
      // job without a forces: section.
      current[step.text] = YAML::Node(YAML::NodeType::Map);
      child = map_child(current, step.text);
      // Everything inside a section created here comes from the command line.
      provenance.mark_overridden(path);
    }
    // reset() rebinds `current`; plain assignment would overwrite the node.
    current.reset(*child);
    parent = path;
  }
  provenance.mark_overridden(parent);
}

// ---------------------------------------------------------------------------
// Sections

std::optional<tool::ToolSpec> read_tool(SectionReader& root) {
  auto section = root.section("tool");
  if (!section)
    return std::nullopt;
  return detail::read_tool_fields(*section);
}

}  // namespace

// The fields of a tool section, wherever it sits (`tool`, `toolpath.tools.T3`).
tool::ToolSpec detail::read_tool_fields(SectionReader& r) {
  r.allow_schema("tool");

  tool::ToolSpec spec;
  const std::string type = r.choice("type", {"flat", "ball", "bull"}, "flat");
  spec.type = type == "ball"   ? tool::ToolType::ball
              : type == "bull" ? tool::ToolType::bull
                               : tool::ToolType::flat;
  spec.diameter_m = r.quantity("diameter", length_mm());
  spec.teeth = r.integer("teeth", 1, 20);
  spec.helix_rad = r.quantity_or(
      "helix", field(dimensions::angle, kDeg, "deg", kNonNegative, Bound{80 * kDeg, true}), 0.0);
  const double radius = 0.5 * spec.diameter_m;
  if (spec.type == tool::ToolType::bull) {
    spec.corner_radius_m = r.quantity("corner_radius", length_mm(kPositive));
    if (spec.corner_radius_m > radius * (1.0 + 1e-12))
      r.fail("corner_radius", "must be at most the tool radius (" +
                                  detail::format_in_unit(radius, length_mm()) + "), got " +
                                  detail::format_in_unit(spec.corner_radius_m, length_mm()));
  } else if (r.has("corner_radius")) {
    r.fail("corner_radius",
           "is read for tool.type: bull only (a flat end mill has none, a "
           "ball's is its radius)");
  }
  spec.overhang_m = r.quantity_or("overhang", length_mm(), 4.0 * spec.diameter_m);
  if (spec.type == tool::ToolType::ball && spec.overhang_m < radius) {
    r.fail("overhang", "must be at least the ball radius (" +
                           detail::format_in_unit(radius, length_mm()) +
                           ") for a ball-end mill, got " +
                           detail::format_in_unit(spec.overhang_m, length_mm()));
  }
  spec.youngs_modulus_pa =
      r.quantity_or("E", field(dimensions::pressure, kGPa, "GPa", kPositive), 600e9);
  if (auto runout = r.section("runout")) {
    runout->allow_schema("tool.runout");
    spec.runout.offset_m = runout->quantity_or("offset", length_mm(kNonNegative), 0.0);
    if (spec.runout.offset_m >= radius) {
      runout->fail("offset", "must be less than the tool radius (" +
                                 detail::format_in_unit(radius, length_mm()) + "), got " +
                                 detail::format_in_unit(spec.runout.offset_m, length_mm()));
    }
    spec.runout.angle_rad =
        runout->quantity_or("angle", field(dimensions::angle, kDeg, "deg"), 0.0);
    runout->finish();
  }
  r.finish();

  // Tool's constructor is the authority on what a physical cutter is; the
  // checks above only make the common mistakes point at the exact field.
  try {
    tool::Tool checked(spec);
  } catch (const std::invalid_argument& error) {
    r.fail_here(error.what());
  }
  return spec;
}

namespace {

std::optional<cutting::CuttingLaw> read_cutting(SectionReader& root) {
  auto section = root.section("cutting");
  if (!section)
    return std::nullopt;
  SectionReader& r = *section;
  // The law decides which keys are valid, so it is read before allow_schema().
  const std::string law =
      r.choice("law", {"linear", "exponential", "fractional", "size_dependent"}, "linear");
  const std::string context = "for law '" + law + "'";
  const QuantityField pressure = field(dimensions::pressure, kNPerMm2, "N/mm^2");
  const QuantityField per_length = field(dimensions::force_per_length, kNPerMm, "N/mm");
  auto bounded = [](QuantityField field, std::optional<Bound> min) {
    field.min = min;
    return field;
  };

  cutting::CuttingLaw result;
  if (law == "linear") {
    r.allow_schema("cutting[law=linear]", {}, {}, context);
    cutting::LinearLaw l;
    l.Ktc_pa = r.quantity("Ktc", bounded(pressure, kPositive));
    l.Krc_pa = r.quantity_or("Krc", bounded(pressure, kNonNegative), 0.0);
    l.Kac_pa = r.quantity_or("Kac", pressure, 0.0);  // sign follows the helix hand
    l.Kte_n_per_m = r.quantity_or("Kte", bounded(per_length, kNonNegative), 0.0);
    l.Kre_n_per_m = r.quantity_or("Kre", bounded(per_length, kNonNegative), 0.0);
    l.Kae_n_per_m = r.quantity_or("Kae", per_length, 0.0);
    result = l;
  } else if (law == "exponential") {
    r.allow_schema("cutting[law=exponential]", {}, {}, context);
    cutting::ExponentialLaw l;
    l.kF_n_per_m = r.quantity("kF", bounded(per_length, kPositive));
    l.exponent = r.quantity("exponent", dimensionless(kPositive, Bound{1.5, true}));
    l.reference_chip_m = r.quantity_or("chip_unit", length_mm(), 1e-3);
    l.radial_ratio = r.quantity_or("kr", dimensionless(kNonNegative), 0.0);
    l.axial_ratio = r.quantity_or("ka", dimensionless(), 0.0);
    result = l;
  } else if (law == "fractional") {
    r.allow_schema("cutting[law=fractional]", {}, {}, context);
    cutting::FractionalLaw l;
    l.k0_n_per_m = r.quantity("k0", field(dimensions::force_per_length, 1.0, "N/m", kPositive));
    l.hs_m = r.quantity("hs", length_mm());
    l.r = r.quantity("r", dimensionless(kNonNegative));
    l.radial_ratio = r.quantity_or("kr", dimensionless(kNonNegative), 0.0);
    l.axial_ratio = r.quantity_or("ka", dimensionless(), 0.0);
    result = l;
  } else {
    r.allow_schema("cutting[law=size_dependent]", {}, {}, context);
    cutting::SizeDependentLaw l;
    l.kc1_pa = r.quantity("kc1", bounded(pressure, kPositive));
    l.b1 = r.quantity("b1", dimensionless());
    l.kc2 = r.quantity("kc2", dimensionless(kNonNegative));
    l.b2 = r.quantity("b2", dimensionless());
    l.reference_chip_m = r.quantity_or("chip_unit", length_mm(), 1e-3);
    result = l;
  }
  r.finish();
  try {
    cutting::validate(result);
  } catch (const std::invalid_argument& error) {
    r.fail_here(error.what());
  }
  return result;
}

std::optional<cutting::MillingProcess> read_process(SectionReader& root,
                                                    const std::optional<tool::ToolSpec>& tool) {
  auto section = root.section("process");
  if (!section)
    return std::nullopt;
  SectionReader& r = *section;
  r.allow_schema("process");

  cutting::MillingProcess process;
  process.spindle_rad_s =
      r.quantity("spindle", field(dimensions::angular_speed, kRpm, "rpm", kPositive));
  const bool per_tooth = r.has("feed_per_tooth");
  const bool rate = r.has("feed_rate");
  if (per_tooth && rate) {
    // Point at whichever comes second: that is the line the user added.
    const bool rate_second = r.line_of("feed_rate") >= r.line_of("feed_per_tooth");
    r.fail(rate_second ? "feed_rate" : "feed_per_tooth",
           "give either feed_per_tooth or feed_rate, not both");
  }
  if (!per_tooth && !rate) {
    r.fail("feed_per_tooth",
           "required field missing (give feed_per_tooth in mm, or feed_rate "
           "in mm/min)");
  }
  if (per_tooth) {
    process.feed_per_tooth_m = r.quantity("feed_per_tooth", length_mm());
  } else {
    const double feed_rate =
        r.quantity("feed_rate", field(dimensions::speed, kMmPerMin, "mm/min", kPositive));
    if (!tool) {
      r.fail("feed_rate",
             "converting a feed rate into a feed per tooth needs the number of teeth; add a "
             "tool: section or give feed_per_tooth instead");
    }
    const double revolutions_per_s = process.spindle_rad_s / (2.0 * kPi);
    process.feed_per_tooth_m = feed_rate / (tool->teeth * revolutions_per_s);
  }
  process.axial_depth_m = r.quantity("ap", length_mm());
  process.radial_depth_m = r.quantity("ae", length_mm());
  process.direction = r.choice("direction", {"down", "up"}, "down") == "up"
                          ? cutting::MillingDirection::up
                          : cutting::MillingDirection::down;
  r.finish();

  if (tool) {
    // A relative tolerance keeps "ae: 10 mm" on a 10 mm cutter (slotting)
    // valid despite rounding in unit conversion.
    if (process.radial_depth_m > tool->diameter_m * (1.0 + 1e-9)) {
      r.fail("ae", "radial depth of cut " +
                       detail::format_in_unit(process.radial_depth_m, length_mm()) +
                       " exceeds the tool diameter " +
                       detail::format_in_unit(tool->diameter_m, length_mm()));
    }
    if (process.axial_depth_m > tool->overhang_m * (1.0 + 1e-9)) {
      r.fail("ap", "axial depth of cut " +
                       detail::format_in_unit(process.axial_depth_m, length_mm()) +
                       " exceeds the tool overhang " +
                       detail::format_in_unit(tool->overhang_m, length_mm()));
    }
  }
  return process;
}

ForcesSettings read_forces(SectionReader& root, const std::optional<tool::ToolSpec>& tool) {
  ForcesSettings forces;
  auto section = root.section("forces");
  if (!section)
    return forces;
  SectionReader& r = *section;
  r.allow_schema("forces");
  forces.revolutions = r.integer_or("revolutions", 1, 1000, forces.revolutions);
  forces.steps_per_tooth = r.integer_or("steps_per_tooth", 4, 100000, forces.steps_per_tooth);
  // 0 (automatic) is the default and cannot be written: an explicit value is a count.
  forces.axial_elements = r.integer_or("axial_elements", 1, 10000, 0);
  // Each sample holds ~50 bytes; cap the history at 20 million samples (1 GB)
  // so a typo cannot exhaust memory.
  constexpr double kMaxSamples = 20e6;
  const double samples =
      static_cast<double>(forces.revolutions) * forces.steps_per_tooth * (tool ? tool->teeth : 1);
  if (samples > kMaxSamples) {
    r.fail(r.has("steps_per_tooth") ? "steps_per_tooth" : "revolutions",
           "revolutions x teeth x steps_per_tooth = " +
               std::to_string(static_cast<long long>(samples)) +
               " samples exceeds the limit of 20000000");
  }
  r.finish();
  return forces;
}

/// `shape: [{at: 3 mm, value: 3.232}, …]` — 000 Table 2's mass-normalized
/// shape (1/√kg) at points measured from the tool tip.
dynamics::AxialShape read_axial_shape(SectionReader& mode) {
  auto points = mode.sections("shape");
  if (points->empty())
    mode.fail("shape", "must list at least one point {at, value}");
  std::vector<double> distance_m, value;
  for (SectionReader& point : *points) {
    point.allow_schema("dynamics.modes[].shape[]");
    const double at = point.quantity("at", length_mm(kNonNegative));
    if (!distance_m.empty() && !(at > distance_m.back()))
      point.fail("at", "points must be listed from the tip outward (increasing distance)");
    distance_m.push_back(at);
    value.push_back(point.quantity("value", dimensionless()));
    point.finish();
  }
  return dynamics::AxialShape(std::move(distance_m), std::move(value));
}

ModeSpec read_mode(SectionReader& m) {
  m.allow_schema("dynamics.modes[]");
  ModeSpec mode;
  if (m.is_list("direction")) {
    const auto components = m.texts("direction");
    // A general direction [dx, dy, dz], normalized: a mode that moves the tip
    // obliquely couples the directions (cross FRFs H_xy ≠ 0).
    if (components->size() != 3)
      m.fail("direction", "a direction vector needs three components [dx, dy, dz]");
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) {
      const auto& item = (*components)[static_cast<std::size_t>(i)];
      try {
        std::size_t used = 0;
        v[i] = std::stod(item.text, &used);
        if (used != item.text.size() || !std::isfinite(v[i]))
          throw std::invalid_argument(item.text);
      } catch (const std::exception&) {
        throw InputError(item.path, item.line, "'" + item.text + "' is not a finite number");
      }
    }
    if (!(v.norm() > 0.0))
      m.fail("direction", "the direction vector must not be zero");
    mode.direction = 'v';
    mode.direction_vector = v.normalized();
  } else {
    mode.direction = m.choice("direction", {"x", "y", "z"})[0];
    mode.direction_vector = Eigen::Vector3d::Unit(mode.direction - 'x');
  }
  mode.natural_frequency_hz = m.quantity("fn", field(dimensions::frequency, 1.0, "Hz", kPositive));
  mode.damping_ratio = m.quantity("zeta", dimensionless(kPositive, Bound{1.0, false}));
  const auto k = m.optional_quantity("k", field(dimensions::stiffness, 1.0, "N/m", kPositive));
  const auto mass = m.optional_quantity("m", field(dimensions::mass, 1.0, "kg", kPositive));
  const int given = (k ? 1 : 0) + (mass ? 1 : 0) + (m.has("shape") ? 1 : 0);
  if (given > 1) {
    const char* second = m.has("shape") ? "shape" : m.line_of("m") >= m.line_of("k") ? "m" : "k";
    m.fail(second,
           "give one of k (modal stiffness), m (modal mass) or shape (mass-normalized shape "
           "along the tool), not several");
  }
  if (given == 0) {
    m.fail("k",
           "required field missing (modal stiffness in N/m, or give the modal mass m in kg, or "
           "the mass-normalized shape along the tool)");
  }
  // k = m ωn² for a single-degree-of-freedom mode; a mass-normalized shape φ
  // at the tip gives m = 1/φ².
  const double omega = 2.0 * kPi * mode.natural_frequency_hz;
  std::string source = k ? "k" : mass ? "m" : "shape";
  if (k) {
    mode.stiffness_n_per_m = *k;
    mode.mass_kg = *k / (omega * omega);
  } else if (mass) {
    mode.mass_kg = *mass;
    mode.stiffness_n_per_m = *mass * omega * omega;
  } else {
    try {
      mode.shape = read_axial_shape(m);
    } catch (const std::invalid_argument& e) {
      m.fail("shape", e.what());
    }
    const double tip = mode.shape.at(0.0);
    if (!(std::abs(tip) > 0.0)) {
      m.fail("shape", fmt::format("extrapolates to {:g} 1/sqrt(kg) at the tool tip; a mode needs "
                                  "a non-zero shape there",
                                  tip));
    }
    mode.mass_kg = 1.0 / (tip * tip);
    mode.stiffness_n_per_m = mode.mass_kg * omega * omega;
  }
  if (!std::isfinite(mode.stiffness_n_per_m) || !std::isfinite(mode.mass_kg) ||
      !(mode.stiffness_n_per_m > 0.0) || !(mode.mass_kg > 0.0)) {
    m.fail(source, "gives a modal mass or stiffness out of range with fn = " +
                       fmt::format("{:g} Hz", mode.natural_frequency_hz));
  }
  m.finish();
  return mode;
}

std::optional<int> read_axis(SectionReader& r, std::string_view key) {
  if (!r.has(key))
    return std::nullopt;
  return r.choice(key, {"x", "y", "z"})[0] - 'x';
}

std::filesystem::path job_relative(const std::filesystem::path& source, const std::string& file) {
  return source.empty() ? std::filesystem::path(file)
                        : source.parent_path() / std::filesystem::path(file);
}

/// Format from the extension: .csv is CSV, anything else UFF58 (.uff, .unv).
FrfFileSpec::Format guessed_format(const std::filesystem::path& file) {
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".csv" ? FrfFileSpec::Format::csv : FrfFileSpec::Format::uff58;
}

FrfFileSpec read_frf_file(SectionReader& f, const std::filesystem::path& source,
                          std::optional<int> direction = std::nullopt) {
  f.allow_schema("dynamics.frf[]");
  FrfFileSpec spec;
  spec.path = f.path();
  spec.line = f.line();
  const auto file = f.optional_text("file");
  if (!file || file->empty())
    f.fail("file", "required field missing (path of a UFF58 or CSV file, relative to the job)");
  spec.file = job_relative(source, *file);
  const std::string guessed =
      guessed_format(spec.file) == FrfFileSpec::Format::csv ? "csv" : "uff58";
  spec.format = f.choice("format", {"uff58", "csv"}, guessed) == "csv" ? FrfFileSpec::Format::csv
                                                                       : FrfFileSpec::Format::uff58;
  spec.response_axis = read_axis(f, "response");
  spec.reference_axis = read_axis(f, "reference");
  if (direction) {
    // `frf: {x: {...}}`: the key is the measured direction (a driving point
    // unless `reference` says otherwise).
    if (spec.response_axis && *spec.response_axis != *direction)
      f.fail("response", "contradicts the direction this entry is listed under");
    spec.response_axis = direction;
    if (!spec.reference_axis)
      spec.reference_axis = direction;
  }
  if (const auto units = f.optional_text("units")) {
    Quantity unit;
    try {
      unit = parse_unit(*units);
    } catch (const std::invalid_argument& e) {
      f.fail("units", e.what());
    }
    if (unit.dimension == dimensions::receptance)
      spec.kind = dynamics::FrfKind::receptance;
    else if (unit.dimension == dimensions::mobility)
      spec.kind = dynamics::FrfKind::mobility;
    else if (unit.dimension == dimensions::accelerance)
      spec.kind = dynamics::FrfKind::accelerance;
    else
      f.fail("units", "'" + *units +
                          "' is not an FRF unit; expected a receptance (m/N, mm/N, um/N), a "
                          "mobility (m/s/N) or an accelerance (m/s^2/N)");
    spec.scale_to_si = unit.value_si;
  }
  if (spec.format == FrfFileSpec::Format::csv) {
    if (!spec.kind)
      f.fail("units", "required for CSV files (e.g. units: mm/N); it sets the FRF kind and scale");
    if (!spec.response_axis)
      f.fail("response", "required for CSV files: the measured direction, x, y or z");
    if (!spec.reference_axis)
      spec.reference_axis = spec.response_axis;  // a driving-point FRF
  }
  f.finish();
  return spec;
}

FitSettings read_fit(SectionReader& fit) {
  fit.allow_schema("dynamics.fit");
  FitSettings settings;
  settings.max_order = fit.integer_or("max_order", 2, 200, 0);
  if (auto bands = fit.sections("bands")) {
    for (SectionReader& b : *bands) {
      b.allow_schema("dynamics.fit.bands[]");
      FitSettings::Band band;
      band.low_hz = b.quantity("from", field(dimensions::frequency, 1.0, "Hz", kPositive));
      band.high_hz = b.quantity("to", field(dimensions::frequency, 1.0, "Hz", kPositive));
      if (!(band.high_hz > band.low_hz)) {
        b.fail("to", fmt::format("must exceed from ({:g} Hz)", band.low_hz));
      }
      band.max_order = b.integer_or("max_order", 2, 200, 0);
      b.finish();
      settings.bands.push_back(band);
    }
  }
  fit.finish();
  return settings;
}

/// `dynamics.postures` (001 §2.2.2): a list of {posture: [deg...], modes:
/// [...]}, every posture listing the same modes (direction, k or m) in the
/// same order; `at` and `idw: {power, joint_weights}` optional. The table is
/// interpolated later (resolve_posture_library), once robot.posture is known.
void read_posture_library(SectionReader& r, Job& job) {
  for (const char* key : {"modes", "frf", "fit", "use", "from_robot"}) {
    if (r.has(key)) {
      r.fail(key, "conflicts with dynamics.postures: the modes come from the posture library");
    }
  }
  PostureLibrary library;
  const QuantityField angle = field(dimensions::angle, kDeg, "deg");
  auto entries = r.sections("postures");
  if (entries->empty())
    r.fail("postures", "must list at least one measured posture {posture: [...], modes: [...]}");
  for (std::size_t i = 0; i < entries->size(); ++i) {
    SectionReader& e = (*entries)[i];
    e.allow_schema("dynamics.postures[]");
    const auto q = e.quantities("posture", angle);
    if (!q)
      e.fail("posture", "required: the joint angles of this measurement (deg by default)");
    if (!library.postures_rad.empty() &&
        static_cast<Eigen::Index>(q->size()) != library.postures_rad.front().size()) {
      e.fail("posture", fmt::format("has {} joint angles, the first posture {}", q->size(),
                                    library.postures_rad.front().size()));
    }
    library.postures_rad.push_back(Eigen::Map<const Eigen::VectorXd>(q->data(), q->size()));
    auto modes = e.sections("modes");
    if (!modes || modes->empty())
      e.fail("modes", "required: the modes measured at this posture");
    std::vector<ModeSpec> table;
    for (SectionReader& m : *modes) {
      table.push_back(read_mode(m));
      if (table.back().direction == 'v' || !table.back().shape.empty()) {
        m.fail(table.back().direction == 'v' ? "direction" : "shape",
               "a posture library takes modes along x, y or z with k or m (what is averaged "
               "between postures must mean the same at each)");
      }
    }
    const std::vector<ModeSpec>& first = library.tables.empty() ? table : library.tables.front();
    if (table.size() != first.size()) {
      e.fail("modes", fmt::format("lists {} modes, the first posture {}: every posture lists the "
                                  "same modes in the same order",
                                  table.size(), first.size()));
    }
    for (std::size_t k = 0; k < table.size(); ++k) {
      if (table[k].direction != first[k].direction) {
        e.fail("modes", fmt::format("mode {} is along {}, the first posture's along {}: every "
                                    "posture lists the same modes in the same order",
                                    k + 1, table[k].direction, first[k].direction));
      }
    }
    library.tables.push_back(std::move(table));
    e.finish();
  }
  if (auto at = r.quantities("at", angle, library.postures_rad.front().size())) {
    library.query_rad = Eigen::Map<const Eigen::VectorXd>(at->data(), at->size());
    library.query_source = "dynamics.at";
  }
  if (auto idw = r.section("idw")) {
    idw->allow_schema("dynamics.idw");
    library.idw.power = idw->quantity_or("power", dimensionless(kPositive), 1.0);
    if (auto w = idw->quantities("joint_weights", dimensionless(kNonNegative),
                                 library.postures_rad.front().size())) {
      library.idw.joint_weights = Eigen::Map<const Eigen::VectorXd>(w->data(), w->size());
      if (!(library.idw.joint_weights.maxCoeff() > 0.0))
        idw->fail("joint_weights", "must not all be zero");
    }
    idw->finish();
  }
  job.posture_library = std::move(library);
  job.dynamics_source = Job::DynamicsSource::postures;
  r.finish();
}

/// 001 Eq 16-18 at the query posture: fn and ζ averaged, k through the
/// compliance 1/k (interpolate_modal_tables), written into job.modes.
void resolve_posture_library(Job& job) {
  if (!job.posture_library)
    return;
  PostureLibrary& library = *job.posture_library;
  const auto dof = library.postures_rad.front().size();
  if (job.robot && static_cast<Eigen::Index>(job.robot->description.joints.size()) != dof) {
    throw InputError("dynamics.postures[0].posture", 0,
                     fmt::format("has {} joint angles but the robot has {} joints", dof,
                                 job.robot->description.joints.size()));
  }
  if (library.query_source.empty()) {
    if (!job.robot || job.robot->posture_rad.empty()) {
      throw InputError("dynamics.at", 0,
                       "required with dynamics.postures (or robot.posture): the posture to "
                       "interpolate the measured modes at");
    }
    library.query_rad = Eigen::Map<const Eigen::VectorXd>(job.robot->posture_rad.data(),
                                                          job.robot->posture_rad.size());
    library.query_source = "robot.posture";
  }
  std::vector<std::vector<robot::DirectionalModeParameters>> tables;
  for (const auto& table : library.tables) {
    std::vector<robot::DirectionalModeParameters> t;
    for (const ModeSpec& m : table) {
      t.push_back(
          {m.direction - 'x', m.natural_frequency_hz, m.damping_ratio, m.stiffness_n_per_m});
    }
    tables.push_back(std::move(t));
  }
  try {
    const robot::IdwResult weights =
        robot::idw_weights(library.postures_rad, library.query_rad, library.idw);
    library.weights = weights.weights;
    library.exact_index = weights.exact_index;
    const auto modes = robot::interpolate_modal_tables(library.postures_rad, tables,
                                                       library.query_rad, library.idw);
    job.modes.clear();
    for (const auto& m : modes) {
      ModeSpec spec;
      spec.direction = static_cast<char>('x' + m.axis);
      spec.direction_vector = Eigen::Vector3d::Unit(m.axis);
      spec.natural_frequency_hz = m.natural_frequency_hz;
      spec.damping_ratio = m.damping_ratio;
      spec.stiffness_n_per_m = m.stiffness_n_per_m;
      const double omega = 2.0 * kPi * m.natural_frequency_hz;
      spec.mass_kg = m.stiffness_n_per_m / (omega * omega);
      job.modes.push_back(spec);
    }
  } catch (const std::invalid_argument& error) {
    throw InputError("dynamics.postures", 0, error.what());
  }
}

void read_dynamics(SectionReader& root, Job& job) {
  auto section = root.section("dynamics");
  if (!section)
    return;
  SectionReader& r = *section;
  r.allow_schema("dynamics");
  if (r.has("postures")) {
    read_posture_library(r, job);
    return;
  }
  for (const char* key : {"at", "idw"}) {
    if (r.has(key))
      r.fail(key, "applies to dynamics.postures (modal tables measured at several postures)");
  }
  if (auto items = r.sections("modes")) {
    if (items->empty())
      r.fail("modes", "must list at least one mode");
    for (SectionReader& m : *items)
      job.modes.push_back(read_mode(m));
  }
  if (r.is_map("frf")) {
    // DESIGN.md's form, one file per measured direction: {x: file, y: file},
    // each a path or a map with the list form's keys.
    auto by_direction = r.section("frf");
    by_direction->allow_schema("dynamics.frf");
    for (const char* key : {"x", "y", "z"}) {
      const int axis = key[0] - 'x';
      if (by_direction->is_map(key)) {
        auto entry = by_direction->section(key);
        job.frf_files.push_back(read_frf_file(*entry, job.source, axis));
      } else if (auto file = by_direction->optional_text(key)) {
        FrfFileSpec spec;
        spec.path = by_direction->path_of(key);
        spec.line = by_direction->line_of(key);
        spec.file = job_relative(job.source, *file);
        spec.format = guessed_format(spec.file);
        if (spec.format == FrfFileSpec::Format::csv) {
          by_direction->fail(key, "a CSV file needs its units: write {file: " + *file +
                                      ", units: mm/N} (or m/s/N, m/s^2/N)");
        }
        spec.response_axis = spec.reference_axis = axis;
        job.frf_files.push_back(spec);
      }
    }
    by_direction->finish();
    if (job.frf_files.empty())
      r.fail("frf", "must name at least one FRF file ({x: file, y: file})");
  } else if (auto files = r.sections("frf")) {
    if (files->empty())
      r.fail("frf", "must list at least one FRF file");
    for (SectionReader& f : *files)
      job.frf_files.push_back(read_frf_file(f, job.source));
  }
  if (auto fit = r.section("fit"))
    job.fit = read_fit(*fit);
  if (r.boolean_or("from_robot", false)) {
    // The robot model at its posture (robot.posture) gives the modes.
    if (r.has("use"))
      r.fail("use", "conflicts with from_robot: true; give one of them");
    job.dynamics_source = Job::DynamicsSource::robot;
    r.finish();
    return;
  }
  const std::string fallback = job.modes.empty() && !job.frf_files.empty() ? "fit" : "table";
  const std::string use = r.choice("use", {"table", "fit", "frf"}, fallback);
  job.dynamics_source = use == "fit"   ? Job::DynamicsSource::fit
                        : use == "frf" ? Job::DynamicsSource::frf
                                       : Job::DynamicsSource::table;
  if (use == "table" && job.modes.empty())
    r.fail("use", "is 'table' but dynamics.modes is missing");
  if (use != "table" && job.frf_files.empty())
    r.fail("use", "is '" + use + "' but dynamics.frf lists no measured FRF file");
  r.finish();
}

/// `{xyz: [x, y, z], rpy: [roll, pitch, yaw]}` (mm and deg by default): a
/// frame as a translation and fixed-axis X-Y-Z rotations (URDF's convention).
Eigen::Isometry3d read_frame(SectionReader& f, std::string_view schema_section) {
  f.allow_schema(schema_section);
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  if (auto xyz = f.quantities("xyz", length_mm({}), 3))
    frame.translation() = Eigen::Vector3d((*xyz)[0], (*xyz)[1], (*xyz)[2]);
  if (auto rpy = f.quantities("rpy", field(dimensions::angle, kDeg, "deg"), 3)) {
    frame.linear() = (Eigen::AngleAxisd((*rpy)[2], Eigen::Vector3d::UnitZ()) *
                      Eigen::AngleAxisd((*rpy)[1], Eigen::Vector3d::UnitY()) *
                      Eigen::AngleAxisd((*rpy)[0], Eigen::Vector3d::UnitX()))
                         .toRotationMatrix();
  }
  f.finish();
  return frame;
}

RobotSettings read_robot_section(SectionReader& r, const std::filesystem::path& source) {
  r.allow_schema("robot");
  RobotSettings settings;
  robot::RobotDescription& d = settings.description;
  d.name = r.optional_text("name").value_or("robot");
  if (r.has("dh") == r.has("urdf"))
    r.fail_here("give the geometry either as a DH table (dh:) or as a URDF file (urdf:)");
  const QuantityField angle = field(dimensions::angle, kDeg, "deg");
  if (r.has("dh")) {
    // DESIGN.md: `dh` is a list of {a, alpha, d, theta} rows, theta the joint
    // offset; `convention` says which DH.
    robot::DhTable table;
    table.convention = r.choice("convention", {"standard", "modified"}, "standard") == "modified"
                           ? robot::DhConvention::modified
                           : robot::DhConvention::standard;
    auto rows = r.sections("dh");
    if (rows->empty())
      r.fail("dh", "required: one row {a, alpha, d, theta} per joint");
    for (SectionReader& row : *rows) {
      row.allow_schema("robot.dh[]");
      robot::DhRow entry;
      entry.a_m = row.quantity_or("a", length_mm({}), 0.0);
      entry.alpha_rad = row.quantity_or("alpha", angle, 0.0);
      entry.d_m = row.quantity_or("d", length_mm({}), 0.0);
      entry.theta_offset_rad = row.quantity_or("theta", angle, 0.0);
      row.finish();
      table.rows.push_back(entry);
    }
    d.dh = std::move(table);
  } else if (r.has("convention")) {
    r.fail("convention", "applies to a DH table (dh:), not to a URDF file");
  }
  if (auto urdf = r.section("urdf")) {
    urdf->allow_schema("robot.urdf");
    const auto file = urdf->optional_text("file");
    if (!file || file->empty())
      urdf->fail("file", "required field missing (path of the URDF file, relative to the job)");
    settings.urdf_file = source.empty() ? std::filesystem::path(*file)
                                        : source.parent_path() / std::filesystem::path(*file);
    robot::UrdfSource urdf_source;
    urdf_source.base_link = urdf->optional_text("base").value_or("");
    urdf_source.tip_link = urdf->optional_text("tip").value_or("");
    if (urdf_source.base_link.empty())
      urdf->fail("base", "required field missing (the chain's root link)");
    if (urdf_source.tip_link.empty())
      urdf->fail("tip", "required field missing (the flange link)");
    d.use_urdf_limits = urdf->boolean_or("limits_from_file", true);
    // Only regular files of sane size: a path such as /dev/zero must not hang
    // the parser (URDF files are kilobytes to a few megabytes).
    std::error_code error;
    const bool regular = std::filesystem::is_regular_file(settings.urdf_file, error);
    const auto bytes = regular ? std::filesystem::file_size(settings.urdf_file, error) : 0;
    if (!regular || error)
      urdf->fail("file", "cannot read '" + settings.urdf_file.string() + "' (not a regular file)");
    if (bytes > 64u * 1024u * 1024u)
      urdf->fail("file", "'" + settings.urdf_file.string() + "' is larger than 64 MiB");
    std::ifstream in(settings.urdf_file, std::ios::binary);
    if (!in)
      urdf->fail("file", "cannot read '" + settings.urdf_file.string() + "'");
    urdf_source.xml.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    urdf->finish();
    d.urdf = std::move(urdf_source);
  }
  // DESIGN.md: `joint_stiffness`, one value per joint (000 §6.1's Kq).
  const auto stiffness = r.quantities(
      "joint_stiffness", field(dimensions::rotational_stiffness, 1.0, "N*m/rad", kPositive));
  if (!stiffness)
    r.fail("joint_stiffness", "required: the torsional stiffness of every joint, N*m/rad");
  if (d.dh && stiffness->size() != d.dh->rows.size()) {
    r.fail("joint_stiffness",
           fmt::format("lists {} values but dh has {} rows", stiffness->size(), d.dh->rows.size()));
  }
  for (const double k : *stiffness) {
    robot::JointProperties joint;
    joint.stiffness_nm_per_rad = k;
    joint.damping_nms_per_rad = robot::kDeriveDamping;
    d.joints.push_back(joint);
  }
  if (auto joints = r.sections("joints")) {
    if (joints->size() != d.joints.size()) {
      r.fail("joints", fmt::format("lists {} joints; one per joint ({}) needed", joints->size(),
                                   d.joints.size()));
    }
    for (std::size_t i = 0; i < joints->size(); ++i) {
      SectionReader& j = (*joints)[i];
      j.allow_schema("robot.joints[]");
      robot::JointProperties& joint = d.joints[i];
      joint.lower_rad = j.quantity_or("lower", angle, joint.lower_rad);
      joint.upper_rad = j.quantity_or("upper", angle, joint.upper_rad);
      if (!(joint.upper_rad > joint.lower_rad))
        j.fail("upper", "must exceed lower");
      joint.damping_nms_per_rad = j.quantity_or(
          "damping", field(dimensions::rotational_damping, 1.0, "N*m*s/rad", kNonNegative),
          robot::kDeriveDamping);
      j.finish();
    }
  }
  if (auto links = r.sections("links")) {
    if (!d.dh)
      r.fail("links", "are read from the URDF file; give links only with a DH table");
    if (links->size() != d.joints.size())
      r.fail("links", fmt::format("lists {} links; one per joint ({}) needed", links->size(),
                                  d.joints.size()));
    for (SectionReader& l : *links) {
      l.allow_schema("robot.links[]");
      robot::LinkInertia link;
      link.mass_kg = l.quantity("mass", field(dimensions::mass, 1.0, "kg", kNonNegative));
      if (auto cog = l.quantities("cog", length_mm({}), 3))
        link.center_of_mass_m = Eigen::Vector3d((*cog)[0], (*cog)[1], (*cog)[2]);
      if (auto inertia =
              l.quantities("inertia", field(dimensions::moment_of_inertia, 1.0, "kg*m^2"))) {
        // [Ixx, Iyy, Izz] (principal axes along the link frame) or
        // [Ixx, Iyy, Izz, Ixy, Ixz, Iyz], about the centre of mass.
        const auto& v = *inertia;
        if (v.size() != 3 && v.size() != 6)
          l.fail("inertia", "expected [Ixx, Iyy, Izz] or [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] in kg*m^2");
        link.inertia_kg_m2.diagonal() << v[0], v[1], v[2];
        if (v.size() == 6) {
          link.inertia_kg_m2(0, 1) = link.inertia_kg_m2(1, 0) = v[3];
          link.inertia_kg_m2(0, 2) = link.inertia_kg_m2(2, 0) = v[4];
          link.inertia_kg_m2(1, 2) = link.inertia_kg_m2(2, 1) = v[5];
        }
      }
      l.finish();
      d.dh->links.push_back(link);
    }
  }
  d.modal_damping_ratio =
      r.quantity_or("damping_ratio", dimensionless(kNonNegative, Bound{1.0, false}), 0.0);
  if (auto base = r.section("base"))
    d.base = read_frame(*base, "robot.base");
  if (auto tool = r.section("tool"))
    d.flange_to_tool = read_frame(*tool, "robot.tool");
  if (auto posture =
          r.quantities("posture", field(dimensions::angle, kDeg, "deg"), d.joints.size()))
    settings.posture_rad = *posture;
  if (auto frf = r.section("frf")) {
    frf->allow_schema("robot.frf");
    settings.frf_from_hz =
        frf->quantity_or("from", field(dimensions::frequency, 1.0, "Hz", kPositive), 0.0);
    settings.frf_to_hz =
        frf->quantity_or("to", field(dimensions::frequency, 1.0, "Hz", kPositive), 0.0);
    if (settings.frf_from_hz > 0.0 && settings.frf_to_hz > 0.0 &&
        !(settings.frf_to_hz > settings.frf_from_hz))
      frf->fail("to", "must exceed from");
    settings.frf_points = frf->integer_or("points", 2, 1000000, settings.frf_points);
    frf->finish();
  }
  if (auto map = r.section("map")) {
    map->allow_schema("robot.map");
    RobotSettings::Map grid;
    const auto from = map->quantities("from", length_mm({}), 3);
    const auto to = map->quantities("to", length_mm({}), 3);
    if (!from)
      map->fail("from", "required: the grid's first corner [x, y, z] in the cell frame");
    if (!to)
      map->fail("to", "required: the grid's opposite corner [x, y, z]");
    grid.from_m = Eigen::Vector3d((*from)[0], (*from)[1], (*from)[2]);
    grid.to_m = Eigen::Vector3d((*to)[0], (*to)[1], (*to)[2]);
    // [nx, ny, nz] point counts.
    if (auto counts = map->integers("counts", 3, 1, 1000))
      std::copy(counts->begin(), counts->end(), grid.counts.begin());
    if (static_cast<long>(grid.counts[0]) * grid.counts[1] * grid.counts[2] > 1000000)
      map->fail("counts", "more than 1 000 000 grid points");
    grid.tool_axis = map->unit_vector_or("tool_axis", grid.tool_axis);
    grid.feed = map->unit_vector_or("feed", grid.feed);
    // The feed lies in the cutting plane: remove its component along the tool axis.
    grid.feed -= grid.feed.dot(grid.tool_axis) * grid.tool_axis;
    if (!(grid.feed.norm() > 1e-9))
      map->fail("feed", "must not be parallel to tool_axis");
    grid.feed.normalize();
    grid.redundancy_rad =
        map->quantity_or("redundancy", field(dimensions::angle, kDeg, "deg"), 0.0);
    map->finish();
    settings.map = grid;
  }
  r.finish();
  return settings;
}

std::optional<StabilitySettings> read_stability(SectionReader& root,
                                                const std::optional<tool::ToolSpec>& tool,
                                                const std::vector<ModeSpec>& modes,
                                                Job::DynamicsSource source) {
  auto section = root.section("stability");
  if (!section)
    return std::nullopt;
  SectionReader& r = *section;
  r.allow_schema("stability");
  using Settings = StabilitySettings;
  Settings settings;

  const std::string method = r.choice("method", {"zoa", "sdm", "fdm", "fdm2"}, "fdm");
  settings.method = method == "zoa"   ? Settings::Method::zoa
                    : method == "sdm" ? Settings::Method::sdm
                    : method == "fdm" ? Settings::Method::fdm
                                      : Settings::Method::fdm2;
  settings.mode = r.choice("mode", {"boundary", "map"}, "boundary") == "map"
                      ? Settings::Mode::map
                      : Settings::Mode::boundary;
  const std::string which = r.choice("modes", {"coupled", "envelope", "both"}, "coupled");
  settings.modes = which == "coupled"    ? Settings::Modes::coupled
                   : which == "envelope" ? Settings::Modes::envelope
                                         : Settings::Modes::both;

  const QuantityField rpm = field(dimensions::angular_speed, kRpm, "rpm", kPositive);
  auto speeds = r.section("speeds");
  if (!speeds) {
    r.fail("speeds", "required field missing (the spindle-speed range {from, to, count}, in rpm)");
  }
  speeds->allow_schema("stability.speeds");
  settings.speed_from_rad_s = speeds->quantity("from", rpm);
  const std::optional<double> to = speeds->optional_quantity("to", rpm);
  settings.speed_count = speeds->integer("count", 1, 100000);
  speeds->finish();
  if (settings.speed_count == 1) {
    // One speed: `to` may be left out; if given it must name the same speed.
    settings.speed_to_rad_s = to.value_or(settings.speed_from_rad_s);
    if (std::abs(settings.speed_to_rad_s - settings.speed_from_rad_s) >
        1e-9 * settings.speed_from_rad_s) {
      speeds->fail("to",
                   "with count 1 there is a single speed; leave out `to` or give it equal "
                   "to from (" +
                       detail::format_in_unit(settings.speed_from_rad_s, rpm) + "), got " +
                       detail::format_in_unit(settings.speed_to_rad_s, rpm));
    }
  } else {
    if (!to) {
      speeds->fail("to",
                   "required field missing (angular speed, in rpm by default; only a "
                   "single speed, count 1, may leave it out)");
    }
    settings.speed_to_rad_s = *to;
    if (!(settings.speed_to_rad_s > settings.speed_from_rad_s)) {
      speeds->fail("to", "must be greater than from (" +
                             detail::format_in_unit(settings.speed_from_rad_s, rpm) + "), got " +
                             detail::format_in_unit(settings.speed_to_rad_s, rpm));
    }
  }

  settings.depth_max_m = r.quantity("depth_max", length_mm());
  if (tool && settings.depth_max_m > tool->overhang_m * (1.0 + 1e-9)) {
    r.fail("depth_max", "depth search limit " +
                            detail::format_in_unit(settings.depth_max_m, length_mm()) +
                            " exceeds the tool overhang " +
                            detail::format_in_unit(tool->overhang_m, length_mm()));
  }
  settings.depth_count = r.integer_or("depths", 2, 100000, settings.depth_count);
  settings.depth_tolerance = r.quantity_or(
      "depth_tolerance", dimensionless(kPositive, Bound{0.1, true}), settings.depth_tolerance);
  settings.discretization = r.integer_or("discretization", 4, 10000, settings.discretization);
  settings.continuation = r.boolean_or("continuation", settings.continuation);
  // 000 §4-5: the diagrams with the deformation-corrected engagement too.
  settings.deformation = r.boolean_or("deformation", false);
  if (settings.deformation && settings.method == Settings::Method::zoa) {
    r.fail("deformation",
           "needs a time-domain method (sdm, fdm or fdm2): 000 solves its multipoint model by "
           "full discretization");
  }

  if (auto damping = r.section("process_damping")) {
    damping->allow_schema("stability.process_damping");
    settings.process_damping =
        damping->choice("model", {"linear_equivalent", "energy_balance"}) == "energy_balance"
            ? Settings::Damping::energy_balance
            : Settings::Damping::linear_equivalent;
    // 000 Eq 18-19: indentation coefficient, flank wear land, friction.
    settings.indentation_n_per_m3 =
        damping->quantity("Ksp", field(dimensions::force_per_volume, 1.0, "N/m^3", kPositive));
    settings.wear_land_m =
        damping->quantity("wear_land", field(dimensions::length, 1e-6, "um", kPositive));
    settings.friction = damping->quantity_or("mu", dimensionless(kNonNegative), 0.3);
    damping->finish();
  }
  r.finish();

  if (source == Job::DynamicsSource::frf && settings.method != Settings::Method::zoa) {
    r.fail("method",
           "dynamics.use is 'frf' (measured FRFs directly), which only the zero-order method "
           "(zoa) can use; set method: zoa, or dynamics.use: fit for the time-domain methods");
  }
  if (source == Job::DynamicsSource::frf && settings.modes != Settings::Modes::coupled) {
    r.fail("modes",
           "the envelope of one-mode diagrams needs modes; with dynamics.use: frf the measured "
           "FRFs are used whole (modes: coupled), or set dynamics.use: fit");
  }
  if (source == Job::DynamicsSource::frf && settings.process_damping != Settings::Damping::none) {
    r.fail("process_damping",
           "process damping is added per mode (003 §3.2) and needs modes; with measured FRFs "
           "use dynamics.use: fit");
  }
  if (modes.empty() && source == Job::DynamicsSource::table) {
    r.fail_here(
        "the stability command needs dynamics.modes (the structure's modal table) or measured "
        "FRFs (dynamics.frf); add a dynamics: section");
  }
  // Time-domain discretizations step through the tooth period τ = 60/(N n) in
  // m steps of h = τ/m; h is largest at the lowest speed. At least two steps
  // per period of the highest mode (h · f_max <= 0.5), otherwise that mode is
  // aliased: m >= 2 f_max τ_max. ZOA has no time step.
  if (tool && settings.method != Settings::Method::zoa) {
    double f_max = 0.0;
    for (const ModeSpec& mode : modes)
      f_max = std::max(f_max, mode.natural_frequency_hz);
    const double tau_max = 2.0 * kPi / (tool->teeth * settings.speed_from_rad_s);
    const double needed = 2.0 * f_max * tau_max;
    if (settings.discretization < needed * (1.0 - 1e-12)) {
      const double minimum = std::ceil(needed * (1.0 - 1e-12));
      const std::string fix = minimum <= 10000
                                  ? "; raise it or use method zoa"
                                  : ", beyond the limit of 10000: raise speeds.from or use "
                                    "method zoa";
      r.fail("discretization",
             fmt::format("{} steps per tooth period{} are too coarse for the {:g} Hz mode at "
                         "{:g} rpm with {} teeth: two steps per period of that mode need a "
                         "discretization of at least {:.0f}{}",
                         settings.discretization, r.has("discretization") ? "" : " (the default)",
                         f_max, settings.speed_from_rad_s / kRpm, tool->teeth, minimum, fix));
    }
  }
  return settings;
}

std::vector<Experiment> read_experiments(SectionReader& root) {
  std::vector<Experiment> experiments;
  auto items = root.sections("experiments");
  if (!items)
    return experiments;
  for (SectionReader& e : *items) {
    e.allow_schema("experiments[]");
    Experiment experiment;
    experiment.spindle_rad_s =
        e.quantity("spindle", field(dimensions::angular_speed, kRpm, "rpm", kPositive));
    experiment.axial_depth_m = e.quantity("depth", length_mm());
    experiment.chatter = e.boolean("chatter");
    e.finish();
    experiments.push_back(experiment);
  }
  return experiments;
}

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
        pos < text.size() ? "'" + std::string(1, text[pos]) + "'" : "end of input";
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
  job.tool = read_tool(root);
  job.cutting = read_cutting(root);
  job.process = read_process(root, job.tool);
  job.forces = read_forces(root, job.tool);
  read_dynamics(root, job);
  if (auto robot = root.section("robot"))
    job.robot = read_robot_section(*robot, source);
  resolve_posture_library(job);
  job.stability = read_stability(root, job.tool, job.modes, job.dynamics_source);
  job.experiments = read_experiments(root);
  detail::read_planning(root, job);    // workpiece, path, optimize (job_parser_planning.cpp)
  detail::read_simulation(root, job);  // simulation (job_parser_simulation.cpp)
  detail::read_deflection(root, job);  // 000 §2-4 (job_parser_deflection.cpp)
  detail::read_atlas(root, job);       // issue 11 (job_parser_atlas.cpp)
  detail::read_surface(root, job);     // 001 §2.4 (job_parser_surface.cpp)
  detail::read_toolpath(root, job);    // program and stock (job_parser_toolpath.cpp)
  detail::read_monitoring(root, job);  // recordings (job_parser_monitoring.cpp)
  job.output = read_output(root);
  root.finish();
  return job;
}

}  // namespace

Job parse_job(std::string_view yaml_text, const std::filesystem::path& source_name,
              const std::vector<Override>& overrides) {
  const std::string source = source_name.empty() ? std::string("job") : source_name.string();
  guard_input(yaml_text, source);

  const std::string text(yaml_text);
  YAML::Node root;
  try {
    check_single_document(text, source);
    root = YAML::Load(text);
  } catch (const YAML::ParserException& error) {
    throw InputError(source, error.mark.line >= 0 ? error.mark.line + 1 : 0,
                     "YAML syntax error: " + error.msg);
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
      apply_override(root, override_, provenance);
    return read_job(root, source_name, provenance);
  } catch (const YAML::Exception& error) {
    // The reader avoids conversions that throw; this is a safety net so that
    // a yaml-cpp surprise is still reported as bad input, not as a crash.
    throw InputError(source, error.mark.line >= 0 ? error.mark.line + 1 : 0,
                     "cannot read the job: " + error.msg);
  }
}

}  // namespace robomill::io
