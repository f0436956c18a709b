#include "robomill/analysis/deflection_sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "robomill/analysis/deformation.hpp"
#include "robomill/core/parallel.hpp"

namespace robomill::analysis {
namespace {

/// The sweep: the job's depths, or ap_lim/8 … 1.5 ap_lim (Eq 22) so that both
/// contact cases show; straight flutes (no ap_lim) sweep up to twice the
/// job's ap.
std::vector<double> sweep_depths(const job::Job& job, const deflection::DeflectionSetup& setup) {
  const job::DeflectionSettings& s = *job.deflection;
  double from = s.depth_from_m, to = s.depth_to_m;
  const int count = s.depth_count;
  if (!(to > 0.0)) {
    const double limit =
        deflection::critical_depth_m(setup.tool_radius_m, setup.radial_depth_m, setup.helix_rad);
    to = std::isfinite(limit) ? 1.5 * limit : 2.0 * job.process->axial_depth_m;
    to = std::min(to, setup.overhang_m);
    from = to / count;
  }
  std::vector<double> depths(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i)
    depths[static_cast<std::size_t>(i)] = count == 1 ? from : from + (to - from) * i / (count - 1);
  return depths;
}

DeflectionSweep sweep(const job::Job& job, int threads) {
  DeflectionSweep result;
  result.setup = analysis::deflection_setup(job);
  const deflection::DeflectionSetup& setup = result.setup;
  result.depths_m = sweep_depths(job, setup);
  const std::vector<double>& depths = result.depths_m;
  const auto start = std::chrono::steady_clock::now();
  result.boundaries.resize(depths.size());
  core::parallel_for(depths.size(), threads, [&](std::size_t i) {
    result.boundaries[i] = deflection::solve_contact_boundary(
        deflection::contact_problem(setup, depths[i]), setup.options);
  });
  result.elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  for (const deflection::ContactBoundary& b : result.boundaries) {
    for (std::size_t k = 0; k < b.positions.size(); ++k) {
      const deflection::NodeState& node = b.positions[k].nodes[k];  // node k generating
      result.max_deflection_m = std::max(result.max_deflection_m, node.deflection_m.norm());
      result.max_entry_increase_rad =
          std::max(result.max_entry_increase_rad, node.entry_rad - b.nominal_entry_rad);
    }
  }
  result.critical_depth_m =
      deflection::critical_depth_m(setup.tool_radius_m, setup.radial_depth_m, setup.helix_rad);
  return result;
}

}  // namespace

DeflectionSweep deflection_sweep(const job::Job& job, int threads) {
  job::require(job, {job::Section::tool, job::Section::cutting, job::Section::process});
  if (job.deflection)
    return sweep(job, threads);
  // No section: the defaults (documented in docs/job-reference.md).
  job::Job defaulted = job;
  defaulted.deflection = job::DeflectionSettings{};
  if (!defaulted.robot || defaulted.robot->posture_rad.empty())
    defaulted.deflection->robot = false;
  return sweep(defaulted, threads);
}

}  // namespace robomill::analysis
