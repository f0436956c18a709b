#include "robomill/cutting/coefficient_identification.hpp"

#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <string>

#include "robomill/core/error.hpp"
#include "robomill/cutting/average_forces.hpp"

namespace robomill::cutting {

CoefficientFit identify_linear_coefficients(const std::vector<MeanForceMeasurement>& tests) {
  const Eigen::Index rows = 3 * static_cast<Eigen::Index>(tests.size());
  Eigen::MatrixXd design(rows, 6);
  Eigen::VectorXd measured(rows);
  double min_feed = 0.0, max_feed = 0.0;
  for (std::size_t i = 0; i < tests.size(); ++i) {
    const MeanForceMeasurement& test = tests[i];
    const std::string where = "test " + std::to_string(i + 1);
    if (!std::isfinite(test.feed_per_tooth_m) || !(test.feed_per_tooth_m > 0.0)) {
      throw InputError(where, 0, "feed per tooth must be positive and finite");
    }
    if (!test.mean_force_n.allFinite())
      throw InputError(where, 0, "force must be finite");
    if (test.teeth < 1 || !(test.axial_depth_m > 0.0) || test.engagement.empty()) {
      throw InputError(where, 0, "needs teeth ≥ 1, a positive axial depth and an engagement");
    }
    const Eigen::Index row = 3 * static_cast<Eigen::Index>(i);
    design.middleRows(row, 3) =
        mean_force_matrix(test.teeth, test.axial_depth_m, test.feed_per_tooth_m, test.engagement);
    measured.segment(row, 3) = test.mean_force_n;
    min_feed = i == 0 ? test.feed_per_tooth_m : std::min(min_feed, test.feed_per_tooth_m);
    max_feed = i == 0 ? test.feed_per_tooth_m : std::max(max_feed, test.feed_per_tooth_m);
  }
  // Shear and edge coefficients are separated by the slope and intercept of
  // force against feed: that needs two different feeds at least.
  if (tests.size() < 2 || !(max_feed > min_feed * (1.0 + 1e-9))) {
    throw InputError("feed_per_tooth", 0,
                     "identification needs tests at two or more different feeds per tooth");
  }

  // Columns differ by ~1e4 in scale (fz multiplies the shear columns):
  // normalize them so that the rank decision of the QR is meaningful.
  const Eigen::VectorXd column_scale = design.colwise().norm().transpose().cwiseMax(1e-300);
  const Eigen::MatrixXd scaled = design * column_scale.cwiseInverse().asDiagonal();
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(scaled);
  qr.setThreshold(1e-10);
  if (qr.rank() < 6) {
    throw InputError("tests", 0,
                     "the tests do not determine all six coefficients (rank " +
                         std::to_string(qr.rank()) + " of 6): vary the feed per tooth");
  }
  const Eigen::VectorXd scaled_solution = qr.solve(measured);
  const Eigen::Matrix<double, 6, 1> solution = scaled_solution.cwiseQuotient(column_scale);

  CoefficientFit fit;
  fit.coefficients = linear_law_from_vector(solution);
  const Eigen::VectorXd model = design * solution;
  const Eigen::VectorXd residual = measured - model;
  const double ss_res = residual.squaredNorm();
  const double ss_tot = (measured.array() - measured.mean()).matrix().squaredNorm();
  fit.rms_residual_n = std::sqrt(ss_res / static_cast<double>(rows));
  fit.r_squared = ss_tot > 0.0 ? 1.0 - ss_res / ss_tot : 1.0;
  const Eigen::Index dof = rows - 6;
  if (dof > 0) {
    // Covariance σ² (AᵀA)⁻¹ from the scaled, well-conditioned system.
    const double variance = ss_res / static_cast<double>(dof);
    const Eigen::MatrixXd normal = scaled.transpose() * scaled;
    const Eigen::MatrixXd inverse = normal.inverse();
    for (int c = 0; c < 6; ++c) {
      fit.standard_error[c] = std::sqrt(std::max(0.0, variance * inverse(c, c))) / column_scale[c];
    }
  }
  fit.fitted_n.reserve(tests.size());
  for (std::size_t i = 0; i < tests.size(); ++i) {
    fit.fitted_n.emplace_back(model.segment(3 * static_cast<Eigen::Index>(i), 3));
  }
  return fit;
}

}  // namespace robomill::cutting
