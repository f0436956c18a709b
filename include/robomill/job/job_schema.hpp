#pragma once
// The job file's schema: every field the job parser accepts, one table.
//
// The parser takes each section's accepted keys from this table
// (SectionReader::allow_schema), so it cannot accept a key the table lacks;
// docs/job-reference.md is generated from the same table (`make docs`), so the
// reference lists every accepted field and nothing else.
//
// Sections are named by their path in the job with `[]` for the items of a
// list (`dynamics.modes[]`) and `[key=value]` for a variant whose keys depend
// on another field (`cutting[law=linear]`); the top level is "job".

#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace robomill::job::schema {

/// How a field's value is written.
enum class Kind {
  quantity,    ///< a number with an optional unit (`4 mm`); bare numbers in `unit`
  quantities,  ///< a list of quantities (`[0, 0, 250 mm]`)
  integer,     ///< a whole number
  integers,    ///< a list of whole numbers
  boolean,     ///< true / false (also yes/no, on/off)
  text,        ///< free text or a file path
  choice,      ///< one of `values`
  choices,     ///< a list of words from `values`
  map,         ///< a nested section (its own table)
  list,        ///< a list of maps (each item its own table)
  variant,     ///< one of several forms, said in the description
};

struct Field {
  std::string_view section;  ///< e.g. "tool", "dynamics.modes[]", "cutting[law=linear]"
  std::string_view key;      ///< e.g. "diameter"
  Kind kind = Kind::quantity;
  std::string_view unit;           ///< the unit of bare numbers ("mm"), "" when none
  std::string_view values;         ///< allowed values or range ("flat, ball", "> 0", "1 … 20")
  std::string_view default_value;  ///< "" when there is none
  std::string_view required;       ///< "yes", a condition ("with model 1dof, 2dof, 3dof"), or ""
  std::string_view description;    ///< one line
};

struct Section {
  std::string_view id;           ///< as Field::section
  std::string_view description;  ///< a short paragraph for the reference
};

/// Every field, grouped by section in reference order.
std::span<const Field> fields();
/// Every section, in reference order.
std::span<const Section> sections();

/// The keys of `section`, in table order; throws std::logic_error for a
/// section the table does not have (a parser bug, never a user error).
const std::vector<std::string_view>& keys(std::string_view section);

/// "tool.diameter", "dynamics.modes[].fn", "cutting.Ktc" (the variant dropped).
std::string path(const Field& field);

/// The unit's dimension in words ("length"), "" for fields without a unit.
std::string dimension(const Field& field);

/// docs/job-reference.md.
std::string markdown();

/// While one is alive on this thread, every field the parser reads is
/// recorded as "section.key" (the schema's section id), and a parser that
/// reads a key its section does not list throws std::logic_error. For tests:
/// every schema field must be read by some job.
class CoverageRecorder {
 public:
  CoverageRecorder();
  ~CoverageRecorder();
  CoverageRecorder(const CoverageRecorder&) = delete;
  CoverageRecorder& operator=(const CoverageRecorder&) = delete;
  const std::set<std::string>& read() const noexcept { return read_; }
  /// Called by the parser: `key` of schema section `section` was read.
  void note(std::string_view section, std::string_view key);

 private:
  std::set<std::string> read_;
  CoverageRecorder* previous_ = nullptr;
};

namespace detail {
/// The active recorder of this thread, or nullptr.
CoverageRecorder* active_recorder() noexcept;
}  // namespace detail

}  // namespace robomill::job::schema
