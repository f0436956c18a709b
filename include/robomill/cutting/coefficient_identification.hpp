#pragma once
// Mechanistic identification of the linear law's six coefficients from mean
// forces measured at several feeds per tooth (000 §6.2 Eq 39, 001 §3.2 and
// Table 1): the mean force is linear in the coefficients, so all measurements
// are stacked into one linear least-squares problem.

#include <Eigen/Core>
#include <vector>

#include "robomill/cutting/cutting_law.hpp"
#include "robomill/cutting/engagement.hpp"

namespace robomill::cutting {

/// One cutting test: a mean force measured on the tool (tool frame) at a feed.
struct MeanForceMeasurement {
  double feed_per_tooth_m = 0.0;
  Eigen::Vector3d mean_force_n = Eigen::Vector3d::Zero();
  int teeth = 0;
  double axial_depth_m = 0.0;
  Engagement engagement{0.0, 3.14159265358979323846};  ///< slot by default
};

struct CoefficientFit {
  LinearLaw coefficients;
  /// One standard error per coefficient, in the order Ktc Krc Kac Kte Kre Kae
  /// (SI), from the residual variance; zero when the fit has no redundancy.
  Eigen::Matrix<double, 6, 1> standard_error = Eigen::Matrix<double, 6, 1>::Zero();
  double rms_residual_n = 0.0;            ///< over all force components of all tests
  double r_squared = 0.0;                 ///< 1 − SS_res / SS_tot over all components
  std::vector<Eigen::Vector3d> fitted_n;  ///< model mean force per measurement
};

/// Least-squares coefficients. Throws InputError if the tests cannot separate
/// shear from edge coefficients (fewer than two distinct feeds) or contain
/// non-finite numbers.
CoefficientFit identify_linear_coefficients(const std::vector<MeanForceMeasurement>& tests);

}  // namespace robomill::cutting
