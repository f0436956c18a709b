#include "robomill/analysis/robust_advice.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <utility>

#include "robomill/analysis/cutting_parameter_advice.hpp"
#include "robomill/core/error.hpp"
#include "robomill/stability/regenerative_model.hpp"
#include "robomill/stability/zero_order.hpp"
#include "robomill/tool/tool.hpp"
#include "robomill/uncertainty/sample_statistics.hpp"

namespace robomill::analysis {
namespace {

/// A draw stable up to depth_max at a speed: stable at every depth.
constexpr double kStableEverywhere = std::numeric_limits<double>::infinity();

/// The draws' stability limits at any set of speeds, each draw a whole job
/// with its stations; every speed evaluated is kept for the probabilities
/// at the advised points.
class DrawLimits {
 public:
  DrawLimits(const job::Job& job, const JobDraws& draws, int threads)
      : job_(job), draws_(draws), threads_(threads) {
    // A0 is the same for every draw when the draws keep the nominal cut
    // (job_draws.hpp): its basis is averaged once (zero_order.hpp).
    if (job.advise->limit.method == planning::LimitMethod::zoa && draws_keep_the_cut(job))
      basis_ = stability::mean_cutting_stiffness_basis(tool::Tool(*job.tool), *job.cutting,
                                                       *job.process);
  }

  /// columns[k][i]: draw i's lowest station limit at speeds[k] (m), +∞ where
  /// no station is limited within depth_max.
  std::vector<std::vector<double>> at(const std::vector<double>& speeds) {
    const auto n = static_cast<std::size_t>(draws_.values.rows());
    std::vector<std::vector<double>> rows(n);
    for_each_draw(draws_, threads_, [&](std::size_t i) { rows[i] = draw_row(i, speeds); });
    std::vector<std::vector<double>> columns(speeds.size(), std::vector<double>(n));
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t k = 0; k < speeds.size(); ++k)
        columns[k][i] = rows[i][k];
    for (std::size_t k = 0; k < speeds.size(); ++k)
      evaluated_.emplace_back(speeds[k], columns[k]);
    return columns;
  }

  /// The draws' limits at a speed evaluated before, or nullptr.
  const std::vector<double>* find(double spindle_rad_s) const {
    for (const auto& [speed, column] : evaluated_)
      if (speed == spindle_rad_s)
        return &column;
    return nullptr;
  }

 private:
  std::vector<double> draw_row(std::size_t i, const std::vector<double>& speeds) const {
    const job::Job draw_job = job_of_draw(job_, draws_, i);
    const std::optional<robot::RobotModel> robot = advice_robot(draw_job);
    const std::vector<dynamics::ModalModel> stations = advice_stations(draw_job, robot);
    const planning::LimitSettings& limit = draw_job.advise->limit;
    const tool::Tool cutter(*draw_job.tool);
    std::vector<double> row(speeds.size(), kStableEverywhere);
    for (const dynamics::ModalModel& station : stations) {
      const stability::RegenerativeModel model(cutter, *draw_job.cutting, *draw_job.process,
                                               station);
      if (basis_) {
        // The planner's zero-order limit (planning::limit_curve) with A0
        // from the shared basis instead of its own average.
        stability::ZeroOrderOptions options;
        options.depth_max_m = limit.depth_max_m;
        const stability::ZeroOrderSolver solver((*basis_)(model.law()), cutter.teeth(), station,
                                                options);
        for (std::size_t k = 0; k < speeds.size(); ++k) {
          const stability::ZeroOrderLimit z = solver.limit(speeds[k]);
          if (z.limited)
            row[k] = std::min(row[k], z.depth_limit_m);
        }
        continue;
      }
      const std::vector<stability::LobePoint> curve =
          planning::limit_curve(model, speeds, limit, 1);
      for (std::size_t k = 0; k < speeds.size(); ++k)
        if (curve[k].limited)
          row[k] = std::min(row[k], curve[k].depth_limit_m);
    }
    return row;
  }

