#pragma once
// Private to the job parser: The `tool:`, `cutting:`, `process:` and `forces:` sections of a job
// (the cut of `robomill forces` and every per-cut analysis): geometry, force law and cut in SI.

#include <optional>
#include <vector>

#include "robomill/job/job.hpp"
#include "yaml_reader.hpp"

namespace robomill::job::detail {

/// `tool:` (absent: nullopt). Throws InputError naming the field and line.
std::optional<tool::ToolSpec> read_tool(SectionReader& root);

/// The fields of a tool section wherever it sits (`tool:`, `toolpath.tools.T2`),
/// validated by tool::Tool. Throws InputError naming the field and line.
tool::ToolSpec read_tool_fields(SectionReader& r);

/// `cutting:`: the force law and its coefficients (absent: nullopt).
std::optional<cutting::CuttingLaw> read_cutting(SectionReader& root);

/// `process:`: spindle, feed, depths, direction (absent: nullopt); the feed
/// rate needs the tool's teeth.
std::optional<cutting::MillingProcess> read_process(SectionReader& root,
                                                    const std::optional<tool::ToolSpec>& tool);

/// `forces:`: what `robomill forces` samples (revolutions, steps, elements).
/// `ae` of section `r` (mm): no wider than the tool's diameter (slotting
/// at exactly the diameter allowed). Throws InputError naming `ae`.
double read_radial_depth(SectionReader& r, const std::optional<tool::ToolSpec>& tool);

/// `direction` of section `r`: down (climb, the default) or up.
cutting::MillingDirection read_direction(SectionReader& r);

ForcesSettings read_forces(SectionReader& root, const std::optional<tool::ToolSpec>& tool);

}  // namespace robomill::job::detail
