#include "robomill/stability/lobes.hpp"

#include <algorithm>
#include <array>
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

namespace {

/// Speeds are searched in fixed chunks of this many, each chunk continuing
/// from speed to speed; chunks, not threads, bound a continuation chain, so
/// the limits do not depend on the thread count.
constexpr std::size_t kContinuationChunk = 16;

/// Predictor of the continuation: the limit at speed i extrapolated linearly
/// from the two previous speeds of its chunk when both lie on the same kind of
/// lobe, else the previous limit; 0 (no prediction) at a chunk's start or
/// after an unlimited speed.
double predicted_limit(const std::vector<LobePoint>& points, std::size_t i) {
  if (i % kContinuationChunk == 0 || !points[i - 1].limited)
    return 0.0;
  const LobePoint& previous = points[i - 1];
  if (i % kContinuationChunk == 1 || !points[i - 2].limited ||
      points[i - 2].bifurcation != previous.bifurcation)
    return previous.depth_limit_m;
  const double extrapolated = 2.0 * previous.depth_limit_m - points[i - 2].depth_limit_m;
  return extrapolated > 0.0 ? extrapolated : previous.depth_limit_m;
}

/// A depth with its Floquet result, for brackets.
struct Probe {
  double depth_m = 0.0;
  FloquetResult result{};
  bool unstable() const { return result.spectral_radius >= 1.0; }
};

/// The limit at one speed. `evaluate(depth)` is the Floquet solve; `hint` the
/// previous speed's limit (0 when there is none).
///  1. Continuation: with a predicted limit, probe it ∓ 0.45 × the tolerance.
///     A stable lower and an unstable upper probe bracket the crossing to the
///     tolerance already; otherwise they narrow the bracket of step 3.
///  2. Islands: every coarse depth (depth_max·c/coarse_points) below the
///     bracket is still checked, shallow first, so an unstable region that
///     appears below the previous limit (a period-doubling island, the next
///     lobe across a cusp) is found; the first unstable coarse depth then
///     brackets the crossing instead.
///  3. Root-finding on ρ(depth) − 1 in the bracket by the Illinois variant of
///     regula falsi (superlinear where ρ is smooth, never worse than halving
///     the bracket every few steps), to the relative depth tolerance.
template <class Evaluate>
void find_limit(Evaluate&& evaluate, double hint, double delay_s, const dynamics::ModalModel& modes,
                const LobeOptions& options, LobePoint& point) {
  // Probes just inside the final tolerance either side of the prediction: when
  // they straddle the crossing the search is over in two solves.
  const double window = 0.45 * options.depth_tolerance;
  std::optional<Probe> unstable;
  std::array<Probe, 2> continuation{};
  int continued = 0;
  // Step 1: continuation probes around the previous speed's limit.
  if (hint > 0.0) {
    for (const double depth :
         {hint * (1.0 - window), std::min(hint * (1.0 + window), options.depth_max_m)}) {
      Probe probe{depth, evaluate(depth)};
      if (probe.unstable()) {
        unstable = probe;
        break;
      }
      continuation[continued++] = probe;
    }
  }
  // Step 2: coarse depths, shallow first, below the lowest unstable depth known.
  Probe stable{0.0, {}};
  for (int c = 1; c <= options.coarse_points; ++c) {
    const double depth = options.depth_max_m * c / options.coarse_points;
    if (unstable && depth >= unstable->depth_m)
      break;
    Probe probe{depth, evaluate(depth)};
    if (probe.unstable()) {
      unstable = probe;
      break;
    }
    stable = probe;
  }
  if (!unstable) {
    point.depth_limit_m = options.depth_max_m;
    point.limited = false;
    return;
  }
  // The deepest stable probe below the crossing is the bracket's stable end.
  for (int i = 0; i < continued; ++i) {
    if (continuation[i].depth_m < unstable->depth_m && continuation[i].depth_m > stable.depth_m)
      stable = continuation[i];
  }
  // Step 3: Illinois regula falsi on g(depth) = ρ − 1, g(stable) < 0 ≤ g(unstable).
  Probe& upper = *unstable;
  double g_stable = stable.result.spectral_radius - 1.0;
  double g_unstable = upper.result.spectral_radius - 1.0;
  int side = 0;  // which end the last step kept: −1 stable, +1 unstable
  while (upper.depth_m - stable.depth_m > options.depth_tolerance * upper.depth_m) {
    double depth =
        (stable.depth_m * g_unstable - upper.depth_m * g_stable) / (g_unstable - g_stable);
    const double width = upper.depth_m - stable.depth_m;
    // Keep the new point strictly inside, away from the ends by a small share.
    depth = std::clamp(depth, stable.depth_m + 0.01 * width, upper.depth_m - 0.01 * width);
    const Probe probe{depth, evaluate(depth)};
    if (probe.unstable()) {
      upper = probe;
      g_unstable = probe.result.spectral_radius - 1.0;
      if (side == +1)
        g_stable *= 0.5;  // the stable end stayed twice: Illinois step
      side = +1;
    } else {
      stable = probe;
      g_stable = probe.result.spectral_radius - 1.0;
      if (side == -1)
        g_unstable *= 0.5;
      side = -1;
    }
  }
  point.depth_limit_m = 0.5 * (stable.depth_m + upper.depth_m);
  point.limited = true;
  point.chatter_frequency_hz =
      chatter_frequency_hz(upper.result.critical_multiplier, delay_s, modes);
  point.bifurcation = bifurcation_name(upper.result.critical_multiplier);
}

}  // namespace

std::vector<LobePoint> stability_boundary(const RegenerativeModel& model,
                                          const std::vector<double>& spindle_rad_s,
                                          const LobeOptions& options) {
  check(options, model);
  std::vector<LobePoint> points(spindle_rad_s.size());
  const std::size_t chunks = (spindle_rad_s.size() + kContinuationChunk - 1) / kContinuationChunk;
  core::parallel_blocks(chunks, options.threads, [&](std::size_t first, std::size_t last) {
    FloquetSolver solver(options.method, modal_dynamics(model), options.steps);
    CouplingCache cache(model, options.steps, options.process_damping);
    for (std::size_t i = first * kContinuationChunk;
         i < std::min(last * kContinuationChunk, spindle_rad_s.size()); ++i) {
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
      find_limit(evaluate, options.continuation ? predicted_limit(points, i) : 0.0, delay,
                 model.modes(), options, point);
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
