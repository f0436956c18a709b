#pragma once
// The stability lobes of an uncertain job (`robomill stability` with an
// `uncertainty:` section, issue 33 deliverable 2): the primary diagram of
// every draw of the uncertain inputs, at the nominal diagram's spindle
// speeds, summarized as quantile lobes (5 %, 50 %, 95 %) and as a
// chatter-probability map over (depth, speed), each number with its
// Monte-Carlo standard error (docs/uncertainty.md §4).
//
// Each draw is the job with the draw's values set (job_draws.hpp,
// job_of_draw) and its diagram is analysis::stability_diagram's, by the same
// method and options as the nominal one: with zero spread every draw
// reproduces the nominal lobe. A draw computes only the primary diagram
// (diagram.primary()): no spectral-radius map, no second diagram of
// `modes: both`, and with `deformation:` only the traditional diagram (the
// one `primary()` is), so it costs one diagram, not four.
//
// Everything is in SI units; the command (src/commands/stability.cpp) writes
// lobes_quantiles.csv, chatter_probability.csv and summary.json's
// "uncertainty" from it.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "robomill/analysis/job_draws.hpp"
#include "robomill/analysis/stability_diagram.hpp"
#include "robomill/job/job.hpp"
#include "robomill/uncertainty/sample_statistics.hpp"

namespace robomill::analysis {

/// The probabilities of the quantile lobes: 5 %, 50 % and 95 %.
inline constexpr double kBandLowerProbability = 0.05;
inline constexpr double kBandMedianProbability = 0.5;
inline constexpr double kBandUpperProbability = 0.95;

/// How many robust pockets a band reports at most.
inline constexpr int kMaxRobustPockets = 5;

/// A robust pocket: a spindle speed where the 5 % quantile lobe has a local
/// maximum (the depth that 95 % of the draws allow is highest around it).
struct RobustPocket {
  double spindle_rad_s = 0.0;      ///< the speed (rad/s); the middle of a flat top
  double depth_limit_q05_m = 0.0;  ///< the 5 % quantile of the limit there (m)
  double standard_error_m = 0.0;   ///< its Monte-Carlo standard error (m)
};

/// The lobes of every draw and what they say.
///
/// A draw whose diagram is stable up to stability.depth_max at a speed
/// (StabilityLimit::limited false) has the limit depth_max there in
/// `limits_m` and in the quantiles (read a quantile equal to depth_max as
/// "at least depth_max"), and counts as stable at every depth of the
/// probability map, depth_max included.
struct StabilityBand {
  JobDraws draws;      ///< the draws' variables, values (samples × variables) and source
  int draw_count = 0;  ///< number of draws (draws.values.rows())

  std::vector<double> speeds_rad_s;     ///< the nominal diagram's speeds (rad/s), ascending
  std::vector<double> nominal_limit_m;  ///< the nominal primary limit per speed (m)

  /// The limit of draw i at speed s (draws × speeds, m): the primary
  /// diagram's depth_limit_m (depth_max where not limited).
  Eigen::MatrixXd limits_m;
  /// Whether draw i is limited at speed s within depth_max (draws × speeds).
  Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> limited;

  /// Per speed, the empirical 5 %, 50 % and 95 % quantiles of the limit over
  /// the draws (m), each with its order-statistic standard error
  /// (uncertainty::empirical_quantile: Hyndman & Fan definition 7).
  std::vector<uncertainty::Estimate> q05_m, q50_m, q95_m;

  /// The map's depths (m): stability.depths values evenly spaced from
  /// depth_max / depths up to depth_max, as the spectral-radius map's.
  std::vector<double> depths_m;
  /// P(chatter) at (depth d, speed s) (depths × speeds): the fraction of
  /// draws whose limit lies strictly below the depth
  /// (uncertainty::fraction_below), unlimited draws counting as stable. For
  /// a speed it never decreases with depth, by construction: the draws
  /// below a depth are also below every deeper one.
  Eigen::MatrixXd p_chatter;
  /// The binomial standard error √(p(1 − p)/n) of each p_chatter (depths ×
  /// speeds). It is the bound for independent draws; for Sobol draws the
  /// error is smaller. It is 0 where p is 0 or 1: then 3/n bounds the unseen
  /// probability at 95 % confidence (the rule of three, docs/uncertainty.md).
  Eigen::MatrixXd p_chatter_se;

  double q05_min_m = 0.0;              ///< the lowest 5 % quantile over the speeds (m)
  double q05_min_spindle_rad_s = 0.0;  ///< its speed (rad/s)
  double q95_max_m = 0.0;              ///< the highest 95 % quantile over the speeds (m)
  double q95_max_spindle_rad_s = 0.0;  ///< its speed (rad/s)
  /// The local maxima of the 5 % quantile lobe over the speeds, deepest
  /// first, at most kMaxRobustPockets. A flat top counts once (at its middle
  /// speed); a maximum at either end of the speed range counts too (the best
  /// speed may then lie beyond the range).
  std::vector<RobustPocket> robust_pockets;

  double elapsed_s = 0.0;  ///< drawing and computing every draw's diagram (s)
};

/// The local maxima of a lobe sampled at `speeds_rad_s` (as RobustPocket),
/// deepest first (ties: the lower speed first), at most `max_count`; the
/// sizes must agree (std::invalid_argument otherwise).
std::vector<RobustPocket> robust_pockets(const std::vector<double>& speeds_rad_s,
                                         const std::vector<uncertainty::Estimate>& lobe_m,
                                         int max_count = kMaxRobustPockets);

/// Fills what a band says from its draws' limits: given band.speeds_rad_s,
/// limits_m and limited (draws × speeds), sets draw_count, the map's depths
/// (settings.depths values up to settings.depth_max, as the spectral-radius
/// map's), the quantile lobes, p_chatter and its standard error, the
/// extremes and the robust pockets. The quantiles of every speed are
/// computed in parallel on up to `threads` threads. Throws
/// std::invalid_argument when the sizes disagree or there are no draws.
void summarize_band(StabilityBand& band, const job::StabilitySettings& settings, int threads = 0);

/// The band of `job` (which has an `uncertainty:` section) around its
/// `nominal` diagram (stability_diagram(job)): the draws of
/// draw_job_inputs(job), each draw's primary diagram by
/// stability_diagram(job_of_draw(job, draws, i), 1), the draws in parallel on
/// up to `threads` threads (0: all cores). Every draw writes only its own
/// row, so the result does not depend on the thread count, and neither does
/// the error reported when draws fail: the first failing draw's.
///
/// Throws InputError when the job has no uncertainty section, the nominal
/// diagram has no speeds, a draw cannot be made (job_of_draw names the
/// variable and the draw) or a draw's diagram refuses its inputs (the
/// message names the draw and its values).
StabilityBand stability_band(const job::Job& job, const StabilityDiagram& nominal, int threads = 0);

}  // namespace robomill::analysis