  const job::Job& job_;
  const JobDraws& draws_;
  int threads_;
  std::optional<stability::MeanCuttingStiffnessBasis> basis_;
  std::vector<std::pair<double, std::vector<double>>> evaluated_;
};

/// The deepest depth with P(chatter) ≤ p over the draws' limits at one
/// speed: the (⌊p n⌋ + 1)-th smallest limit, depth_max where that draw (or
/// every draw, p n ≥ n) is stable up to depth_max.
stability::LobePoint robust_limit(double spindle_rad_s, const std::vector<double>& limits,
                                  double max_chatter_probability, double depth_max_m) {
  stability::LobePoint point;
  point.spindle_rad_s = spindle_rad_s;
  point.depth_limit_m = depth_max_m;
  point.bifurcation = "none";
  const std::optional<double> at =
      uncertainty::value_at_fraction_bound(limits, max_chatter_probability);
  if (at && *at <= depth_max_m) {
    point.depth_limit_m = *at;
    point.limited = true;
    point.bifurcation = "hopf";
  }
  return point;
}

}  // namespace

RobustCuttingAdvice robust_cutting_advice(const job::Job& job,
                                          const planning::CuttingAdvice& nominal, int threads) {
  if (!job.uncertainty)
    throw InputError("uncertainty", 0, "the robust advice needs an uncertainty: section");
  if (!job.advise)
    throw InputError("advise", 0, "required: the advise: section");
  const auto start = std::chrono::steady_clock::now();
  const job::AdviseSettings& settings = *job.advise;
  RobustCuttingAdvice result;
  result.draws = draw_job_inputs(job);
  result.draw_count = static_cast<int>(result.draws.values.rows());
  if (result.draw_count < 1)
    throw InputError("uncertainty.samples", 0, "no draws to compute the robust advice from");
  result.max_chatter_probability = settings.max_chatter_probability;

  DrawLimits limits(job, result.draws, threads);
  planning::AdviceOptions options;
  options.limit = settings.limit;
  options.peaks = settings.peaks;
  options.threads = threads;
  options.limit_source = [&](const std::vector<double>& speeds) {
    const std::vector<std::vector<double>> columns = limits.at(speeds);
    std::vector<stability::LobePoint> curve;
    curve.reserve(speeds.size());
    for (std::size_t k = 0; k < speeds.size(); ++k)
      curve.push_back(robust_limit(speeds[k], columns[k], settings.max_chatter_probability,
                                   settings.limit.depth_max_m));
    return curve;
  };
  // The probability is the margin: the robust limit already keeps it.
  planning::AdviceLimits robust_limits = settings.limits;
  robust_limits.stability_margin = 1.0;
  const std::optional<robot::RobotModel> robot = advice_robot(job);
  const std::vector<dynamics::ModalModel> stations = advice_stations(job, robot);
  try {
    result.advice = planning::advise_cutting(tool::Tool(*job.tool), *job.cutting, *job.process,
                                             stations, robust_limits, options);
  } catch (const std::invalid_argument& error) {
    throw InputError("advise", 0, error.what());
  }

  // P(chatter) at a point: the draws' limits at its speed (evaluated by the
  // scan, or now), the fraction strictly below its depth.
  auto p_chatter_at = [&](double spindle_rad_s, double depth_m) {
    if (const std::vector<double>* column = limits.find(spindle_rad_s))
      return uncertainty::fraction_below(*column, depth_m);
    const std::vector<std::vector<double>> fresh = limits.at({spindle_rad_s});
    return uncertainty::fraction_below(fresh.front(), depth_m);
  };
  if (result.advice.feasible)
    result.p_chatter = p_chatter_at(result.advice.best.spindle_rad_s, result.advice.best.depth_m);
  if (nominal.feasible)
    result.nominal_p_chatter = p_chatter_at(nominal.best.spindle_rad_s, nominal.best.depth_m);
  result.elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace robomill::analysis
