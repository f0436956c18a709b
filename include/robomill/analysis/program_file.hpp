#pragma once
// The program a job names (`toolpath.file`), read from disk in its dialect.

#include "robomill/job/job.hpp"
#include "robomill/toolpath/program.hpp"

namespace robomill::analysis {

/// The job's program (`toolpath.file`, its `.dat` for KRL) read in its
/// dialect and placed in the workpiece frame (`toolpath.origin`,
/// `toolpath.orientation`). A file larger than `toolpath.max_size`, missing
/// or unreadable is an InputError naming `toolpath.file` and its line in the job.
toolpath::Program read_program(const job::ToolpathSettings& settings);

}  // namespace robomill::analysis
