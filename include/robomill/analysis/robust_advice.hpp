#pragma once
// `robomill advise` of an uncertain job (issue 33, deliverable 3): beside the
// nominal advice, the spindle speed and axial depth of the highest material
// removal rate whose chance of chatter over the draws of the job's uncertain
// inputs is at most advise.max_chatter_probability (default 5 %).
//
// P(chatter) at (Ω, ap) is the fraction of draws whose limit at Ω (the
// lowest station's, by the advice's method) lies strictly below ap, as in
// the stability band (stability_band.hpp; a draw stable up to depth_max
// counts as stable). Over n draws the deepest depth with P(chatter) ≤ p is
// the (⌊p n⌋ + 1)-th smallest limit: at most ⌊p n⌋ draws lie below it. The
// planner (planning/cutting_advice.hpp) scans the speeds as for the nominal
// advice with that robust limit in place of the stations' diagram and a
// margin of 1 (the probability is the margin): the largest multiple of the
// depth step under it, the offset limit on the nominal structure, the fine
// rescan around the best speed. Every draw is a whole job (job_of_draw), so
// a drawn robot stiffness moves the modes at every station.

#include <vector>

#include "robomill/analysis/job_draws.hpp"
#include "robomill/job/job.hpp"
#include "robomill/planning/cutting_advice.hpp"
#include "robomill/uncertainty/sample_statistics.hpp"

namespace robomill::analysis {

struct RobustCuttingAdvice {
  JobDraws draws;                         ///< the draws' variables, values and source
  int draw_count = 0;                     ///< number of draws
  double max_chatter_probability = 0.05;  ///< the bound p (advise.max_chatter_probability)
  /// The scan under the robust limit: its rows' limit_depth_m is the
  /// robust limit (the (⌊p n⌋ + 1)-th smallest draw limit, depth_max where
  /// fewer draws are limited), its best the robust advice; its Floquet check
  /// is the nominal structure's at that point.
  planning::CuttingAdvice advice;
  /// P(chatter) at the robust advice (≤ p by construction) and at the
  /// nominal advice's speed and depth, each with its binomial standard error.
  uncertainty::Estimate p_chatter, nominal_p_chatter;
  double elapsed_s = 0.0;  ///< the draws' limits and the scan (s)
};

/// The robust advice of `job` (advise: and uncertainty: sections) beside its
/// `nominal` advice (cutting_parameter_advice(job).advice), the draws in
/// parallel on up to `threads` threads (0: all cores); the result does not
/// depend on the thread count. Throws InputError when the job has no
/// uncertainty: section, or naming the draw and its values when a draw is
/// refused (job_of_draw, for_each_draw).
RobustCuttingAdvice robust_cutting_advice(const job::Job& job,
                                          const planning::CuttingAdvice& nominal, int threads = 0);

}  // namespace robomill::analysis
