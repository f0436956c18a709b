#include "robomill/analysis/milling_force_history.hpp"

#include <chrono>

namespace robomill::analysis {

MillingForceHistory milling_force_history(const job::Job& job, int threads) {
  job::require(job, {job::Section::tool, job::Section::cutting, job::Section::process});

  MillingForceHistory history;
  const auto start = std::chrono::steady_clock::now();
  const tool::Tool cutter(*job.tool);
  history.axial_elements = job.forces.axial_elements > 0 ? job.forces.axial_elements
                                                         : cutting::default_axial_elements(
                                                               cutter, job.process->axial_depth_m);
  const cutting::MillingForceModel model(cutter, *job.cutting, *job.process,
                                         history.axial_elements);
  history.sampling = cutting::ForceSampling{job.forces.revolutions, job.forces.steps_per_tooth};
  history.series = cutting::sample_forces(model, history.sampling, threads);
  history.statistics = cutting::summarize(history.series, job.process->spindle_rad_s);
  history.elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  history.tooth_period_s = model.tooth_period_s();
  history.nominal_engagement = model.nominal_engagement();
  history.helix_lag_rad = cutter.lag_angle_rad(job.process->axial_depth_m);
  history.mean_chip_m = model.mean_chip_m();
  if (model.law().is_linear())
    history.linear_law = model.law().linear();
  return history;
}

}  // namespace robomill::analysis
