#pragma once
// Private to the job parser: typed, strict reading of one YAML map.
//
// A SectionReader wraps one map of the job (`tool:`, `dynamics.modes[1]`) and
// reads fields by kind (quantity with a dimension, bounded integer, boolean,
// choice, text, nested section, list of sections). Every failure becomes an
// InputError naming the dotted field path and the line, so the section parsers
// in job_parser.cpp contain only the schema, not error plumbing. The reader
// also records which keys were read: a key that no parser read is reported as
// unknown, never silently ignored (a typo such as `teth:` must not fall back to
// a default).

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>

#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "robomill/core/error.hpp"
#include "robomill/job/units.hpp"

namespace robomill::job::detail {

/// Which fields of the tree were replaced by `--set`. Nodes that came from a
/// command-line value carry marks of their own one-line document, which would
/// be misreported as line 1 of the job; errors in them get line 0 and the note
/// "(from --set)" instead.
class Provenance {
 public:
  void mark_overridden(std::string path);
  /// True when `path` or one of its ancestors was set by an override.
  bool overridden(std::string_view path) const;
  /// The 1-based line of `node` for a field at `path`, 0 when unknown.
  int line(const YAML::Node& node, std::string_view path) const;
  /// " (from --set)" for overridden paths, "" otherwise.
  std::string note(std::string_view path) const;

 private:
  std::vector<std::string> paths_;
};

/// One end of an admissible interval, in SI.
struct Bound {
  double value = 0.0;
  bool inclusive = true;
};

/// How a quantity field is read: its dimension, the documented unit applied to
/// bare numbers (and used to print values back), and its admissible range.
struct QuantityField {
  Dimension dimension;
  double unit_si = 1.0;   ///< SI value of one documented unit
  std::string_view unit;  ///< its spelling, "" for dimensionless fields
  std::optional<Bound> min;
  std::optional<Bound> max;
};

/// "12.5 mm" for an SI value printed in the field's documented unit.
std::string format_in_unit(double value_si, const QuantityField& field);

/// "a map", "a list", "the value 'abc'", "nothing" — for type errors.
std::string describe_node(const YAML::Node& node);

/// What to add to a YAML syntax error on `line` when it is the usual trap
/// of the uncertainty section: a field path with list indices written
/// unquoted inside a flow map or list ({name: k, path: dynamics.modes[0].k}),
/// where `[` opens a list. "" when the line shows no such path.
std::string flow_index_hint(std::string_view line);

class SectionReader {
 public:
  /// `node` must be a map (or null, read as an empty map); otherwise this
  /// throws an InputError at `path`. `line` is where the section starts (the
  /// line of its key), used for errors about the section as a whole.
  SectionReader(const YAML::Node& node, std::string path, int line, const Provenance& provenance);

  /// Declares that this map is the job schema's section `schema_section`
  /// (include/robomill/job/job_schema.hpp: "tool", "dynamics.modes[]",
  /// "cutting[law=linear]"): it accepts exactly that section's keys. The
  /// first other key is reported at once, before any field is read, so a typo
  /// is reported as such rather than as the "missing field" it causes. Keys in
  /// `unsupported` are recognised but not implemented: they get
  /// `unsupported_message`. `context` qualifies the list ("for law 'linear'").
  void allow_schema(std::string_view schema_section,
                    std::initializer_list<std::string_view> unsupported = {},
                    std::string_view unsupported_message = {}, std::string_view context = {});

  bool has(std::string_view key) const;
  /// Every key of the map, in the file's order (for maps keyed by the user:
  /// `toolpath.tools: {T1: ..., T2: ...}`).
  std::vector<std::string> keys() const;
  /// True when the key is present and holds a list (for fields that take
  /// either a word or a list, such as a mode's direction).
  bool is_list(std::string_view key) const;
  bool is_map(std::string_view key) const;

  double quantity(std::string_view key, const QuantityField& field);
  std::optional<double> optional_quantity(std::string_view key, const QuantityField& field);
  double quantity_or(std::string_view key, const QuantityField& field, double default_si);

  /// A list of quantities (`xyz: [0, 0, 250 mm]`), each with its unit or in
  /// the field's; `count` > 0 requires that many. Errors name the item.
  std::optional<std::vector<double>> quantities(std::string_view key, const QuantityField& field,
                                                std::size_t count = 0);
  /// A direction: three numbers, returned normalized; `fallback` when the key
  /// is absent. A zero vector is an error naming the key.
  Eigen::Vector3d unit_vector_or(std::string_view key, const Eigen::Vector3d& fallback);

  int integer(std::string_view key, int min, int max);
  int integer_or(std::string_view key, int min, int max, int default_value);

  bool boolean(std::string_view key);
  bool boolean_or(std::string_view key, bool default_value);

  /// One of `options`; `default_value` empty makes the field required.
  std::string choice(std::string_view key, std::initializer_list<std::string_view> options,
                     std::string_view default_value = {});

  std::optional<std::string> optional_text(std::string_view key);

  /// A nested map; nullopt when absent. `key: ` with no value is an empty map.
  std::optional<SectionReader> section(std::string_view key);

  /// A list of maps (`modes:`); nullopt when absent. Each item is a reader
  /// with path `key[i]`.
  std::optional<std::vector<SectionReader>> sections(std::string_view key);

  /// A list of plain values (`formats: [csv, json]`), each with its path and line.
  struct Item {
    std::string text;
    std::string path;
    int line = 0;
  };
  std::optional<std::vector<Item>> texts(std::string_view key);
  /// A list of exactly `count` integers in [min, max] (`counts: [4, 3, 1]`),
  /// each error naming the element; nullopt when the key is absent.
  std::optional<std::vector<int>> integers(std::string_view key, std::size_t count, int min,
                                           int max);

  /// Reports any key that was not read (see the class comment).
  void finish();

  /// Throws an InputError for the field `key` of this section, at the key's
  /// line (the section's line when the key is absent).
  [[noreturn]] void fail(std::string_view key, const std::string& message) const;
  /// Throws an InputError for the section itself.
  [[noreturn]] void fail_here(const std::string& message) const;

  const std::string& path() const noexcept { return path_; }
  int line() const noexcept { return line_; }
  std::string path_of(std::string_view key) const;
  /// The path for messages: "job" for the top level, whose path is "".
  std::string display_path() const;
  int line_of(std::string_view key) const;

 private:
  struct Entry {
    std::string key;
    YAML::Node key_node;
    YAML::Node value;
    int line = 0;
    bool read = false;
  };

  const Entry* find(std::string_view key) const;
  /// The entry of a present key with a value, marked read; nullopt-like null
  /// when absent. A key given without a value (`helix:`) is an error.
  const Entry* take_value(std::string_view key);
  const std::string& scalar(const Entry& entry, std::string_view expected) const;
  double read_quantity(const Entry& entry, const QuantityField& field) const;
  /// The SI value of `text` for `field`, or 0 with `problem` set.
  double quantity_in_field(const std::string& text, const QuantityField& field,
                           std::string_view key, std::string& problem) const;
  int read_integer(const Entry& entry, int min, int max) const;
  bool read_boolean(const Entry& entry) const;
  [[noreturn]] void unknown_key(const Entry& entry, std::string_view message) const;
  /// For a schema::CoverageRecorder (tests): records that `key` was read and
  /// checks that the schema section lists it.
  void note_read(std::string_view key) const;

  std::string path_;
  int line_ = 0;
  const Provenance* provenance_ = nullptr;
  std::vector<Entry> entries_;
  std::vector<std::string_view> allowed_;
  std::string context_;
  std::string_view schema_section_;
};

}  // namespace robomill::job::detail
