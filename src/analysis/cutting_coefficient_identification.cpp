#include "robomill/analysis/cutting_coefficient_identification.hpp"

#include <numbers>

#include "robomill/core/error.hpp"
#include "robomill/cutting/engagement.hpp"

namespace robomill::analysis {
namespace {

cutting::Engagement engagement_for(const CuttingTestSetup& setup,
                                   std::optional<double> radial_depth_m, const std::string& where) {
  if (!radial_depth_m)
    return {0.0, std::numbers::pi};  // slot
  if (!setup.diameter_m) {
    throw InputError(where, 0, "a radial depth needs the tool diameter (--diameter or --job)");
  }
  if (*radial_depth_m > *setup.diameter_m * (1.0 + 1e-12)) {
    throw InputError(where, 0, "radial depth exceeds the tool diameter");
  }
  const double radius = 0.5 * *setup.diameter_m;
  return cutting::radial_engagement(radius, radius, *radial_depth_m, setup.direction);
}

}  // namespace

CuttingTestSetup cutting_test_setup(const job::Job& job) {
  CuttingTestSetup setup;
  if (job.tool) {
    setup.teeth = job.tool->teeth;
    setup.diameter_m = job.tool->diameter_m;
  }
  if (job.process) {
    setup.axial_depth_m = job.process->axial_depth_m;
    setup.radial_depth_m = job.process->radial_depth_m;
    setup.direction = job.process->direction;
  }
  return setup;
}

CuttingCoefficientIdentification identify_cutting_coefficients(
    const CuttingTestSetup& setup, const std::vector<MeasuredCuttingTest>& tests,
    const std::string& data_source) {
  CuttingCoefficientIdentification result;
  for (const MeasuredCuttingTest& measured : tests) {
    const std::string where = data_source + " row " + std::to_string(measured.row);
    cutting::MeanForceMeasurement test;
    test.feed_per_tooth_m = measured.feed_per_tooth_m;
    test.mean_force_n = measured.mean_force_n;
    test.teeth = setup.teeth;
    std::optional<double> ap = setup.axial_depth_m;
    if (measured.axial_depth_m)
      ap = measured.axial_depth_m;
    if (!ap || !(*ap > 0.0))
      throw InputError(where, 0, "axial depth missing (ap_mm column, --ap or --job)");
    test.axial_depth_m = *ap;
    std::optional<double> ae = setup.radial_depth_m;
    if (measured.radial_depth_m)
      ae = measured.radial_depth_m;
    if (ae && !(*ae > 0.0))
      throw InputError(where, 0, "radial depth must be positive");
    test.engagement = engagement_for(setup, ae, where);
    result.tests.push_back(test);
  }
  if (result.tests.empty())
    throw InputError(data_source, 0, "no data rows");

  result.fit = cutting::identify_linear_coefficients(result.tests);
  return result;
}

}  // namespace robomill::analysis
