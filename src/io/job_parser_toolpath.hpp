#pragma once
// Private to the job parser: the `toolpath:` and `stock:` sections of
// `robomill toolpath` (docs/toolpath.md), and the tool fields they share with
// the job's `tool:`.

#include "robomill/io/job.hpp"
#include "yaml_reader.hpp"

namespace robomill::io::detail {

/// The fields of a tool section wherever it sits (`tool:`, `toolpath.tools.T2`),
/// validated by tool::Tool. Throws InputError naming the field and line.
tool::ToolSpec read_tool_fields(SectionReader& r);

/// Reads `toolpath` and `stock` from the job's top level into `job` (after
/// the tool section). Throws InputError naming the field and line.
void read_toolpath(SectionReader& root, Job& job);

}  // namespace robomill::io::detail
