#pragma once
// Sequential Monte Carlo with likelihood tempering: samples of a posterior
// p(w | data) ∝ N(w; 0, I) · L(w) over a few to a few tens of variables
// (issue 35 deliverable 3; docs/learning.md, "The sampler").
//
// The prior is the standard normal in every coordinate: the caller maps w to
// its variables (a quantile transform x_j = F_j⁻¹(Φ(w_j)), with a Gaussian
// copula for correlated ones), so one sampler serves every family without a
// Jacobian, and the moves never leave a variable's support.
//
// The bridge p_β ∝ N(w; 0, I) · L(w)^β runs from the prior (β = 0) to the
// posterior (β = 1) (Neal, "Annealed importance sampling", Statistics and
// Computing 11, 2001; Del Moral, Doucet & Jasra, "Sequential Monte Carlo
// samplers", JRSS B 68, 2006). Each stage
//  1. chooses the next β by bisection so that the incremental weights
//     exp((β' − β) ℓ_i) keep an effective sample size of `ess_fraction` of
//     the particles (Jasra, Stephens, Doucet & Tsagaris, Scand. J. Stat. 38,
//     2011: adaptive tempering);
//  2. adds log mean exp((β' − β) ℓ_i) to the log evidence log ∫ N(w) L(w) dw
//     (the particles are equally weighted at the start of every stage);
//  3. resamples (systematic resampling, Kitagawa 1996);
//  4. moves every particle by random-walk Metropolis steps invariant for
//     p_β', with the proposal covariance s² Σ̂, Σ̂ the particles' covariance
//     (adaptive: Haario, Saksman & Tamminen, Bernoulli 7, 2001, as the
//     anchor's adaptive Metropolis; here one Σ̂ per stage from the
//     population, Chopin 2002), s starting at 2.38/√d (Roberts, Gelman &
//     Gilks 1997) and scaled by the last stage's acceptance; as many steps
//     as make 1 − (1 − acceptance)^steps ≥ 0.99, i.e. every particle has
//     most likely moved at least once (Drovandi & Pettitt, Biometrics 67,
//     2011), between `min_moves` and `max_moves`.
// After β = 1 the particles are equally weighted posterior samples.
//
// extend_tempered continues such samples to more data (sequential Bayesian
// updating: the posterior of the first tests is the prior of the next):
// starting from samples of N(w)·L0(w) it tempers in L1, each move invariant
// for N·L0·L1^β. `robomill learn` samples its tests but the latest this way,
// then extends to the latest, so one run gives the posterior with and
// without it at little more than the cost of one.
//
// Reproducible: every random number comes from a counter-based generator
// keyed by (seed, stage, step, particle), so the samples do not depend on
// the number of threads. The likelihood is evaluated in parallel.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <vector>

namespace robomill::learning {

/// The log-likelihood ℓ(w) of one particle: finite or −∞ (impossible), never
/// NaN or +∞. Called from several threads at once.
using LogLikelihood = std::function<double(const Eigen::VectorXd& w)>;

/// A particle's log-likelihood in two parts: the data the starting particles
/// already sample (`settled`, L0) and the data being tempered in (`added`,
/// L1). Each finite or −∞, never NaN or +∞.
struct LogLikelihoodParts {
  double settled = 0.0;
  double added = 0.0;
};

/// Both parts at once (one model evaluation serves both). Called from
/// several threads at once.
using PartedLogLikelihood = std::function<LogLikelihoodParts(const Eigen::VectorXd& w)>;

/// How many particles, how fast the temperature rises, how much the moves mix.
struct SmcSettings {
  int particles = 4000;       ///< N ≥ 10
  std::uint64_t seed = 1;     ///< the random stream (same seed, same samples)
  double ess_fraction = 0.5;  ///< the effective sample size kept per stage, in (0, 1)
  int min_moves = 2;          ///< Metropolis steps per stage, at least
  int max_moves = 25;         ///< and at most
  int max_stages = 400;       ///< the tempering gives up (NumericalError) beyond this
  int threads = 0;            ///< 0: every core
};

/// What one tempering stage did.
struct SmcStage {
  double temperature = 0.0;     ///< β reached at the end of the stage
  double ess_fraction = 0.0;    ///< the incremental weights' ESS / N before resampling
  double acceptance = 0.0;      ///< the Metropolis acceptance over the stage's steps
  int moves = 0;                ///< Metropolis steps made
  double proposal_scale = 0.0;  ///< s of the proposal s² Σ̂
};

/// Equally weighted samples of the posterior and the run's diagnostics.
struct SmcPosterior {
  Eigen::MatrixXd particles;       ///< N × d, standard-normal coordinates w
  Eigen::VectorXd log_likelihood;  ///< ℓ of every particle
  double log_evidence = 0.0;       ///< log ∫ N(w; 0, I) L(w) dw (nats)
  std::vector<SmcStage> stages;
  double acceptance = 0.0;  ///< mean Metropolis acceptance over the stages
  /// The smallest incremental ESS / N of any stage (≥ ess_fraction unless a
  /// single step to β = 1 already kept more).
  double min_ess_fraction = 1.0;
  std::int64_t likelihood_evaluations = 0;
};

/// Samples N(w; 0, I_d) · L(w) by tempered SMC. Throws std::invalid_argument
/// for d < 1 or settings out of range; NumericalError when no prior particle
/// has a finite likelihood (no value the prior allows explains the data) or
/// the tempering needs more than max_stages stages. The likelihood's own
/// exceptions are rethrown.
SmcPosterior sample_tempered(int dimension, const LogLikelihood& log_likelihood,
                             const SmcSettings& settings);

/// Extends `start` (equally weighted samples of N(w)·L0(w), as
/// sample_tempered returns them) to N(w)·L0(w)·L1(w) by tempering in L1;
/// `log_likelihood` returns L0's and L1's logarithms. The particle count is
/// start's (settings.particles is not used). The result's log evidence is
/// start's plus log ∫ L1 dP0 (so log ∫ N L0 L1 dw), its stages follow
/// start's, and its random numbers are keyed after them. Throws
/// NumericalError when no particle has a finite L1 or L0 is −∞ for one.
SmcPosterior extend_tempered(const SmcPosterior& start, const PartedLogLikelihood& log_likelihood,
                             const SmcSettings& settings);

/// 64 pseudo-random bits from a key: SplitMix64's finalizer (Steele, Lea &
/// Flood, OOPSLA 2014) over the key's words, for counter-based streams.
std::uint64_t mix_bits(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0,
                       std::uint64_t c = 0, std::uint64_t d = 0) noexcept;

/// A uniform number in the open interval (0, 1) from 64 bits (their top 52
/// bits, centred in their cell: never 0 or 1).
double open_unit(std::uint64_t bits) noexcept;

}  // namespace robomill::learning
