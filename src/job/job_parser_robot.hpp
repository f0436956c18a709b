#pragma once
// Private to the job parser: The `robot:` section of a job: DH table or URDF, joint stiffness, link
// inertias, posture, tool frame (000 §2, 002 §2).

#include <optional>
#include <vector>

#include "robomill/job/job.hpp"
#include "yaml_reader.hpp"

namespace robomill::job::detail {

/// `robot:` (a URDF path relative to the job file `source`). Throws
/// InputError naming the field and line.
RobotSettings read_robot_section(SectionReader& r, const std::filesystem::path& source);

}  // namespace robomill::job::detail
