// `--set key.path=value` applied to the job's YAML tree before it is read,
// and the guard every YAML text passes before yaml-cpp sees it.

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <optional>
#include <string>
#include <vector>

#include "job_overrides.hpp"
#include "robomill/core/error.hpp"
#include "robomill/core/text.hpp"
#include "robomill/job/job_schema.hpp"

namespace robomill::job::detail {
namespace {

// Cheap guards run before yaml-cpp sees the text. yaml-cpp parses nested
// collections recursively; pathological nesting ("[[[[...", "- - - - ...")
// exhausts the stack (notably under sanitizers) before its own depth guard
// trips. No job needs more than a handful of levels, so anything beyond
// kMaxDepth is rejected. The scan is deliberately conservative: brackets are
// counted even inside quoted strings, so a name with 65 unmatched '[' is
// rejected too — a false positive nobody will meet, never a false negative.
constexpr std::size_t kMaxJobBytes = 1 << 20;
constexpr int kMaxDepth = 64;

}  // namespace

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

namespace {

bool is_key_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

using text::is_digit;

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

}  // namespace

KeyPath split_key_path(std::string_view path) {
  KeyPath split;
  const auto fail = [&](std::size_t at) {
    split.error_at = at;
    // "-1" where a name or an index belongs: indices start at 0.
    if (at < path.size() && path[at] == '-') {
      std::size_t end = at + 1;
      while (end < path.size() && is_digit(path[end]))
        ++end;
      if (end > at + 1)
        split.negative_index = std::string(path.substr(at, end - at));
    }
    return split;
  };
  std::size_t i = 0;
  while (true) {
    const std::size_t start = i;
    while (i < path.size() && is_key_char(path[i]))
      ++i;
    if (i == start)
      return fail(i);
    split.steps.push_back(make_step(path.substr(start, i - start), false));
    while (i < path.size() && path[i] == '[') {
      const std::size_t digits_start = ++i;
      while (i < path.size() && is_digit(path[i]))
        ++i;
      if (i == digits_start || i >= path.size() || path[i] != ']')
        return fail(digits_start);
      split.steps.push_back(make_step(path.substr(digits_start, i - digits_start), true));
      ++i;
    }
    if (i == path.size())
      return split;
    if (path[i] != '.')
      return fail(i);
    ++i;
  }
}

namespace {

// "dynamics.modes[0].fn" → {dynamics, modes, [0], fn}; "dynamics.modes.0.fn"
// → {dynamics, modes, 0, fn}. Malformed paths throw, naming the override.
std::vector<PathStep> split_path(const Override& override_, const std::string& where) {
  KeyPath split = split_key_path(override_.path);
  if (!split.error_at)
    return std::move(split.steps);
  if (!split.negative_index.empty()) {
    throw InputError(override_.path, 0,
                     "invalid key path in `" + where + "`: list indices count from 0, got " +
                         split.negative_index + " (from --set)");
  }
  throw InputError(override_.path, 0,
                   "invalid key path in `" + where +
                       "`; expected dotted names such as process.ae, dynamics.modes.0.fn or "
                       "dynamics.modes[0].fn (from --set)");
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
}  // namespace

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
                     "value of `" + where + "` is not valid YAML: " + error.msg +
                         detail::flow_index_hint(override_.value) + " (from --set)");
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

FoundNode find_node(const YAML::Node& root, std::string_view path) {
  FoundNode found;
  const KeyPath split = split_key_path(path);
  if (split.error_at) {
    found.problem = !split.negative_index.empty()
                        ? "list indices count from 0, got " + split.negative_index
                        : std::string(
                              "is not a key path; expected dotted names such as "
                              "dynamics.modes[0].k or cutting.Ktc");
    return found;
  }
  YAML::Node current = root;
  for (const PathStep& step : split.steps) {
    if (step.bracket || (step.digits && current.IsSequence())) {
      if (!current.IsSequence()) {
        found.problem = "indexes " + (found.path.empty() ? std::string("the job") : found.path) +
                        ", which is " + describe_node(current) + ", not a list";
        return found;
      }
      if (step.index >= current.size()) {
        found.problem = fmt::format("index {} is out of range: {} has {}", step.text, found.path,
                                    entries(current.size()));
        return found;
      }
      std::size_t position = 0;
      for (auto it = current.begin(); it != current.end(); ++it, ++position) {
        if (position == step.index) {
          current.reset(*it);
          break;
        }
      }
      found.path += "[" + std::to_string(step.index) + "]";
      continue;
    }
    const std::string next = found.path.empty() ? step.text : found.path + "." + step.text;
    std::optional<YAML::Node> child =
        current.IsMap() ? map_child(current, step.text) : std::optional<YAML::Node>();
    if (!current.IsMap() || !child || child->IsNull()) {
      found.problem = current.IsMap() ? "the job has no " + next
                                      : (found.path.empty() ? std::string("the job") : found.path) +
                                            " is " + describe_node(current) + ", not a section";
      found.path = next;
      return found;
    }
    current.reset(*child);
    found.path = next;
  }
  found.node = current;
  return found;
}

}  // namespace robomill::job::detail
