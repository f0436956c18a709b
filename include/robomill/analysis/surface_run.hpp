#pragma once
// `robomill surface` from a job (001 §2.1-2.4, docs/surface.md): the checks
// of 001 Eq 29-31, path coverage and the shank, each naming the job field
// and a value that works (InputError); the raster over the patch; the tool
// vibration from the time-domain simulation at the job's dynamics
// (dynamics.postures + dynamics.at: 001 Eq 16-18); the Z-map and roughness.

#include <optional>
#include <string>
#include <vector>

#include "robomill/job/job.hpp"
#include "robomill/simulation/response_metrics.hpp"
#include "robomill/surface/roughness.hpp"
#include "robomill/surface/topography.hpp"

namespace robomill::analysis {

/// The simulated vibration behind a surface (001 §2.2).
struct SurfaceVibration {
  surface::Vibration vibration;  ///< u(t) in the spindle frame over the raster (or a pass)
  double warmup_s = 0.0, duration_s = 0.0;
  int steps_per_tooth = 0;
  std::vector<double> natural_frequencies_hz;
  Eigen::Vector3d mean_m = Eigen::Vector3d::Zero(), peak_to_peak_m = Eigen::Vector3d::Zero();
  std::string structure;
  /// The simulate command's verdict over the second half of the simulated
  /// run: a vibration not locked to the tooth (or, with runout, the
  /// revolution) — chatter, period doubling — is what roughens a surface.
  simulation::ChatterVerdict verdict;
};

struct SurfaceRun {
  surface::ZMapResult zmap;
  surface::SurfaceRoughness roughness;
  surface::RasterPath path;
  surface::ResolutionRules rules;  ///< Eq 29-31 for the grid (without vibration)
  surface::ToolOrientation orientation;
  std::optional<SurfaceVibration> vibration;
  double path_time_s = 0.0, zmap_s = 0.0, elapsed_s = 0.0;
};

/// Throws InputError naming the field for a job that breaks a rule.
SurfaceRun run_surface_job(const job::Job& job, int threads = 0);

}  // namespace robomill::analysis
