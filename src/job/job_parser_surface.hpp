#pragma once
// Private to the job parser: the `surface:` section of `robomill surface`
// (docs/surface.md, 001 §2.4).

#include "robomill/job/job.hpp"
#include "yaml_reader.hpp"

namespace robomill::job::detail {

/// Reads `surface` from the job's top level into `job` (after the tool and
/// process sections). Throws InputError naming the field and line.
void read_surface(SectionReader& root, Job& job);

}  // namespace robomill::job::detail
