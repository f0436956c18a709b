#pragma once
// Private to the job parser: the `simulation:` section of `robomill simulate`
// (docs/job-reference.md, "simulation").

#include "robomill/job/job.hpp"
#include "yaml_reader.hpp"

namespace robomill::job::detail {

/// Reads `simulation` from the job's top level into `job` (after the tool,
/// process, dynamics and robot sections, which it cross-checks). Throws
/// InputError naming the field and line.
void read_simulation(SectionReader& root, Job& job);

}  // namespace robomill::job::detail
