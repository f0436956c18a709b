#pragma once
// `robomill identify-cutting`: the six linear cutting coefficients from mean
// forces measured at several feeds per tooth (000 §6.2, 001 §3.2) — the setup
// the tests share (from a job), each test's depths and engagement, and the
// least-squares fit (cutting/coefficient_identification.hpp).
//
// Everything is in SI units; commands::compute_identify_cutting reads the
// tests (DATA.csv) and the typed options and turns the fit into fit.csv,
// cutting.yaml and summary.json.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "robomill/cutting/coefficient_identification.hpp"
#include "robomill/cutting/process.hpp"
#include "robomill/job/job.hpp"

namespace robomill::analysis {

/// What the cutting tests share unless a test's row says otherwise.
struct CuttingTestSetup {
  int teeth = 0;                         ///< the tool's teeth
  std::optional<double> axial_depth_m;   ///< ap of a test whose row gives none
  std::optional<double> radial_depth_m;  ///< ae of a test whose row gives none; none: a slot
  std::optional<double> diameter_m;      ///< the tool's, needed for a radial depth
  /// Down or up milling (irrelevant for slots).
  cutting::MillingDirection direction = cutting::MillingDirection::down;
};

/// The setup a job gives: teeth and diameter from its tool section, ap, ae and
/// the direction from its process section; what the job lacks stays unset.
CuttingTestSetup cutting_test_setup(const job::Job& job);

/// One cutting test as measured (a row of the data file).
struct MeasuredCuttingTest {
  int row = 0;  ///< 1-based data row, naming the test in errors
  double feed_per_tooth_m = 0.0;
  Eigen::Vector3d mean_force_n = Eigen::Vector3d::Zero();  ///< on the tool, tool frame
  std::optional<double> axial_depth_m;                     ///< the row's own ap; none: the setup's
  std::optional<double> radial_depth_m;                    ///< the row's own ae; none: the setup's
};

/// The linear law's coefficients identified from cutting tests.
struct CuttingCoefficientIdentification {
  /// The tests as fitted (same order): the setup's teeth, each test's axial
  /// depth and its radial engagement (a slot without a radial depth).
  std::vector<cutting::MeanForceMeasurement> tests;
  /// The six coefficients, their standard errors, the fitted mean forces.
  cutting::CoefficientFit fit;
};

/// The fit of the tests on `setup` (000 §6.2). Throws InputError naming
/// "`data_source` row N" for a test without a positive axial depth, with a
/// non-positive radial depth, or with a radial depth but no tool diameter or
/// one above it; naming `data_source` when there are no tests; and
/// cutting::identify_linear_coefficients's.
CuttingCoefficientIdentification identify_cutting_coefficients(
    const CuttingTestSetup& setup, const std::vector<MeasuredCuttingTest>& tests,
    const std::string& data_source);

}  // namespace robomill::analysis
