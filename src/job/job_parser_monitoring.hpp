#pragma once
// Private to the job parser: the `recording:`, `recordings:` and `listen:`
// sections of `robomill listen` (docs/monitoring.md).

#include "robomill/job/job.hpp"
#include "yaml_reader.hpp"

namespace robomill::job::detail {

/// Reads `recording`, `recordings` and `listen` from the job's top level into
/// `job` (after tool, process and advise). Files are opened by the command,
/// not here, so `robomill validate` stays fast. Throws InputError naming the
/// field and line.
void read_monitoring(SectionReader& root, Job& job);

/// One recording written inside another section (`experiments[].recording`),
/// with the keys of `recording:`; its spindle defaults to `spindle_rad_s`
/// (the experiment's).
io::RecordingSpec read_nested_recording(SectionReader& r, const Job& job, double spindle_rad_s);

}  // namespace robomill::job::detail
