#pragma once
// Private to the job parser: the `toolpath:` and `stock:` sections of
// `robomill toolpath` (docs/toolpath.md), and the tool fields they share with
// the job's `tool:`.

#include "robomill/job/job.hpp"
#include "yaml_reader.hpp"

namespace robomill::job::detail {

/// Reads `toolpath` and `stock` from the job's top level into `job` (after
/// the tool section). Throws InputError naming the field and line.
void read_toolpath(SectionReader& root, Job& job);

}  // namespace robomill::job::detail
