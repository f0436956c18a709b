#include "robomill/planning/pose_optimization.hpp"

#include <nlopt.h>

#include <algorithm>
#include <chrono>
#include <exception>
#include <stdexcept>

#include "robomill/core/error.hpp"
#include "robomill/core/parallel.hpp"

namespace robomill::planning {
namespace {

// Far above any offset a milling robot survives: an unreachable pose always
// loses to a reachable one, and the residuals still point the way back.
constexpr double kUnreachablePenaltyM = 1.0;

double& component(WorkpiecePose& pose, int i) {
  return i == 0 ? pose.x_m : (i == 1 ? pose.y_m : pose.theta_rad);
}
double component(const WorkpiecePose& pose, int i) {
  return i == 0 ? pose.x_m : (i == 1 ? pose.y_m : pose.theta_rad);
}

struct Search {
  const robot::RobotModel& robot;
  const PlacementProblem& problem;
  const PoseBounds& bounds;
  const PoseOptimizationOptions& options;
  std::vector<int> free;  // indices of the free variables
  PoseOptimizationResult& result;
  int phase = 0;
  std::exception_ptr failure;

  WorkpiecePose pose_of(const double* x) const {
    WorkpiecePose pose = bounds.fixed;
    for (std::size_t i = 0; i < free.size(); ++i)
      component(pose, free[i]) = x[i];
    return pose;
  }

