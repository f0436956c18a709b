#pragma once
// `robomill deflection` of a job: 000's force-induced deformation (§2 Eq 1-4)
// and the actual contact boundary (§4 Eq 20-31) over a sweep of axial
// depths — per node, the deformation, the actual radial depth and entry
// angle when the node cuts the wall: 000 Figure 11. SI units.

#include <vector>

#include "robomill/deflection/contact_boundary.hpp"
#include "robomill/deflection/deformed_engagement.hpp"
#include "robomill/job/job.hpp"

namespace robomill::analysis {

struct DeflectionSweep {
  /// The deformation model from the job (analysis/deformation.hpp): tool, cut,
  /// linear law and, with deflection.robot, the robot at its posture.
  deflection::DeflectionSetup setup;
  /// The swept axial depths: deflection.depths, or ap_lim/8 … 1.5 ap_lim
  /// (Eq 22) so that both contact cases show; straight flutes (no ap_lim)
  /// sweep up to twice the job's ap; never beyond the overhang.
  std::vector<double> depths_m;
  /// The contact boundary at each depth (same order); at position k node k
  /// generates the surface.
  std::vector<deflection::ContactBoundary> boundaries;
  /// 000 Eq 22: where Case 1 (the whole flute in the arc) ends; +inf for
  /// straight flutes.
  double critical_depth_m = 0.0;
  /// The largest deformation |(dx, dy)| of a surface-generating node over
  /// the sweep, and the largest rise of its entry angle over the nominal one.
  double max_deflection_m = 0.0;
  double max_entry_increase_rad = 0.0;
  double elapsed_s = 0.0;  ///< solving the boundaries
};

/// The sweep on up to `threads` threads (0: all cores). Needs the tool,
/// cutting and process sections; without a deflection: section the
/// defaults apply (docs/job-reference.md), the robot only when the job gives
/// one with a posture. Throws InputError naming the field, NumericalError
/// when a depth's deformation does not converge.
DeflectionSweep deflection_sweep(const job::Job& job, int threads = 0);

}  // namespace robomill::analysis
