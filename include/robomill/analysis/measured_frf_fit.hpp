#pragma once
// `robomill fit-modes` of a job: modal parameters from the job's measured
// FRFs (dynamics.frf), band by band (dynamics.fit), for the stability and
// simulation engines or for a modal table to paste into a job. SI units.

#include <cstddef>
#include <vector>

#include "robomill/analysis/structure.hpp"
#include "robomill/job/job.hpp"

namespace robomill::analysis {

struct MeasuredFrfFit {
  std::size_t frfs_read = 0;  ///< FRFs in the files of dynamics.frf, cross FRFs included
  /// The driving-point FRFs fitted, one fit each, and every fitted mode.
  StructureFit structure;
  /// Per fit, the measured point at the fitted grid's first frequency: the
  /// fit drops a 0 Hz point, so the grids align from the top.
  std::vector<std::size_t> first_fitted_point;
  double worst_fit_error = 0.0;  ///< the largest overall error of a fit
  double elapsed_s = 0.0;        ///< reading and fitting
};

/// Reads and fits the job's FRFs. Throws InputError naming `dynamics.frf`
/// without FRF files, and what load_measured_frfs and fit_structure throw.
MeasuredFrfFit measured_frf_fit(const job::Job& job);

}  // namespace robomill::analysis
