#pragma once
// The job's structure as 000's multipoint-contact and deformation models see
// it: the deflection set-up (tool, cut, law, robot at its posture) and the
// measured mode shapes along the tool.

#include <vector>

#include "robomill/deflection/deformed_engagement.hpp"
#include "robomill/dynamics/axial_shape.hpp"
#include "robomill/job/job.hpp"

namespace robomill::analysis {

/// 000 §2/§4 from the job: tool radius, helix, overhang and bending section
/// (deflection.equivalent_diameter, default 0.8 D), the process's feed per
/// tooth and radial depth, the linear law, and — with deflection.robot — the
/// robot model at robot.posture. Throws InputError naming the field when a
/// needed section is missing.
deflection::DeflectionSetup deflection_setup(const job::Job& job);

/// The modal table's shapes along the tool (`dynamics.modes[i].shape`, 000
/// Table 2), one per mode in the order of structure_modes(job); empty when
/// no mode has a shape or the modes do not come from the table.
std::vector<dynamics::AxialShape> mode_shapes_along_tool(const job::Job& job);

}  // namespace robomill::analysis
