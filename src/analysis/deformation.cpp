#include "robomill/analysis/deformation.hpp"

#include <memory>

#include "robomill/core/error.hpp"
#include "robomill/deflection/node_compliance.hpp"

namespace robomill::analysis {

deflection::DeflectionSetup deflection_setup(const job::Job& job) {
  require(job, {job::Section::tool, job::Section::cutting, job::Section::process});
  const job::DeflectionSettings settings = job.deflection.value_or(job::DeflectionSettings{});
  const auto* law = std::get_if<cutting::LinearLaw>(&*job.cutting);
  if (!law) {
    throw InputError("cutting.law", 0,
                     "000's deformation model uses the linear law (Eq 13: Ktc, Krc, Kte, Kre)");
  }
  deflection::DeflectionSetup setup;
  setup.tool_radius_m = 0.5 * job.tool->diameter_m;
  setup.helix_rad = job.tool->helix_rad;
  setup.overhang_m = job.tool->overhang_m;
  const double diameter = settings.equivalent_diameter_m > 0.0 ? settings.equivalent_diameter_m
                                                               : 0.8 * job.tool->diameter_m;
  setup.flexural_rigidity_n_m2 =
      deflection::flexural_rigidity_n_m2(job.tool->youngs_modulus_pa, diameter);
  setup.feed_per_tooth_m = job.process->feed_per_tooth_m;
  setup.radial_depth_m = job.process->radial_depth_m;
  setup.law = *law;
  setup.elements = settings.elements;
  setup.options.chip_correction = settings.chip_correction;
  if (settings.robot && job.robot && !job.robot->posture_rad.empty()) {
    try {
      setup.robot = std::make_shared<const robot::RobotModel>(job.robot->description);
    } catch (const std::invalid_argument& error) {
      throw InputError("robot", 0, error.what());
    }
    setup.posture_rad = Eigen::Map<const Eigen::VectorXd>(
        job.robot->posture_rad.data(), static_cast<Eigen::Index>(job.robot->posture_rad.size()));
  }
  return setup;
}

std::vector<dynamics::AxialShape> mode_shapes_along_tool(const job::Job& job) {
  if (job.dynamics_source != job::Job::DynamicsSource::table)
    return {};
  std::vector<dynamics::AxialShape> shapes;
  bool any = false;
  for (const job::ModeSpec& mode : job.modes) {
    shapes.push_back(mode.shape);
    any = any || !mode.shape.empty();
  }
  return any ? shapes : std::vector<dynamics::AxialShape>{};
}

}  // namespace robomill::analysis
