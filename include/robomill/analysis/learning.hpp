#pragma once
// Bayesian updating of a job's uncertain inputs from its test cuts, and the
// next test to run (`robomill learn`, issue 35; docs/learning.md).
//
// Prior: the job's `uncertainty:` variables (their distributions and
// correlation). Evidence: the job's `experiments:`, each a verdict (probit
// around the zero-order limit, learning/stability_evidence.hpp) and, for a
// cut that chattered, the chatter frequency heard. Posterior: samples by
// tempered sequential Monte Carlo (learning/tempered_smc.hpp) over the
// variables' standard-normal coordinates, evaluating the limit with
// LearningModel. Stateless: every run starts from the prior and all the
// experiments, so the same job gives the same posterior (for a seed)
// whatever was run before.
//
// From the prior draws (the job's own, as `stability` makes them) and the
// posterior samples: the quantile lobes and chatter-probability map of each
// (StabilityBand, as `stability` writes them), every variable's summary, and
// the next test among stability.speeds × the map's depths:
//   information   — the largest expected information about the boundary
//                   (bits; learning::expected_information_bits) among the
//                   candidates whose predicted P(chatter) ≤ learn.max_risk;
//   productivity  — the largest material removal rate ap·ae·f_z·N·n among
//                   them;
//   switching     — information while the boundary's spread (the mean over
//                   the speeds of the 5-95 % band's width) still shrinks by
//                   learn.spread_shrink with the latest test (the posterior
//                   without it is sampled too), productivity after.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "robomill/analysis/stability_band.hpp"
#include "robomill/job/job.hpp"
#include "robomill/learning/tempered_smc.hpp"

namespace robomill::analysis {

/// A variable's distribution summarized: mean, sd and the 5/50/95 % quantiles.
struct VariableSummary {
  double mean = 0.0, sd = 0.0, q05 = 0.0, q50 = 0.0, q95 = 0.0;
};

/// One experiment as the learning used it.
struct LearnedExperiment {
  std::size_t index = 0;  ///< in job.experiments
  int line = 0;
  double spindle_rad_s = 0.0, depth_m = 0.0;
  bool chatter = false;
  double chatter_frequency_hz = 0.0;  ///< measured; 0: none
  /// The predicted probability of chatter (the probit's mean over the
  /// samples) before and after learning.
  double p_chatter_prior = 0.0, p_chatter_posterior = 0.0;
  /// The posterior median of the predicted family member nearest to the
  /// measured chatter frequency (Hz); 0 without a measured one.
  double predicted_chatter_frequency_hz = 0.0;
  int place = 0;         ///< where it was cut (LearningModel::places(); 0 without a robot)
  double power_w = 0.0;  ///< measured spindle power (W); 0: none
  double predicted_power_w = 0.0;  ///< the posterior median of the law's mean power (W)
  /// Whether the verdict, chatter frequency and spindle speed are its
  /// recording's (`listen`'s analysis; spindle_rad_s is then the measured one).
  bool from_recording = false;
};

/// A mode fitted to a hammer test's FRF, and the nearest predicted mode
/// (the one its likelihood compares it with) before and after learning.
struct LearnedHammerMode {
  std::size_t index = 0;  ///< the test in job.experiments
  int line = 0;
  int place = 0;  ///< where it was measured
  int axis = 0;   ///< the driving-point axis: 0 x, 1 y, 2 z (tool frame)
  double fn_hz = 0.0, zeta = 0.0, k_n_per_m = 0.0;  ///< fitted
  /// The nearest predicted mode's fn and k along the axis: medians over the
  /// prior draws and the posterior samples (0 when none has one).
  double prior_fn_hz = 0.0, prior_k_n_per_m = 0.0;
  double posterior_fn_hz = 0.0, posterior_k_n_per_m = 0.0;
};

/// An experiment left out, and why (a recording judged "unknown").
struct SkippedExperiment {
  std::size_t index = 0;  ///< in job.experiments
  int line = 0;
  std::string reason;
};

/// The test to run next.
struct NextTest {
  bool found = false;    ///< false: no candidate within max_risk
  std::string strategy;  ///< "information" or "productivity": the one that chose it
  std::string reason;    ///< why this strategy (switching), or why none was found
  double spindle_rad_s = 0.0;
  double depth_m = 0.0;
  double p_chatter = 0.0;          ///< predicted probability of chatter
  double information_bits = 0.0;   ///< expected information about the boundary
  double removal_rate_m3_s = 0.0;  ///< ap · ae · f_z · N · n
  int place = 0;                   ///< where (a robot's posture: LearningResult::places)
};

/// The lobes before and after the tests at one of a robot's places.
struct PlaceBands {
  std::vector<double> posture_rad;  ///< the joint angles
  StabilityBand prior, posterior;
};

/// Everything `robomill learn` reports.
struct LearningResult {
  std::vector<std::string> names;    ///< the variables
  std::vector<std::string> units;    ///< their SI unit, or "factor" for scale variables
  Eigen::MatrixXd posterior_values;  ///< samples × variables (SI or factors)
  std::vector<VariableSummary> prior, posterior;  ///< per variable
  Eigen::MatrixXd posterior_correlation;          ///< variables × variables (Pearson)
  /// At the first place (robot.posture for a robot; the modal table's
  /// structure otherwise).
  StabilityBand prior_band, posterior_band;
  /// For a robot, every place (postures, rad): robot.posture, the tests'
  /// postures and learn.places, in that order; the first is the one above.
  std::vector<std::vector<double>> places_rad;
  /// The bands at the places after the first.
  std::vector<PlaceBands> more_places;
  /// The mean over the speeds (and places) of the band's 5-95 % width (m): prior, posterior,
  /// and the posterior without the latest experiment (NaN when not sampled).
  double prior_spread_m = 0.0, posterior_spread_m = 0.0, spread_before_last_m = 0.0;
  std::vector<LearnedExperiment> experiments;  ///< the ones used
  std::vector<SkippedExperiment> skipped;
  std::vector<LearnedHammerMode> hammer_modes;  ///< every hammer test's fitted modes
  std::vector<std::string> warnings;            ///< contradictory or surprising tests
  learning::SmcPosterior sampler;  ///< diagnostics (its particles are the w coordinates)
  NextTest next;
  double elapsed_s = 0.0;
};

/// Learns the job's uncertain inputs from its experiments on up to `threads`
/// threads (0: all cores). Throws InputError naming the section, variable or
/// experiment that does not fit (LearningModel), NumericalError when the
/// sampler fails.
LearningResult learn(const job::Job& job, int threads = 0);

}  // namespace robomill::analysis
