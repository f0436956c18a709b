#pragma once
// The job's process damping as the numerical methods take it: the
// `stability:` section's (000 Eq 18-19 linear equivalent or 003 §3.1 energy
// balance) for the zero-order method of `robomill stability` and along the
// program, the `simulation:` section's (000 Eq 18-19) for `robomill simulate`.

#include <optional>

#include "robomill/job/job.hpp"
#include "robomill/stability/lobes.hpp"
#include "robomill/stability/process_damping.hpp"

namespace robomill::analysis {

/// `stability.process_damping`: its model and coefficients (K_sp in N/m³,
/// wear land in m, μ); nullopt when the job gives none.
std::optional<stability::ProcessDamping> process_damping(const job::StabilitySettings& settings);

/// `simulation.process_damping`: 000 Eq 18-19's linear-equivalent damper
/// (K_sp in N/m³, wear land in m, μ); nullopt when the job gives none.
std::optional<stability::LinearProcessDamping> process_damping(
    const job::SimulationSettings& settings);

}  // namespace robomill::analysis
