#include "robomill/analysis/measured_frf_fit.hpp"

#include <algorithm>
#include <chrono>
#include <utility>

#include "robomill/core/error.hpp"

namespace robomill::analysis {

MeasuredFrfFit measured_frf_fit(const job::Job& job) {
  if (job.frf_files.empty())
    throw InputError("dynamics.frf", 0, "fit-modes needs measured FRF files (dynamics.frf)");
  const auto start = std::chrono::steady_clock::now();
  const std::vector<dynamics::Frf> measured = load_measured_frfs(job);
  StructureFit structure = fit_structure(job, measured);
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  std::vector<std::size_t> first_fitted_point;
  double worst_fit_error = 0.0;
  for (std::size_t f = 0; f < structure.fits.size(); ++f) {
    const dynamics::Frf& frf = structure.measured[f];
    const dynamics::ModalFit& fit = structure.fits[f];
    const dynamics::Frf& fitted = fit.fitted.front();
    first_fitted_point.push_back(frf.frequency_hz.size() - fitted.frequency_hz.size());
    worst_fit_error = std::max(worst_fit_error, fit.overall_error);
  }
  return {measured.size(), std::move(structure), std::move(first_fitted_point), worst_fit_error,
          elapsed_s};
}

}  // namespace robomill::analysis
