#pragma once
// Draws of several uncertain inputs at once: a samples × variables matrix
// whose column j follows variables[j], optionally correlated through a
// Gaussian copula.
//
// 1. Points u in the open unit cube (0, 1)^k, one row per sample:
//    - sobol: Boost.Random's boost::random::sobol (Sobol 1967; Bratley & Fox,
//      ACM TOMS 14, 1988, algorithm 659; direction numbers of Joe & Kuo, SIAM
//      J. Sci. Comput. 30, 2008, as Boost tabulates them for up to 3667
//      dimensions). Boost's sequence already starts after the all-zero point
//      (its first point is (1/2, ..., 1/2)), so sample i is the sequence's
//      point i + 1. Each coordinate is then rotated by a random shift modulo
//      1 (Cranley & Patterson, SIAM J. Numer. Anal. 13, 1976): the shift
//      vector comes from std::mt19937_64 seeded with `seed`, so another seed
//      gives another, equally well spread point set and the same seed the
//      same one. The rotation is exact: it is done on Boost's 64-bit integer
//      coordinates, modulo 2^64.
//    - random: std::mt19937_64 seeded with `seed` (a generator the C++
//      standard specifies bit for bit), read sample by sample, variable by
//      variable.
//    Both map 64 random bits b to ((b >> 12) + 1/2)·2^-52: the centre of one
//    of 2^52 equal cells, so no coordinate is ever exactly 0 or 1 (the
//    extreme values are 2^-53 and 1 − 2^-53, within 8.2 sd of a normal's
//    mean).
// 2. Correlation (optional), on the normal scale (the Gaussian copula: Sklar's
//    theorem as in Nelsen, An Introduction to Copulas, 2nd ed., 2006, §2.3,
//    with the multivariate normal's dependence): with
//    R = L·Lᵀ (Cholesky), z = L·Φ⁻¹(u) is normal with correlation R, and
//    u' = Φ(z) again uniform per column (clamped to [2^-53, 1 − 2^-53]).
//    Without a correlation u' = u.
// 3. x_ij = quantile(variables[j], u'_ij) (distribution.hpp).
//
// The first n rows do not depend on `samples` (more draws extend a run), and
// no thread runs inside, so a seed gives the same matrix on every run. Across
// machines the points u are bit-identical (integer arithmetic); the values x
// pass through Boost.Math and std::exp/std::log, whose last bits can differ
// between C libraries.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "robomill/uncertainty/distribution.hpp"

namespace robomill::uncertainty {

/// How many draws, from which seed, by which point set, with which
/// correlation.
struct DrawSettings {
  /// Which points in the unit cube the draws are made from.
  enum class Sampling {
    sobol,  ///< randomly shifted Sobol points (quasi-random): the default
    random  ///< independent pseudo-random points (plain Monte Carlo)
  };

  int samples = 1000;                   ///< rows of the result, ≥ 1 (Sobol: a power of two
                                        ///< keeps the point set best balanced)
  std::uint64_t seed = 0;               ///< the Sobol shift's or the random points' seed
  Sampling sampling = Sampling::sobol;  ///< the point set
  /// Correlation between the variables on the normal scale (variables × variables:
  /// symmetric, unit diagonal, positive definite); none: independent variables.
  std::optional<Eigen::MatrixXd> correlation;
};

/// The Cholesky factor L (lower triangular, R = L·Lᵀ) of a correlation matrix
/// for `variables` variables, after checking that R is one: the right size,
/// finite, symmetric, ones on the diagonal, off-diagonal entries in [−1, 1]
/// and positive definite (Eigen::LLT succeeds and the smallest eigenvalue
/// exceeds 1e-10). Throws std::invalid_argument naming the entry (0-based
/// row, column) or, when it is not positive definite, its smallest
/// eigenvalue.
Eigen::MatrixXd correlation_factor(const Eigen::MatrixXd& correlation, int variables);

/// settings.samples points in the open unit cube (0, 1)^dimension, one per
/// row, by settings.sampling and settings.seed (the correlation is not used).
/// Throws std::invalid_argument when samples < 1, dimension < 1 or, for
/// Sobol, dimension > 3667 (Boost's table).
Eigen::MatrixXd uniform_points(int dimension, const DrawSettings& settings);

/// settings.samples draws of the variables: a samples × variables matrix,
/// column j following variables[j], correlated as settings.correlation says
/// (Gaussian copula). Values in each variable's SI unit. Throws
/// std::invalid_argument when there are no variables, samples < 1, or the
/// correlation is not a valid correlation matrix of that size.
Eigen::MatrixXd draw(const std::vector<Distribution>& variables, const DrawSettings& settings);

}  // namespace robomill::uncertainty
