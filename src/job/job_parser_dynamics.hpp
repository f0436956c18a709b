#pragma once
// Private to the job parser: The `dynamics:` section of a job: the modal table, measured FRF files
// and their fit, and the library of modes measured at postures (001 Eq 16-18).

#include <optional>
#include <vector>

#include "robomill/job/job.hpp"
#include "yaml_reader.hpp"

namespace robomill::job::detail {

/// `dynamics:` into job.modes, job.frf, job.fit or job.posture_library, and
/// job.dynamics_source. Throws InputError naming the field and line.
void read_dynamics(SectionReader& root, Job& job);

/// The measured FRF files under `frf` of section `r` (dynamics.frf, an
/// experiment's hammer test): the map by direction or the list; empty when
/// `frf` is absent. Paths are resolved against `source`'s folder.
std::vector<FrfFileSpec> read_frf_files(SectionReader& r, const std::filesystem::path& source);

/// 001 Eq 16-18 at the query posture (dynamics.at or robot.posture): the
/// library's modes interpolated into job.modes. Nothing without a library.
void resolve_posture_library(Job& job);

}  // namespace robomill::job::detail
