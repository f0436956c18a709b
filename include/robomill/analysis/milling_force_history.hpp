#pragma once
// `robomill forces` of a job: the rigid-tool milling force history
// (DESIGN.md §3) — the force model of the job's tool, cutting law and
// process (000 Eq 8-15, 001 Eq 11-15, 004 Eq A1-A5) sampled over whole
// revolutions, and its statistics. SI units.

#include <optional>

#include "robomill/cutting/cutting_law.hpp"
#include "robomill/cutting/engagement.hpp"
#include "robomill/cutting/milling_forces.hpp"
#include "robomill/job/job.hpp"

namespace robomill::analysis {

struct MillingForceHistory {
  /// forces.axial_elements, or the default that resolves the helix lag.
  int axial_elements = 0;
  cutting::ForceSampling sampling;  ///< forces.revolutions and forces.steps_per_tooth
  /// The forces on the tool, tool frame: x feed, z tool axis towards the
  /// spindle; from ϕ = 0 over whole revolutions.
  cutting::ForceSeries series;
  cutting::ForceStatistics statistics;  ///< of `series` at the job's spindle speed
  double tooth_period_s = 0.0;
  cutting::Engagement nominal_engagement;  ///< of the full-radius edge
  double helix_lag_rad = 0.0;              ///< the helix lag over the axial depth
  double mean_chip_m = 0.0;                ///< mean chip thickness t_c (004 Eq A3)
  /// The linear law's coefficients; for the size-dependent law those at this
  /// process's mean chip thickness (004 Eq A2-A3). nullopt when the law is
  /// not linear.
  std::optional<cutting::LinearLaw> linear_law;
  double elapsed_s = 0.0;  ///< building the model and sampling
};

/// The history on up to `threads` threads (0: all cores). Needs the tool,
/// cutting and process sections (InputError naming the missing one).
MillingForceHistory milling_force_history(const job::Job& job, int threads = 0);

}  // namespace robomill::analysis