  double evaluate(const WorkpiecePose& pose) {
    const PathPerformance path = evaluate_path(robot, problem, pose, options.threads);
    PoseEvaluation e;
    e.pose = pose;
    e.reachable = path.reachable();
    e.dm_m = path.dm_m;
    e.objective_m =
        e.reachable ? path.dm_m : kUnreachablePenaltyM + path.residual_m + 0.01 * path.unreachable;
    e.phase = phase;
    result.evaluations.push_back(e);
    if (e.reachable && (!result.found || e.dm_m < result.dm_m)) {
      result.found = true;
      result.best = pose;
      result.dm_m = e.dm_m;
    }
    return e.objective_m;
  }
};

double objective(unsigned n, const double* x, double* gradient, void* data) {
  (void)n;
  (void)gradient;  // derivative-free methods only
  auto* search = static_cast<Search*>(data);
  try {
    return search->evaluate(search->pose_of(x));
  } catch (...) {
    if (!search->failure)
      search->failure = std::current_exception();
    return HUGE_VAL;
  }
}

nlopt_algorithm global_algorithm(GlobalMethod method) {
  switch (method) {
    case GlobalMethod::crs2:
      return NLOPT_GN_CRS2_LM;
    case GlobalMethod::mlsl:
      return NLOPT_G_MLSL_LDS;
    case GlobalMethod::direct_l:
    case GlobalMethod::none:
      break;
  }
  return NLOPT_GN_DIRECT_L;
}

nlopt_algorithm local_algorithm(LocalMethod method) {
  switch (method) {
    case LocalMethod::cobyla:
      return NLOPT_LN_COBYLA;
    case LocalMethod::nelder_mead:
      return NLOPT_LN_NELDERMEAD;
    case LocalMethod::bobyqa:
    case LocalMethod::none:
      break;
  }
  return NLOPT_LN_BOBYQA;
}

struct Opt {  // owns an nlopt_opt
  nlopt_opt handle;
  Opt(nlopt_algorithm algorithm, unsigned n) : handle(nlopt_create(algorithm, n)) {
    if (!handle)
      throw NumericalError("NLopt: cannot create the optimizer");
  }
  ~Opt() { nlopt_destroy(handle); }
  Opt(const Opt&) = delete;
  Opt& operator=(const Opt&) = delete;
};

// Runs one NLopt phase from x; returns NLopt's status as words.
std::string run(Search& search, nlopt_algorithm algorithm, int max_evaluations,
                const std::vector<double>& lower, const std::vector<double>& upper,
                std::vector<double>& x, double x_tolerance, const nlopt_opt local = nullptr) {
  const unsigned n = static_cast<unsigned>(x.size());
  Opt opt(algorithm, n);
  nlopt_set_lower_bounds(opt.handle, lower.data());
  nlopt_set_upper_bounds(opt.handle, upper.data());
  nlopt_set_min_objective(opt.handle, objective, &search);
  nlopt_set_maxeval(opt.handle, max_evaluations);
  if (x_tolerance > 0.0)
    nlopt_set_xtol_rel(opt.handle, x_tolerance);
  std::vector<double> step(n);
  for (unsigned i = 0; i < n; ++i)
    step[i] = 0.05 * (upper[i] - lower[i]);
  nlopt_set_initial_step(opt.handle, step.data());
  if (local)
    nlopt_set_local_optimizer(opt.handle, local);
  double value = 0.0;
  const nlopt_result status = nlopt_optimize(opt.handle, x.data(), &value);
  if (search.failure)
    std::rethrow_exception(search.failure);
  return nlopt_result_to_string(status);
}

}  // namespace

PoseOptimizationResult optimize_workpiece_pose(const robot::RobotModel& robot,
                                               const PlacementProblem& problem,
                                               const PoseBounds& bounds,
                                               const PoseOptimizationOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  PoseOptimizationResult result;
  Search search{robot, problem, bounds, options, {}, result, 0, nullptr};
  std::vector<double> lower, upper, x;
  for (int i = 0; i < 3; ++i) {
    if (!bounds.free[std::size_t(i)])
      continue;
    const double lo = component(bounds.lower, i), hi = component(bounds.upper, i);
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(hi > lo))
      throw std::invalid_argument(
          "optimize_workpiece_pose: each free variable needs lower < upper");
    search.free.push_back(i);
    lower.push_back(lo);
    upper.push_back(hi);
    x.push_back(0.5 * (lo + hi));
  }
  if (search.free.empty()) {
    search.evaluate(bounds.fixed);
    result.global_status = result.local_status = "no free variable";
  } else {
    if (options.global != GlobalMethod::none) {
      nlopt_srand(options.seed);
      if (options.global == GlobalMethod::mlsl) {
        // MLSL's own local searches: BOBYQA with a share of the budget.
        Opt local(NLOPT_LN_BOBYQA, static_cast<unsigned>(x.size()));
        nlopt_set_xtol_rel(local.handle, 1e-3);
        nlopt_set_maxeval(local.handle, std::max(20, options.global_evaluations / 20));
        result.global_status = run(search, global_algorithm(options.global),
                                   options.global_evaluations, lower, upper, x, 0.0, local.handle);
      } else {
        result.global_status = run(search, global_algorithm(options.global),
                                   options.global_evaluations, lower, upper, x, 0.0);
      }
    } else {
      result.global_status = "skipped";
      search.evaluate(search.pose_of(x.data()));
    }
    result.global_evaluations = static_cast<int>(result.evaluations.size());
    if (options.local != LocalMethod::none && result.found && options.local_evaluations > 0) {
      search.phase = 1;
      for (std::size_t i = 0; i < search.free.size(); ++i)
        x[i] = component(result.best, search.free[i]);
      result.local_status = run(search, local_algorithm(options.local), options.local_evaluations,
                                lower, upper, x, options.relative_x_tolerance);
    } else {
      result.local_status = "skipped";
    }
  }
  result.elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::vector<PathPerformance> pose_landscape(const robot::RobotModel& robot,
                                            const PlacementProblem& problem,
                                            const std::vector<double>& x_m,
                                            const std::vector<double>& y_m,
                                            const std::vector<double>& theta_rad, int threads) {
  const std::size_t nx = x_m.size(), ny = y_m.size();
  std::vector<PathPerformance> cells(nx * ny * theta_rad.size());
  core::parallel_for(cells.size(), threads, [&](std::size_t index) {
    const std::size_t ix = index % nx, iy = (index / nx) % ny, it = index / (nx * ny);
    cells[index] = evaluate_path(robot, problem, {x_m[ix], y_m[iy], theta_rad[it]}, 1);
  });
  return cells;
}

}  // namespace robomill::planning
