// The tempered SMC sampler against posteriors and evidences known in closed
// form: a linear-Gaussian model (a correlated 3-variable posterior) and a
// likelihood that is an indicator (a truncated normal). The tolerances are
// Monte-Carlo errors of 4000 particles, stated at each check.

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <numbers>

#include "robomill/core/error.hpp"
#include "robomill/learning/tempered_smc.hpp"

namespace robomill::learning {
namespace {

/// y = A w + noise (σ): a posterior N(m, P⁻¹), P = I + AᵀA/σ², m = P⁻¹Aᵀy/σ²,
/// and an evidence N(y; 0, AAᵀ + σ²I).
struct LinearGaussian {
  Eigen::MatrixXd a{4, 3};
  Eigen::VectorXd y{4};
  double sigma = 0.37;
  LinearGaussian() {
    a << 0.83, -0.41, 0.27, 1.12, 0.35, -0.66, -0.29, 0.94, 0.58, 0.47, 0.13, 1.31;
    y << 0.71, -0.38, 1.46, 0.22;
  }
  double log_likelihood(const Eigen::VectorXd& w) const {
    const Eigen::VectorXd r = a * w - y;
    return -0.5 * r.squaredNorm() / (sigma * sigma) -
           static_cast<double>(y.size()) * std::log(sigma * std::sqrt(2.0 * std::numbers::pi));
  }
  Eigen::MatrixXd precision() const {
    return Eigen::MatrixXd::Identity(3, 3) + a.transpose() * a / (sigma * sigma);
  }
  Eigen::VectorXd mean() const {
    return precision().ldlt().solve(a.transpose() * y / (sigma * sigma));
  }
  double log_evidence() const {
    const Eigen::MatrixXd s = a * a.transpose() + sigma * sigma * Eigen::MatrixXd::Identity(4, 4);
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(s);
    return -0.5 * y.dot(ldlt.solve(y)) -
           0.5 * (4.0 * std::log(2.0 * std::numbers::pi) + std::log(s.determinant()));
  }
};

TEST(TemperedSmc, RecoversALinearGaussianPosteriorAndItsEvidence) {
  const LinearGaussian model;
  SmcSettings settings;
  settings.seed = 20261129;
  const SmcPosterior p = sample_tempered(
      3, [&](const Eigen::VectorXd& w) { return model.log_likelihood(w); }, settings);
  ASSERT_EQ(p.particles.rows(), 4000);
  const Eigen::MatrixXd covariance = model.precision().inverse();
  const Eigen::VectorXd mean = model.mean();
  const Eigen::RowVectorXd sample_mean = p.particles.colwise().mean();
  const Eigen::MatrixXd centred = p.particles.rowwise() - sample_mean;
  const Eigen::MatrixXd sample_covariance = centred.transpose() * centred / 3999.0;
  for (int j = 0; j < 3; ++j) {
    const double sd = std::sqrt(covariance(j, j));
    // 4000 correlated particles: an effective few hundred or more, so the
    // mean's error is below 0.1 sd and the sd's below 10 %.
    EXPECT_NEAR(sample_mean(j), mean(j), 0.1 * sd) << "variable " << j;
    EXPECT_NEAR(std::sqrt(sample_covariance(j, j)), sd, 0.1 * sd) << "variable " << j;
  }
  // The posterior correlation of w0 and w1 (−0.6 here), within 0.1.
  const double rho = covariance(0, 1) / std::sqrt(covariance(0, 0) * covariance(1, 1));
  const double sample_rho =
      sample_covariance(0, 1) / std::sqrt(sample_covariance(0, 0) * sample_covariance(1, 1));
  EXPECT_NEAR(sample_rho, rho, 0.1);
  // SMC's log evidence is unbiased in Z; its spread for this run is a few 0.01.
  EXPECT_NEAR(p.log_evidence, model.log_evidence(), 0.15);
  EXPECT_GE(p.stages.size(), 2u);
  EXPECT_DOUBLE_EQ(p.stages.back().temperature, 1.0);
  EXPECT_GT(p.acceptance, 0.1);
  EXPECT_GE(p.min_ess_fraction, 0.45);
}

TEST(TemperedSmc, ExtendingByTheLastObservationGivesTheWholePosterior) {
  // The first three observations sampled, then the fourth tempered in: the
  // same posterior and evidence as all four at once (closed forms above).
  const LinearGaussian model;
  const auto part = [&](const Eigen::VectorXd& w, Eigen::Index from, Eigen::Index count) {
    const Eigen::VectorXd r = (model.a * w - model.y).segment(from, count);
    return -0.5 * r.squaredNorm() / (model.sigma * model.sigma) -
           static_cast<double>(count) * std::log(model.sigma * std::sqrt(2.0 * std::numbers::pi));
  };
  SmcSettings settings;
  settings.seed = 31;
  const SmcPosterior first = sample_tempered(
      3, [&](const Eigen::VectorXd& w) { return part(w, 0, 3); }, settings);
  const SmcPosterior all = extend_tempered(
      first,
      [&](const Eigen::VectorXd& w) {
        return LogLikelihoodParts{part(w, 0, 3), part(w, 3, 1)};
      },
      settings);
  const Eigen::VectorXd mean = model.mean();
  const Eigen::MatrixXd covariance = model.precision().inverse();
  for (int j = 0; j < 3; ++j)
    EXPECT_NEAR(all.particles.col(j).mean(), mean(j), 0.1 * std::sqrt(covariance(j, j))) << j;
  EXPECT_NEAR(all.log_evidence, model.log_evidence(), 0.15);
  EXPECT_GT(all.stages.size(), first.stages.size());
  EXPECT_EQ(all.likelihood_evaluations > first.likelihood_evaluations, true);
  for (Eigen::Index i = 0; i < all.particles.rows(); i += 97)
    EXPECT_NEAR(all.log_likelihood(i), model.log_likelihood(all.particles.row(i).transpose()),
                1e-9);
}

TEST(TemperedSmc, AnIndicatorLikelihoodGivesTheTruncatedNormal) {
  // L(w) = 1 for w0 > 0.7: the posterior of w0 is N(0, 1) truncated to
  // (0.7, ∞), mean φ(0.7)/Q(0.7) = 1.2918, and Z = Q(0.7) = 0.24196; w1 keeps
  // its prior.
  const double cut = 0.7;
  const double tail = 0.5 * std::erfc(cut / std::numbers::sqrt2);
  const double truncated_mean =
      std::exp(-0.5 * cut * cut) / std::sqrt(2.0 * std::numbers::pi) / tail;
  SmcSettings settings;
  settings.seed = 77;
  const SmcPosterior p = sample_tempered(
      2,
      [&](const Eigen::VectorXd& w) {
        return w(0) > cut ? 0.0 : -std::numeric_limits<double>::infinity();
      },
      settings);
  EXPECT_GT(p.particles.col(0).minCoeff(), cut);
  EXPECT_NEAR(p.particles.col(0).mean(), truncated_mean, 0.03);
  EXPECT_NEAR(p.particles.col(1).mean(), 0.0, 0.08);
  EXPECT_NEAR(p.log_evidence, std::log(tail), 0.05);
}

TEST(TemperedSmc, TheSameSeedGivesTheSameSamplesOnAnyNumberOfThreads) {
  const LinearGaussian model;
  SmcSettings settings;
  settings.particles = 500;
  settings.seed = 5;
  const auto likelihood = [&](const Eigen::VectorXd& w) { return model.log_likelihood(w); };
  settings.threads = 1;
  const SmcPosterior one = sample_tempered(3, likelihood, settings);
  settings.threads = 3;
  const SmcPosterior three = sample_tempered(3, likelihood, settings);
  EXPECT_EQ(one.particles, three.particles);
  EXPECT_EQ(one.log_evidence, three.log_evidence);
  settings.seed = 6;
  const SmcPosterior other = sample_tempered(3, likelihood, settings);
  EXPECT_NE(one.particles, other.particles);
}

TEST(TemperedSmc, DataNoPriorParticleExplainsIsRefused) {
  SmcSettings settings;
  settings.particles = 100;
  EXPECT_THROW(
      sample_tempered(
          1, [](const Eigen::VectorXd&) { return -std::numeric_limits<double>::infinity(); },
          settings),
      NumericalError);
  EXPECT_THROW(sample_tempered(
                   0, [](const Eigen::VectorXd&) { return 0.0; }, settings),
               std::invalid_argument);
  settings.particles = 5;
  EXPECT_THROW(sample_tempered(
                   1, [](const Eigen::VectorXd&) { return 0.0; }, settings),
               std::invalid_argument);
}

TEST(TemperedSmc, WithoutDataThePosteriorIsThePrior) {
  SmcSettings settings;
  settings.particles = 2000;
  const SmcPosterior p = sample_tempered(
      2, [](const Eigen::VectorXd&) { return 0.0; }, settings);
  EXPECT_EQ(p.log_evidence, 0.0);
  EXPECT_NEAR(p.particles.col(0).mean(), 0.0, 0.1);
  const double sd =
      std::sqrt((p.particles.col(1).array() - p.particles.col(1).mean()).square().mean());
  EXPECT_NEAR(sd, 1.0, 0.06);
}

}  // namespace
}  // namespace robomill::learning
