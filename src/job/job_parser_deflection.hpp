#pragma once
// Private to the job parser: the `deflection:` section (000 §2 and §4, the
// force-induced deformation and the contact-boundary iteration).

#include "robomill/job/job.hpp"
#include "yaml_reader.hpp"

namespace robomill::job::detail {

/// Reads `deflection` into job.deflection (after the tool, process, robot and
/// stability sections, which it is checked against). Throws InputError naming
/// the field and line.
void read_deflection(SectionReader& root, Job& job);

}  // namespace robomill::job::detail
