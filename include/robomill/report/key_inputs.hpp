#pragma once
// The job's key inputs for the report's inputs table (`inputs.json`): tool,
// cutting law and coefficients, process, structure (modes, FRF files,
// robot posture), and the analysis settings, each value with its unit.

#include <string>

#include "robomill/job/job.hpp"

namespace robomill::report {

/// JSON text: {"job": path, "name": ..., "inputs": [{"group", "name",
/// "value"}...]} with every value a display string ("855 N/mm²").
std::string key_inputs_json(const job::Job& job);

}  // namespace robomill::report
