#pragma once
// Private to the job parser: the `uncertainty:` section (issue 33;
// docs/uncertainty.md, "From a job"): the uncertain inputs, each resolved
// against the job's own fields, and how they are drawn.

#include <yaml-cpp/yaml.h>

#include "robomill/job/job.hpp"
#include "yaml_reader.hpp"

namespace robomill::job::detail {

/// Reads `uncertainty` into job.uncertainty (absent or empty: left unset).
/// `tree` is the whole job after the --set overrides: every path is looked up
/// in it (its nominal value) and in the job schema (its dimension and the unit
/// of bare numbers). Needs job.source (the posterior file is resolved against
/// the job's folder). Throws InputError naming the field and line.
void read_uncertainty(SectionReader& root, const YAML::Node& tree, Job& job);

/// Reads the job again with every variable's fields set to their own nominal
/// values written in SI, as analysis::job_of_draw writes drawn values, and
/// refuses a path the job does not read back as that number (InputError
/// naming the variable's path and line). Needs job.yaml_text and
/// job.overrides; does nothing without job.uncertainty.
void check_uncertainty_round_trip(const Job& job);

}  // namespace robomill::job::detail
