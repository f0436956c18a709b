#pragma once
// Private to the job parser: the `atlas:` section (issue 11, docs/atlas.md).

#include "robomill/job/job.hpp"
#include "yaml_reader.hpp"

namespace robomill::job::detail {

/// Reads `atlas` into job.atlas (after the robot, tool, cutting and process
/// sections, which it is checked against). Throws InputError naming the
/// field and line.
void read_atlas(SectionReader& root, Job& job);

}  // namespace robomill::job::detail
