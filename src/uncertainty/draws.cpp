#include "robomill/uncertainty/draws.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/policies/policy.hpp>
#include <boost/random/sobol.hpp>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

namespace robomill::uncertainty {
namespace {

// Boost's normal in plain double precision (see distribution.cpp).
using DrawsDoublePolicy =
    boost::math::policies::policy<boost::math::policies::promote_double<false>>;
using DrawsStandardNormal = boost::math::normal_distribution<double, DrawsDoublePolicy>;

/// The smallest and largest coordinates a point can have: 2^-53 and 1 − 2^-53.
constexpr double kSmallestUnitCoordinate = 0x1p-53;
constexpr double kLargestUnitCoordinate = 1.0 - 0x1p-53;

/// Boost's table of primitive polynomials reaches this dimension.
constexpr int kSobolMaxDimension = 3667;

/// Tolerance on the symmetry and the unit diagonal of a correlation matrix,
/// and the smallest eigenvalue it may have.
constexpr double kCorrelationEntryTolerance = 1e-9;
constexpr double kSmallestCorrelationEigenvalue = 1e-10;

/// 64 random bits → the centre of one of 2^52 equal cells of (0, 1).
double open_unit_coordinate(std::uint64_t bits) {
  return (static_cast<double>(bits >> 12) + 0.5) * 0x1p-52;
}

std::string draws_number_text(double value) {
  std::ostringstream text;
  text.precision(6);
  text << value;
  return text.str();
}

std::string entry_text(Eigen::Index row, Eigen::Index column) {
  // fmt, not "(" + std::string: GCC 12 at -O3 raises a -Wrestrict false
  // positive on the concatenation.
  return fmt::format("({}, {})", row, column);
}

[[noreturn]] void refuse_correlation(const std::string& problem) {
  throw std::invalid_argument("correlation matrix: " + problem);
}

/// Size, finiteness, symmetry, unit diagonal and range of the entries.
void check_correlation_entries(const Eigen::MatrixXd& r, int variables) {
  if (r.rows() != variables || r.cols() != variables)
    refuse_correlation("is " + std::to_string(r.rows()) + " x " + std::to_string(r.cols()) +
                       " but there are " + std::to_string(variables) + " variables");
  for (Eigen::Index i = 0; i < r.rows(); ++i) {
    for (Eigen::Index j = 0; j < r.cols(); ++j) {
      const double value = r(i, j);
      if (!std::isfinite(value))
        refuse_correlation("entry " + entry_text(i, j) + " is not a finite number");
      if (i == j && std::abs(value - 1.0) > kCorrelationEntryTolerance)
        refuse_correlation("diagonal entry " + entry_text(i, j) + " is " +
                           draws_number_text(value) +
                           "; a variable's correlation with itself is 1");
      if (i != j && std::abs(value) > 1.0)
        refuse_correlation("entry " + entry_text(i, j) + " = " + draws_number_text(value) +
                           " lies outside [-1, 1]");
      if (j > i && std::abs(value - r(j, i)) > kCorrelationEntryTolerance)
        refuse_correlation("is not symmetric: entry " + entry_text(i, j) + " is " +
                           draws_number_text(value) + " but " + entry_text(j, i) + " is " +
                           draws_number_text(r(j, i)));
    }
  }
}

/// Randomly shifted Sobol points: Boost's points 1, 2, ... (it skips the
/// all-zero point 0), each coordinate plus its shift modulo 2^64.
Eigen::MatrixXd shifted_sobol_points(int samples, int dimension, std::uint64_t seed) {
  boost::random::sobol sequence(static_cast<std::size_t>(dimension));
  std::mt19937_64 shift_source(seed);
  std::vector<std::uint64_t> shift(static_cast<std::size_t>(dimension));
  for (auto& s : shift)
    s = shift_source();
  Eigen::MatrixXd points(samples, dimension);
  for (int i = 0; i < samples; ++i)
    for (int j = 0; j < dimension; ++j)
      points(i, j) = open_unit_coordinate(static_cast<std::uint64_t>(sequence()) +
                                          shift[static_cast<std::size_t>(j)]);
  return points;
}

Eigen::MatrixXd pseudo_random_points(int samples, int dimension, std::uint64_t seed) {
  std::mt19937_64 engine(seed);
  Eigen::MatrixXd points(samples, dimension);
  for (int i = 0; i < samples; ++i)
    for (int j = 0; j < dimension; ++j)
      points(i, j) = open_unit_coordinate(engine());
  return points;
}

/// Row by row: z = Φ⁻¹(u), z ← L·z, u = Φ(z), clamped into the open interval.
void correlate_points(Eigen::MatrixXd& points, const Eigen::MatrixXd& factor) {
  const DrawsStandardNormal standard_normal;
  Eigen::VectorXd z(points.cols());
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    for (Eigen::Index j = 0; j < points.cols(); ++j)
      z(j) = boost::math::quantile(standard_normal, points(i, j));
    const Eigen::VectorXd correlated = factor.triangularView<Eigen::Lower>() * z;
    for (Eigen::Index j = 0; j < points.cols(); ++j)
      points(i, j) = std::clamp(boost::math::cdf(standard_normal, correlated(j)),
                                kSmallestUnitCoordinate, kLargestUnitCoordinate);
  }
}

}  // namespace

Eigen::MatrixXd correlation_factor(const Eigen::MatrixXd& correlation, int variables) {
  check_correlation_entries(correlation, variables);
  const Eigen::LLT<Eigen::MatrixXd> cholesky(correlation);
  const double smallest_eigenvalue =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(correlation, Eigen::EigenvaluesOnly)
          .eigenvalues()
          .minCoeff();
  if (cholesky.info() != Eigen::Success || !(smallest_eigenvalue > kSmallestCorrelationEigenvalue))
    refuse_correlation(
        "is not positive definite (smallest eigenvalue " + draws_number_text(smallest_eigenvalue) +
        "): no set of variables can have these correlations together, or one variable is "
        "fixed by the others (drive the fields of fully correlated variables with one variable)");
  return cholesky.matrixL();
}

Eigen::MatrixXd uniform_points(int dimension, const DrawSettings& settings) {
  if (settings.samples < 1)
    throw std::invalid_argument("draws: samples must be at least 1 (got " +
                                std::to_string(settings.samples) + ")");
  if (dimension < 1)
    throw std::invalid_argument("draws: no variables to draw");
  if (settings.sampling == DrawSettings::Sampling::random)
    return pseudo_random_points(settings.samples, dimension, settings.seed);
  if (dimension > kSobolMaxDimension)
    throw std::invalid_argument("draws: Sobol points exist for at most " +
                                std::to_string(kSobolMaxDimension) + " variables (got " +
                                std::to_string(dimension) + "); use sampling random");
  return shifted_sobol_points(settings.samples, dimension, settings.seed);
}

Eigen::MatrixXd draw(const std::vector<Distribution>& variables, const DrawSettings& settings) {
  const int count = static_cast<int>(variables.size());
  if (count == 0)
    throw std::invalid_argument("draws: no variables to draw");
  // The correlation is checked before any point is made.
  std::optional<Eigen::MatrixXd> factor;
  if (settings.correlation)
    factor = correlation_factor(*settings.correlation, count);
  Eigen::MatrixXd values = uniform_points(count, settings);
  if (factor)
    correlate_points(values, *factor);
  for (Eigen::Index j = 0; j < values.cols(); ++j)
    for (Eigen::Index i = 0; i < values.rows(); ++i)
      values(i, j) = quantile(variables[static_cast<std::size_t>(j)], values(i, j));
  return values;
}

}  // namespace robomill::uncertainty
