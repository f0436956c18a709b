#include "robomill/stability/lobes.hpp"

#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>

#include "robomill/core/parallel.hpp"

namespace robomill::stability {
namespace {

ModalDynamics modal_dynamics(const RegenerativeModel& model) {
  return {model.modes().natural_rad_s(), model.modes().damping_ratios()};
}

double tooth_period_s(const RegenerativeModel& model, double spindle_rad_s) {
  return 2.0 * std::numbers::pi / (model.tool().teeth() * spindle_rad_s);
}

/// Coupling samples at a depth: one set per unit depth when W ∝ depth,
/// otherwise sampled at each depth and memoized per thread.
/// Coupling P(t) and, with process damping, the damping shape Φᵀ D Φ (per
/// unit C_eq') at a depth; one set per unit depth when W ∝ depth, otherwise
/// sampled at each depth and memoized per thread.
class CouplingCache {
 public:
  struct Entry {
    CouplingSamples coupling, damping;
  };
  CouplingCache(const RegenerativeModel& model, int steps,
                const std::optional<LinearProcessDamping>& damping)
      : model_(model), steps_(steps), damping_(damping) {
    if (model.proportional_to_depth())
      unit_ = make(1.0);
  }
  /// The samples and the scale (the depth, or 1) to apply to them.
  std::pair<const Entry*, double> at(double depth_m) {
    if (model_.proportional_to_depth())
      return {&unit_, depth_m};
    auto found = by_depth_.find(depth_m);
    if (found == by_depth_.end()) {
      if (by_depth_.size() > 256)
        by_depth_.clear();
      found = by_depth_.emplace(depth_m, make(depth_m)).first;
    }
    return {&found->second, 1.0};
  }

 private:
  Entry make(double depth_m) const {
    Entry entry;
    entry.coupling = model_.sample(depth_m, steps_);
    if (damping_)
      entry.damping = model_.sample_damping(depth_m, steps_, damping_->friction);
    return entry;
  }
  const RegenerativeModel& model_;
  int steps_;
  std::optional<LinearProcessDamping> damping_;
  Entry unit_;
  std::map<double, Entry> by_depth_;
};

/// The modal damping is C(t) = −C_eq' Φᵀ D Φ with C_eq' = K_sp w² / (4 v)
/// (000 Eq 19 per unit engaged width); returns −C_eq' at this speed.
double damping_factor(const RegenerativeModel& model, const std::optional<LinearProcessDamping>& d,
                      double spindle_rad_s) {
  if (!d)
    return 0.0;
  const double cutting_speed = model.tool().radius_m() * spindle_rad_s;
  return -d->indentation_n_per_m3 * d->wear_land_m * d->wear_land_m / (4.0 * cutting_speed);
}

void check(const LobeOptions& options, const RegenerativeModel& model) {
  if (!(options.depth_max_m > 0.0))
    throw std::invalid_argument("depth_max must be positive");
  if (options.depth_max_m > model.max_depth_m() * (1.0 + 1e-12)) {
    throw std::invalid_argument("depth_max exceeds the tool overhang");
  }
  if (options.steps < 1)
    throw std::invalid_argument("discretization must be ≥ 1");
  if (!(options.depth_tolerance > 0.0))
    throw std::invalid_argument("depth tolerance must be > 0");
  if (options.coarse_points < 1)
    throw std::invalid_argument("coarse_points must be ≥ 1");
}

}  // namespace

std::vector<double> linear_range(double from, double to, int count) {
  std::vector<double> values(static_cast<std::size_t>(std::max(count, 0)));
  for (int i = 0; i < count; ++i) {
    values[static_cast<std::size_t>(i)] = count == 1 ? from : from + (to - from) * i / (count - 1);
  }
  return values;
}

std::vector<LobePoint> stability_boundary(const RegenerativeModel& model,
                                          const std::vector<double>& spindle_rad_s,
                                          const LobeOptions& options) {
  check(options, model);
  std::vector<LobePoint> points(spindle_rad_s.size());
  core::parallel_blocks(
      spindle_rad_s.size(), options.threads, [&](std::size_t begin, std::size_t end) {
        FloquetSolver solver(options.method, modal_dynamics(model), options.steps);
        CouplingCache cache(model, options.steps, options.process_damping);
        for (std::size_t i = begin; i < end; ++i) {
          LobePoint& point = points[i];
          const double factor = damping_factor(model, options.process_damping, spindle_rad_s[i]);
          point.spindle_rad_s = spindle_rad_s[i];
          const double delay = tooth_period_s(model, spindle_rad_s[i]);
          solver.set_delay(delay);
          auto evaluate = [&](double depth) {
            ++point.evaluations;
            const auto [entry, scale] = cache.at(depth);
            return options.process_damping
                       ? solver.solve(entry->coupling, scale, &entry->damping, factor * scale)
                       : solver.solve(entry->coupling, scale);
          };
          // Coarse scan from the shallow end: the first unstable depth brackets
          // the boundary (islands narrower than a scan step can be missed).
          double stable_depth = 0.0, unstable_depth = 0.0;
          FloquetResult unstable_result;
          for (int c = 1; c <= options.coarse_points; ++c) {
            const double depth = options.depth_max_m * c / options.coarse_points;
            const FloquetResult result = evaluate(depth);
            if (result.spectral_radius >= 1.0) {
              unstable_depth = depth;
              unstable_result = result;
              break;
            }
            stable_depth = depth;
          }
          if (unstable_depth == 0.0) {
            point.depth_limit_m = options.depth_max_m;
            point.limited = false;
            continue;
          }
          while (unstable_depth - stable_depth > options.depth_tolerance * unstable_depth) {
            const double middle = 0.5 * (stable_depth + unstable_depth);
            const FloquetResult result = evaluate(middle);
            if (result.spectral_radius >= 1.0) {
              unstable_depth = middle;
              unstable_result = result;
            } else {
              stable_depth = middle;
            }
          }
          point.depth_limit_m = 0.5 * (stable_depth + unstable_depth);
          point.limited = true;
          point.chatter_frequency_hz =
              chatter_frequency_hz(unstable_result.critical_multiplier, delay, model.modes());
          point.bifurcation = bifurcation_name(unstable_result.critical_multiplier);
        }
      });
  return points;
}

StabilityMap stability_map(const RegenerativeModel& model, const std::vector<double>& spindle_rad_s,
                           const std::vector<double>& depth_m, const LobeOptions& options) {
  check(options, model);
  StabilityMap map;
  map.spindle_rad_s = spindle_rad_s;
  map.depth_m = depth_m;
  map.spectral_radius.resize(static_cast<Eigen::Index>(spindle_rad_s.size()),
                             static_cast<Eigen::Index>(depth_m.size()));
  core::parallel_blocks(
      spindle_rad_s.size(), options.threads, [&](std::size_t begin, std::size_t end) {
        FloquetSolver solver(options.method, modal_dynamics(model), options.steps);
        CouplingCache cache(model, options.steps, options.process_damping);
        for (std::size_t i = begin; i < end; ++i) {
          solver.set_delay(tooth_period_s(model, spindle_rad_s[i]));
          const double factor = damping_factor(model, options.process_damping, spindle_rad_s[i]);
          for (std::size_t j = 0; j < depth_m.size(); ++j) {
            const auto [entry, scale] = cache.at(depth_m[j]);
            map.spectral_radius(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) =
                (options.process_damping
                     ? solver.solve(entry->coupling, scale, &entry->damping, factor * scale)
                     : solver.solve(entry->coupling, scale))
                    .spectral_radius;
          }
        }
      });
  return map;
}

}  // namespace robomill::stability
