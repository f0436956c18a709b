#pragma once
// Private to the job parser: The `stability:` section of a job: method, speed grid, depths, process
// damping and the structure options of `robomill stability`.

#include <optional>
#include <vector>

#include "robomill/job/job.hpp"
#include "yaml_reader.hpp"

namespace robomill::job::detail {

/// `stability:` (absent: nullopt); the tool, the modes and their source set
/// the defaults. Throws InputError naming the field and line.
std::optional<StabilitySettings> read_stability(SectionReader& root,
                                                const std::optional<tool::ToolSpec>& tool,
                                                const std::vector<ModeSpec>& modes,
                                                Job::DynamicsSource source);

/// `method` of section `r` (stability, learn): zoa, sdm, fdm or fdm2.
StabilitySettings::Method read_stability_method(SectionReader& r, const std::string& fallback);

}  // namespace robomill::job::detail
