// The SectionReader (yaml_reader.hpp): typed, strict access to one map of a
// job, every error naming the field's path and line, and the provenance of
// values set by --set.

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
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "quantity_fields.hpp"
#include "robomill/core/error.hpp"
#include "robomill/core/text.hpp"
#include "robomill/job/job.hpp"
#include "robomill/job/job_schema.hpp"
#include "robomill/job/units.hpp"
#include "yaml_reader.hpp"

namespace robomill::job {
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

std::string flow_index_hint(std::string_view line) {
  // A word character, then [digits]: a list index inside a plain scalar.
  static const std::regex indexed_path(R"(\w\[\s*\d+\s*\])");
  const std::string text(line);
  if (text.find_first_of("{[") == std::string::npos || !std::regex_search(text, indexed_path))
    return "";
  return "; inside { } or [ ], a path with list indices must be quoted "
         "('dynamics.modes[0].k') or written with dots (dynamics.modes.0.k)";
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

}  // namespace robomill::job
