#pragma once
// Private to the job parser: the planning sections (`workpiece:`, `path:`,
// `optimize:`) of 004's workpiece pose optimization, and `advise:` (the
// cutting-parameter advice).

#include "robomill/job/job.hpp"
#include "yaml_reader.hpp"

namespace robomill::job::detail {

/// Reads `workpiece`, `path`, `optimize` and `advise` from the job's top level into
/// `job` (after the robot, tool, cutting and process sections), with the
/// cross-checks between them. Throws InputError naming the field and line.
void read_planning(SectionReader& root, Job& job);

}  // namespace robomill::job::detail
