#include "robomill/learning/tempered_smc.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "robomill/core/error.hpp"
#include "robomill/core/parallel.hpp"

namespace robomill::learning {
namespace {

constexpr double kMinusInfinity = -std::numeric_limits<double>::infinity();

// Stream tags: which use a random number is for, so that two uses never share one.
constexpr std::uint64_t kInitialTag = 1, kResampleTag = 2, kProposalTag = 3, kAcceptTag = 4;

/// A standard normal deviate from a key (Box-Muller on two keyed uniforms).
double keyed_normal(std::uint64_t seed, std::uint64_t tag, std::uint64_t stage,
                    std::uint64_t particle, std::uint64_t index) {
  const double u1 = open_unit(mix_bits(seed, tag, stage, particle, 2 * index));
  const double u2 = open_unit(mix_bits(seed, tag, stage, particle, 2 * index + 1));
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

/// log mean exp(x_i), −∞ when every x_i is −∞.
double log_mean_exp(const Eigen::VectorXd& x) {
  const double peak = x.maxCoeff();
  if (peak == kMinusInfinity)
    return kMinusInfinity;
  return peak + std::log((x.array() - peak).exp().mean());
}

/// The effective sample size / N of weights exp(x_i): (Σw)² / (N Σw²).
double ess_fraction_of(const Eigen::VectorXd& log_weights) {
  const double peak = log_weights.maxCoeff();
  if (peak == kMinusInfinity)
    return 0.0;
  const Eigen::ArrayXd w = (log_weights.array() - peak).exp();
  return w.sum() * w.sum() / (static_cast<double>(w.size()) * w.square().sum());
}

/// The temperature step Δ ≤ room whose incremental weights exp(Δ ℓ_i) keep an
/// ESS of `target` (bisection on Δ: the ESS falls as Δ grows).
double next_step(const Eigen::VectorXd& log_likelihood, double room, double target) {
  if (ess_fraction_of(room * log_likelihood) >= target)
    return room;
  double low = 0.0, high = room;
  for (int i = 0; i < 60 && high - low > 1e-12 * room; ++i) {
    const double middle = 0.5 * (low + high);
    (ess_fraction_of(middle * log_likelihood) >= target ? low : high) = middle;
  }
  return std::max(low, 1e-12 * room);
}

/// Systematic resampling: the indices of N particles drawn with the weights
/// exp(log_weights) from one uniform offset.
std::vector<Eigen::Index> systematic_resample(const Eigen::VectorXd& log_weights, double offset) {
  const Eigen::Index n = log_weights.size();
  const Eigen::ArrayXd w = (log_weights.array() - log_weights.maxCoeff()).exp();
  const double total = w.sum();
  std::vector<Eigen::Index> chosen(static_cast<std::size_t>(n));
  double cumulative = w(0) / total;
  Eigen::Index source = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double u = (static_cast<double>(i) + offset) / static_cast<double>(n);
    while (u > cumulative && source + 1 < n)
      cumulative += w(++source) / total;
    chosen[static_cast<std::size_t>(i)] = source;
  }
  return chosen;
}

/// The lower Cholesky factor of the particles' covariance (with a small
/// ridge, so that a population collapsed in one direction still proposes).
Eigen::MatrixXd proposal_factor(const Eigen::MatrixXd& particles) {
  const Eigen::RowVectorXd mean = particles.colwise().mean();
  const Eigen::MatrixXd centred = particles.rowwise() - mean;
  Eigen::MatrixXd covariance = centred.transpose() * centred /
                               std::max<double>(1.0, static_cast<double>(particles.rows() - 1));
  const double ridge = 1e-8 + 1e-6 * covariance.diagonal().maxCoeff();
  covariance.diagonal().array() += ridge;
  return Eigen::LLT<Eigen::MatrixXd>(covariance).matrixL();
}

void check_settings(int dimension, const SmcSettings& s) {
  if (dimension < 1)
    throw std::invalid_argument("sample_tempered: dimension must be at least 1");
  if (s.particles < 10)
    throw std::invalid_argument("sample_tempered: at least 10 particles");
  if (!(s.ess_fraction > 0.0 && s.ess_fraction < 1.0))
    throw std::invalid_argument("sample_tempered: ess_fraction must lie in (0, 1)");
  if (s.min_moves < 1 || s.max_moves < s.min_moves || s.max_stages < 1)
    throw std::invalid_argument("sample_tempered: moves or stages out of range");
}

/// One population being tempered: the particles and both parts of their
/// log-likelihood.
struct Population {
  Eigen::MatrixXd w;
  Eigen::VectorXd settled;  ///< log L0
  Eigen::VectorXd added;    ///< log L1
};

/// log of the tempered target N(w) L0 L1^β (up to a constant), −∞ when
/// either part rules the particle out.
double log_target(double squared_norm, const LogLikelihoodParts& l, double beta) {
  if (l.settled == kMinusInfinity || (beta > 0.0 && l.added == kMinusInfinity))
    return kMinusInfinity;
  return -0.5 * squared_norm + l.settled + (beta > 0.0 ? beta * l.added : 0.0);
}

LogLikelihoodParts checked(const LogLikelihoodParts& l) {
  const auto bad = [](double x) { return std::isnan(x) || x == -kMinusInfinity; };
  if (bad(l.settled) || bad(l.added))
    throw NumericalError("sample_tempered: the likelihood returned NaN or +inf");
  return l;
}

/// One Metropolis step of every particle at temperature β; returns the
/// number of accepted proposals.
Eigen::Index metropolis_step(Population& p, const PartedLogLikelihood& log_likelihood,
                             const Eigen::MatrixXd& factor, double scale, double beta,
                             const SmcSettings& s, std::uint64_t stage, std::uint64_t step) {
  const Eigen::Index n = p.w.rows(), d = p.w.cols();
  std::vector<char> accepted(static_cast<std::size_t>(n), 0);
  core::parallel_blocks(
      static_cast<std::size_t>(n), s.threads, [&](std::size_t begin, std::size_t end) {
        Eigen::VectorXd z(d), proposal(d);
        for (std::size_t i = begin; i < end; ++i) {
          const auto row = static_cast<Eigen::Index>(i);
          for (Eigen::Index k = 0; k < d; ++k)
            z(k) = keyed_normal(s.seed, kProposalTag, stage, i,
                                step * 64 + static_cast<std::uint64_t>(k));
          proposal = p.w.row(row).transpose() + scale * (factor * z);
          const LogLikelihoodParts l = checked(log_likelihood(proposal));
          const double log_ratio =
              log_target(proposal.squaredNorm(), l, beta) -
              log_target(p.w.row(row).squaredNorm(), {p.settled(row), p.added(row)}, beta);
          const double u = open_unit(mix_bits(s.seed, kAcceptTag, stage, i, step));
          if (std::log(u) < log_ratio) {
            p.w.row(row) = proposal.transpose();
            p.settled(row) = l.settled;
            p.added(row) = l.added;
            accepted[i] = 1;
          }
        }
      });
  Eigen::Index count = 0;
  for (const char a : accepted)
    count += a;
  return count;
}

/// Resamples the population by the incremental weights (systematic).
void resample(Population& p, const Eigen::VectorXd& increments, double offset) {
  const std::vector<Eigen::Index> chosen = systematic_resample(increments, offset);
  Population next{Eigen::MatrixXd(p.w.rows(), p.w.cols()), Eigen::VectorXd(p.w.rows()),
                  Eigen::VectorXd(p.w.rows())};
  for (Eigen::Index i = 0; i < p.w.rows(); ++i) {
    const Eigen::Index from = chosen[static_cast<std::size_t>(i)];
    next.w.row(i) = p.w.row(from);
    next.settled(i) = p.settled(from);
    next.added(i) = p.added(from);
  }
  p = std::move(next);
}

/// Tempers `p.added` in, β from 0 to 1, adding to `out` (its stages, log
/// evidence, evaluations); stage numbers (the random keys) continue from
/// out.stages.size().
void temper(Population p, const PartedLogLikelihood& log_likelihood, const SmcSettings& settings,
            SmcPosterior& out) {
  const Eigen::Index n = p.w.rows();
  if (p.added.hasNaN() || p.added.maxCoeff() == kMinusInfinity)
    throw NumericalError(fmt::format(
        "sample_tempered: none of {} particles explains the data (every likelihood is 0)", n));
  const std::size_t first_stage = out.stages.size();
  double beta = 0.0;
  double scale = out.stages.empty() ? 2.38 / std::sqrt(static_cast<double>(p.w.cols()))
                                    : out.stages.back().proposal_scale;
  double acceptance_sum = out.acceptance * static_cast<double>(first_stage);
  for (std::uint64_t stage = first_stage + 1; beta < 1.0; ++stage) {
    if (static_cast<int>(stage - first_stage) > settings.max_stages)
      throw NumericalError(fmt::format(
          "sample_tempered: the tempering needed more than {} stages (reached β = {:.3g})",
          settings.max_stages, beta));
    const double step = next_step(p.added, 1.0 - beta, settings.ess_fraction);
    const double next_beta = (1.0 - beta - step) <= 1e-12 ? 1.0 : beta + step;
    const Eigen::VectorXd increments = (next_beta - beta) * p.added;
    SmcStage record;
    record.ess_fraction = ess_fraction_of(increments);
    out.log_evidence += log_mean_exp(increments);
    out.min_ess_fraction = std::min(out.min_ess_fraction, record.ess_fraction);
    beta = next_beta;
    resample(p, increments, open_unit(mix_bits(settings.seed, kResampleTag, stage)));

    const Eigen::MatrixXd factor = proposal_factor(p.w);
    Eigen::Index accepted = 0;
    int moves = 0;
    int wanted = settings.max_moves;
    while (moves < wanted) {
      accepted += metropolis_step(p, log_likelihood, factor, scale, beta, settings, stage,
                                  static_cast<std::uint64_t>(moves));
      ++moves;
      const double rate = static_cast<double>(accepted) / static_cast<double>(n * moves);
      // Steps after which a particle has most likely (99 %) moved at least once.
      wanted =
          rate <= 0.0
              ? settings.max_moves
              : static_cast<int>(std::ceil(std::log(0.01) / std::log1p(-std::min(rate, 0.99))));
      wanted = std::clamp(wanted, settings.min_moves, settings.max_moves);
    }
    out.likelihood_evaluations += n * moves;
    record.temperature = beta;
    record.moves = moves;
    record.acceptance = static_cast<double>(accepted) / static_cast<double>(n * moves);
    record.proposal_scale = scale;
    acceptance_sum += record.acceptance;
    out.stages.push_back(record);
    // Aim the next stage's proposals at about a quarter accepted.
    scale = std::clamp(scale * std::exp(2.0 * (record.acceptance - 0.25)), 0.02, 3.0);
  }
  out.acceptance = acceptance_sum / static_cast<double>(out.stages.size());
  out.particles = std::move(p.w);
  out.log_likelihood = p.settled + p.added;
}

}  // namespace

std::uint64_t mix_bits(std::uint64_t seed, std::uint64_t a, std::uint64_t b, std::uint64_t c,
                       std::uint64_t d) noexcept {
  const auto finalize = [](std::uint64_t z) {
    z += 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  };
  std::uint64_t h = finalize(seed);
  for (const std::uint64_t word : {a, b, c, d})
    h = finalize(h ^ word);
  return h;
}

double open_unit(std::uint64_t bits) noexcept {
  return (static_cast<double>(bits >> 12) + 0.5) * 0x1.0p-52;
}

SmcPosterior sample_tempered(int dimension, const LogLikelihood& log_likelihood,
                             const SmcSettings& settings) {
  check_settings(dimension, settings);
  const Eigen::Index n = settings.particles, d = dimension;
  Population p{Eigen::MatrixXd(n, d), Eigen::VectorXd::Zero(n), Eigen::VectorXd(n)};
  core::parallel_blocks(
      static_cast<std::size_t>(n), settings.threads, [&](std::size_t begin, std::size_t end) {
        Eigen::VectorXd w(d);
        for (std::size_t i = begin; i < end; ++i) {
          for (Eigen::Index k = 0; k < d; ++k)
            w(k) = keyed_normal(settings.seed, kInitialTag, 0, i, static_cast<std::uint64_t>(k));
          const auto row = static_cast<Eigen::Index>(i);
          p.w.row(row) = w.transpose();
          p.added(row) = checked({0.0, log_likelihood(w)}).added;
        }
      });
  SmcPosterior out;
  out.likelihood_evaluations = n;
  temper(
      std::move(p),
      [&](const Eigen::VectorXd& w) {
        return LogLikelihoodParts{0.0, log_likelihood(w)};
      },
      settings, out);
  return out;
}

SmcPosterior extend_tempered(const SmcPosterior& start, const PartedLogLikelihood& log_likelihood,
                             const SmcSettings& settings) {
  const Eigen::Index n = start.particles.rows(), d = start.particles.cols();
  SmcSettings s = settings;
  s.particles = static_cast<int>(n);
  check_settings(static_cast<int>(d), s);
  Population p{start.particles, Eigen::VectorXd(n), Eigen::VectorXd(n)};
  core::parallel_blocks(
      static_cast<std::size_t>(n), s.threads, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
          const auto row = static_cast<Eigen::Index>(i);
          const LogLikelihoodParts l = checked(log_likelihood(p.w.row(row).transpose()));
          p.settled(row) = l.settled;
          p.added(row) = l.added;
        }
      });
  if (p.settled.minCoeff() == kMinusInfinity)
    throw NumericalError("extend_tempered: a starting particle has zero likelihood under L0");
  SmcPosterior out;
  out.log_evidence = start.log_evidence;
  out.stages = start.stages;
  out.acceptance = start.acceptance;
  out.min_ess_fraction = start.min_ess_fraction;
  out.likelihood_evaluations = start.likelihood_evaluations + n;
  temper(std::move(p), log_likelihood, s, out);
  return out;
}

}  // namespace robomill::learning
