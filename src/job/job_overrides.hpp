#pragma once
// Private to the job parser: `--set` overrides and the input guard.

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "robomill/job/job.hpp"
#include "yaml_reader.hpp"

namespace robomill::job::detail {

/// One step of a --set key path as written: a name (`modes`, `T3`, `0`) or a
/// bracket index (`[0]`). A name of digits indexes a list when the node it
/// steps into is a list (`dynamics.modes.0.zeta`) and is a key otherwise
/// (`toolpath.bases.1`, a map keyed by numbers).
struct PathStep {
  std::string text;       ///< the name, or the index's digits
  bool bracket = false;   ///< written `[n]`: always an index
  bool digits = false;    ///< only digits: an index where the node is a list
  std::size_t index = 0;  ///< its value when `digits`; SIZE_MAX when it overflows
};

/// A key path split by its grammar: dotted names of [A-Za-z0-9_], each
/// optionally followed by [index]s (process.ae, dynamics.modes[0].fn,
/// dynamics.modes.0.fn). parse_override checks --set with it, apply_override
/// walks the YAML tree with its steps.
struct KeyPath {
  std::vector<PathStep> steps;
  std::optional<std::size_t> error_at;  ///< where the grammar breaks; nullopt: a key path
  std::string negative_index;           ///< "-1" written at error_at, else ""
};
KeyPath split_key_path(std::string_view path);

/// Rejects a YAML text yaml-cpp must not see: over 1 MiB, or nested deeper
/// than any job needs (yaml-cpp recurses per level). InputError naming `source`.
void guard_input(std::string_view text, const std::string& source);

/// Applies one `--set key.path=value` to the YAML tree (list entries by
/// index), recording in `provenance` that the value came from --set.
void apply_override(YAML::Node& root, const Override& override_, Provenance& provenance);

/// What a key path (as --set writes it) leads to in the YAML tree, found the
/// way apply_override walks it but creating nothing (the `uncertainty:`
/// section's paths).
struct FoundNode {
  std::optional<YAML::Node> node;  ///< the node at the path; nullopt when it leads nowhere
  std::string path;                ///< the path in the reader's bracket form, as far as walked
  std::string problem;             ///< why it leads nowhere; "" when found
};
FoundNode find_node(const YAML::Node& root, std::string_view path);

}  // namespace robomill::job::detail
