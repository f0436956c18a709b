#pragma once
// What a test cut says about the stability limit: the likelihood terms of
// issue 35 (docs/learning.md, "The likelihood") and the expected information
// of a test not yet run. Numbers only (SI); the job-level learning is
// analysis/learning.hpp.
//
// The verdict. A cut at depth ap is predicted to chatter when ap exceeds the
// limit a_lim(θ) of the model with parameters θ; the model and the
// measurement are not exact, so the probability of a chatter verdict is a
// probit around the limit (Karandikar, Abbas & Schmitz, Precision
// Engineering 38, 2014; Cornelius, Karandikar & Schmitz, npj Adv. Manuf.
// 2024, the anchor's physicsFunZOA_StabilityLikelihood: normcdf(ap, a_lim, σ)),
// mixed with a small mislabel probability ε (a verdict called wrong, a test
// recorded at the wrong depth): one contradictory test then lowers a
// hypothesis' weight by ε instead of excluding it, and the posterior stays
// proper when the tests contradict each other:
//   P(chatter | θ) = ε/2 + (1 − ε) Φ((ap − a_lim(θ)) / σ),
//   σ = √(σ_abs² + (σ_rel · a_lim)²).
//
// The chatter frequency. A measured chatter line f_m is compared with the
// nearest member of the predicted family |±f_c + k f_tooth| (k integer: the
// regenerative frequencies repeat at every tooth-passing harmonic, and a
// spectrum shows them folded at zero), by a normal density of spread σ_f:
//   log p(f_m | θ) = log N(f_m − f_family; 0, σ_f²).
//
// The expected information of a test (its mutual information with θ, in
// bits; Houlsby, Huszár, Ghahramani & Lengyel, "Bayesian active learning
// for classification and preference learning", 2011): with p_i the chatter
// probability under posterior sample i,
//   I = H(mean p_i) − mean H(p_i),   H(p) = −p log₂ p − (1 − p) log₂(1 − p).
// It is largest where the samples disagree most about the verdict and is 0
// where they all agree; the noise of the verdict itself (σ, ε) is not
// counted as information.

#include <span>

namespace robomill::learning {

/// The spread of the verdict around the predicted limit.
struct VerdictModel {
  double sd_m = 0.1e-3;       ///< σ_abs (m)
  double relative_sd = 0.05;  ///< σ_rel (fraction of the limit)
  double mislabel = 0.01;     ///< ε in [0, 1)
};

/// σ = √(σ_abs² + (σ_rel · a_lim)²) for a finite limit (m).
double verdict_sd_m(double limit_m, const VerdictModel& model);

/// P(chatter | a_lim): ε/2 + (1 − ε) Φ((ap − a_lim)/σ). An infinite limit
/// (stable at every depth) gives ε/2.
double chatter_probability(double depth_m, double limit_m, const VerdictModel& model);

/// log P(verdict | a_lim), accurate far in the tails (log Φ through the
/// complementary error function), finite whenever ε > 0.
double log_verdict_likelihood(bool chatter, double depth_m, double limit_m,
                              const VerdictModel& model);

/// The member of the family |±f_c + k f_tooth| (k = ..., −1, 0, 1, ...)
/// nearest to f_m (Hz). f_tooth ≤ 0 gives f_c itself.
double nearest_chatter_family_hz(double measured_hz, double predicted_hz, double tooth_hz);

/// log N(f_m − nearest family member; 0, σ_f²).
double log_chatter_frequency_likelihood(double measured_hz, double predicted_hz, double tooth_hz,
                                        double sd_hz);

/// H(p) in bits (0 at p = 0 or 1).
double binary_entropy_bits(double p);

/// The expected information of a test about θ (bits), from the chatter
/// probability under every posterior sample: H(mean p) − mean H(p) ≥ 0.
double expected_information_bits(std::span<const double> p_chatter);

}  // namespace robomill::learning
