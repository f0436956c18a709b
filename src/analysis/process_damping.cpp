#include "robomill/analysis/process_damping.hpp"

namespace robomill::analysis {

std::optional<stability::ProcessDamping> process_damping(const job::StabilitySettings& settings) {
  using Damping = job::StabilitySettings::Damping;
  if (settings.process_damping == Damping::none)
    return std::nullopt;
  stability::ProcessDamping damping;
  damping.model = settings.process_damping == Damping::energy_balance
                      ? stability::ProcessDampingModel::energy_balance
                      : stability::ProcessDampingModel::linear_equivalent;
  damping.indentation_n_per_m3 = settings.indentation_n_per_m3;
  damping.wear_land_m = settings.wear_land_m;
  damping.friction = settings.friction;
  return damping;
}

std::optional<stability::LinearProcessDamping> process_damping(
    const job::SimulationSettings& settings) {
  if (!settings.process_damping)
    return std::nullopt;
  return stability::LinearProcessDamping{settings.indentation_n_per_m3, settings.wear_land_m,
                                         settings.friction};
}

}  // namespace robomill::analysis
