#include "robomill/planning/cutting_advice.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "robomill/core/constants.hpp"
#include "robomill/core/parallel.hpp"
#include "robomill/cutting/milling_forces.hpp"
#include "robomill/planning/force_harmonics.hpp"
#include "robomill/stability/floquet.hpp"
#include "robomill/stability/zero_order.hpp"

namespace robomill::planning {
namespace {

std::optional<stability::FloquetMethod> floquet_method(LimitMethod method) {
  switch (method) {
    case LimitMethod::sdm:
      return stability::FloquetMethod::sdm;
    case LimitMethod::fdm:
      return stability::FloquetMethod::fdm;
    case LimitMethod::fdm2:
      return stability::FloquetMethod::fdm2;
    case LimitMethod::zoa:
      break;
  }
  return std::nullopt;
}

stability::LobePoint from_zero_order(const stability::ZeroOrderLimit& z) {
  stability::LobePoint p;
  p.spindle_rad_s = z.spindle_rad_s;
  p.depth_limit_m = z.depth_limit_m;
  p.limited = z.limited;
  p.chatter_frequency_hz = z.chatter_frequency_hz;
  p.bifurcation = z.limited ? "hopf" : "none";
  return p;
}

/// The stability limits of every station at any set of speeds. The
/// zero-order solvers (their eigenvalue tracking) are built once and reused
/// by the scan and the fine rescan.
class LimitEngine {
 public:
  LimitEngine(const std::vector<stability::RegenerativeModel>& models,
              const LimitSettings& settings, const AdviceOptions& options)
      : models_(models),
        settings_(settings),
        threads_(options.threads),
        source_(options.limit_source) {
    if (settings.method != LimitMethod::zoa || source_)
      return;
    solvers_.resize(models.size());
    core::parallel_for(models.size(), threads_, [&](std::size_t s) {
      stability::ZeroOrderOptions options;
      options.depth_max_m = settings.depth_max_m;
      solvers_[s] = std::make_unique<stability::ZeroOrderSolver>(models[s], options);
    });
  }

  /// curves[s][i]: station s at speed i.
  std::vector<std::vector<stability::LobePoint>> at(const std::vector<double>& speeds) const {
    if (source_) {
      std::vector<std::vector<stability::LobePoint>> curves = {source_(speeds)};
      if (curves.front().size() != speeds.size())
        throw std::logic_error("advise_cutting: the limit source gave another number of speeds");
      return curves;
    }
    std::vector<std::vector<stability::LobePoint>> curves(models_.size());
    if (settings_.method == LimitMethod::zoa) {
      for (std::size_t s = 0; s < models_.size(); ++s) {
        curves[s].resize(speeds.size());
        core::parallel_for(speeds.size(), threads_, [&](std::size_t i) {
          curves[s][i] = from_zero_order(solvers_[s]->limit(speeds[i]));
        });
      }
      return curves;
    }
    for (std::size_t s = 0; s < models_.size(); ++s)
      curves[s] = limit_curve(models_[s], speeds, settings_, threads_);
    return curves;
  }

 private:
  const std::vector<stability::RegenerativeModel>& models_;
  LimitSettings settings_;
  int threads_;
  const std::function<std::vector<stability::LobePoint>(const std::vector<double>&)>& source_;
  std::vector<std::unique_ptr<stability::ZeroOrderSolver>> solvers_;
};

/// Per-thread scratch of the offset evaluation: the series rescaled to a
/// speed and one workspace per station (sized on first use, then reused).
struct OffsetScratch {
  ForceHarmonics series;
  std::vector<OffsetWorkspace> workspaces;
};

}  // namespace

std::string_view to_string(LimitMethod method) noexcept {
  switch (method) {
    case LimitMethod::zoa:
      return "zoa";
    case LimitMethod::sdm:
      return "sdm";
    case LimitMethod::fdm:
      return "fdm";
    case LimitMethod::fdm2:
      return "fdm2";
  }
  return "?";
}

std::vector<stability::LobePoint> limit_curve(const stability::RegenerativeModel& model,
                                              const std::vector<double>& spindle_rad_s,
                                              const LimitSettings& settings, int threads) {
  if (const auto method = floquet_method(settings.method)) {
    stability::LobeOptions options;
    options.method = *method;
    options.steps = settings.discretization;
    options.depth_max_m = settings.depth_max_m;
    options.depth_tolerance = settings.depth_tolerance;
    options.threads = threads;
    return stability::stability_boundary(model, spindle_rad_s, options);
  }
  stability::ZeroOrderOptions options;
  options.depth_max_m = settings.depth_max_m;
  const stability::ZeroOrderSolver solver(model, options);
  std::vector<stability::LobePoint> curve(spindle_rad_s.size());
  core::parallel_for(spindle_rad_s.size(), threads, [&](std::size_t i) {
    curve[i] = from_zero_order(solver.limit(spindle_rad_s[i]));
  });
  return curve;
}

PostureDynamics modal_dynamics(const dynamics::ModalModel& modes) {
  const Eigen::VectorXd omega = modes.natural_rad_s();
  const Eigen::VectorXd zeta = modes.damping_ratios();
  PostureDynamics d;
  d.mass = Eigen::MatrixXd::Identity(omega.size(), omega.size());
  d.stiffness = omega.array().square().matrix().asDiagonal();
  d.damping = (2.0 * zeta.array() * omega.array()).matrix().asDiagonal();
  d.jacobian = modes.shape_matrix();
  return d;
}

double material_removal_rate(double spindle_rad_s, double axial_depth_m,
                             const cutting::MillingProcess& process, int teeth) {
  const double feed_speed = process.feed_per_tooth_m * teeth * spindle_rad_s / kTwoPi;
  return axial_depth_m * process.radial_depth_m * feed_speed;
}

double spectral_radius_at(const stability::RegenerativeModel& model, double spindle_rad_s,
                          double axial_depth_m, stability::FloquetMethod method, int steps) {
  stability::FloquetSolver solver(
      method, {model.modes().natural_rad_s(), model.modes().damping_ratios()}, steps);
  solver.set_delay(kTwoPi / (model.tool().teeth() * spindle_rad_s));
  return solver.solve(model.sample(axial_depth_m, steps), 1.0).spectral_radius;
}

namespace {

/// The scan of advise_cutting over spindle speeds: at each speed the
/// stable depth step, lowered by bisection to the offset limit.
struct AdviceScan {
  const tool::Tool& tool;
  const cutting::CuttingLaw& law;
  const cutting::MillingProcess& process;
  const AdviceLimits& limits;
  const AdviceOptions& options;
  const std::vector<PostureDynamics>& dynamics;
  const LimitEngine& engine;
  const double step;
  const int depth_steps;
  const int teeth;
  // The milling force depends on the spindle angle, not on the speed (the
  // chip thickness is set by f_z), so its Fourier coefficients are computed
  // once per depth step at a reference speed; at another speed only the
  // period scales (τ ∝ 1/Ω). Filled on demand, depth steps in parallel.
  const double reference_speed;
  std::vector<ForceHarmonics> series;
  int series_ready = 0;  // steps 1 … series_ready are filled

  AdviceScan(const tool::Tool& tool, const cutting::CuttingLaw& law,
             const cutting::MillingProcess& process, const AdviceLimits& limits,
             const AdviceOptions& options, const std::vector<PostureDynamics>& dynamics,
             const LimitEngine& engine, int depth_steps)
      : tool(tool),
        law(law),
        process(process),
        limits(limits),
        options(options),
        dynamics(dynamics),
        engine(engine),
        step(limits.depth_step_m),
        depth_steps(depth_steps),
        teeth(tool.teeth()),
        reference_speed(limits.speed_min_rad_s),
        series(static_cast<std::size_t>(depth_steps) + 1) {}

  /// Fills the force series of depth steps 1 … upto.
  void ensure_series(int upto) {
    if (upto <= series_ready)
      return;
    const int first = series_ready + 1;
    core::parallel_for(
        static_cast<std::size_t>(upto - series_ready), options.threads, [&](std::size_t k) {
          const int j = first + static_cast<int>(k);
          cutting::MillingProcess cut = process;
          cut.spindle_rad_s = reference_speed;
          cut.axial_depth_m = j * step;
          const cutting::MillingForceModel force(
              tool, law, cut, cutting::default_axial_elements(tool, cut.axial_depth_m));
          series[std::size_t(j)] = force_harmonics(force, limits.samples, limits.harmonics);
        });
    series_ready = upto;
  }

  // The expected offset at depth step j and speed Ω: the largest over stations.
  double offset_at(OffsetScratch& scratch, int j, double spindle_rad_s) const {
    const ForceHarmonics& base = series[std::size_t(j)];
    scratch.series.coefficients = base.coefficients;  // same size after the first: no allocation
    scratch.series.samples = base.samples;
    scratch.series.period_s = base.period_s * reference_speed / spindle_rad_s;
    scratch.series.fundamental_rad_s = kTwoPi / scratch.series.period_s;
    double largest = 0.0;
    for (std::size_t s = 0; s < dynamics.size(); ++s) {
      const OffsetResponse r = steady_state_offset(dynamics[s], Eigen::Matrix3d::Identity(),
                                                   scratch.series, scratch.workspaces[s]);
      largest = std::max(largest, r.measure(limits.measure));
    }
    return largest;
  }

  void fill_depth(OffsetScratch& scratch, SpeedAdvice& a, int j) const {
    a.depth_m = j * step;
    a.offset_m = j > 0 ? offset_at(scratch, j, a.spindle_rad_s) : 0.0;
    a.mrr_m3_per_s = material_removal_rate(a.spindle_rad_s, a.depth_m, process, teeth);
  }

  /// One row per speed, stage 0 (the scan) or 1 (the fine rescan).
  std::vector<SpeedAdvice> evaluate(const std::vector<double>& speeds, int stage) {
    const auto curves = engine.at(speeds);
    std::vector<SpeedAdvice> rows(speeds.size());
    std::vector<int> stable_steps(speeds.size(), 0);
    int deepest = 0;
    for (std::size_t i = 0; i < speeds.size(); ++i) {
      SpeedAdvice& a = rows[i];
      a.spindle_rad_s = speeds[i];
      a.stage = stage;
      a.limit_depth_m = INFINITY;
      for (std::size_t s = 0; s < curves.size(); ++s) {
        const stability::LobePoint& p = curves[s][i];
        a.limited = a.limited || p.limited;
        if (p.depth_limit_m < a.limit_depth_m) {
          a.limit_depth_m = p.depth_limit_m;
          a.station = static_cast<int>(s);
          a.chatter_frequency_hz = p.chatter_frequency_hz;
        }
      }
      // Largest multiple of Δ inside s · a_lim (1e-9 Δ absorbs round-off
      // when s · a_lim is itself a multiple).
      const int j = std::min(
          depth_steps,
          static_cast<int>(std::floor(limits.stability_margin * a.limit_depth_m / step + 1e-9)));
      stable_steps[i] = std::max(j, 0);
      a.stable_depth_m = stable_steps[i] * step;
      deepest = std::max(deepest, stable_steps[i]);
    }
    ensure_series(deepest);
    core::parallel_blocks(speeds.size(), options.threads, [&](std::size_t begin, std::size_t end) {
      OffsetScratch scratch;
      scratch.workspaces.resize(dynamics.size());
      for (std::size_t i = begin; i < end; ++i) {
        SpeedAdvice& a = rows[i];
        int j = stable_steps[i];
        if (limits.max_offset_m && j > 0 &&
            offset_at(scratch, j, a.spindle_rad_s) > *limits.max_offset_m) {
          // Bisection on the depth steps: lo feasible (0 by convention), hi not.
          int lo = 0, hi = j;
          while (hi - lo > 1) {
            const int mid = (lo + hi) / 2;
            (offset_at(scratch, mid, a.spindle_rad_s) <= *limits.max_offset_m ? lo : hi) = mid;
          }
          j = lo;
          a.offset_limited = true;
        }
        fill_depth(scratch, a, j);
      }
    });
    return rows;
  }
};

/// Floquet re-check of the advised point (all stations); with a Floquet
/// method the depth steps down until that method finds it stable.
void recheck(const std::vector<stability::RegenerativeModel>& models,
             const std::vector<dynamics::ModalModel>& stations, const AdviceOptions& options,
             const AdviceScan& scan, SpeedAdvice& chosen, CuttingAdvice& advice) {
  const double step = scan.step;
  const int depth_steps = scan.depth_steps;
  const int teeth = scan.teeth;
  const auto method = floquet_method(options.limit.method);
  int steps = options.limit.discretization;
  if (!method) {
    double highest_hz = 0.0;
    for (const auto& station : stations)
      highest_hz = std::max(highest_hz, station.highest_frequency_hz());
    const double tau = kTwoPi / (teeth * std::max(chosen.spindle_rad_s, 1e-300));
    steps = std::max(options.check_steps, static_cast<int>(std::ceil(2.0 * highest_hz * tau)));
  }
  auto radius = [&](double spindle, double depth) {
    double largest = 0.0;
    for (const auto& model : models)
      largest = std::max(largest,
                         spectral_radius_at(model, spindle, depth,
                                            method.value_or(stability::FloquetMethod::fdm), steps));
    return largest;
  };
  int j = static_cast<int>(std::lround(chosen.depth_m / step));
  if (j > 0 && (method || steps <= options.max_check_steps)) {
    advice.check.done = true;
    advice.check.method = std::string(to_string(method ? options.limit.method : LimitMethod::fdm));
    advice.check.steps = steps;
    advice.check.spectral_radius = radius(chosen.spindle_rad_s, j * step);
    // With a Floquet method the advice must be stable by that same method
    // (not with a limit source: its bound is a chance over uncertain
    // structures, and the stations are only the nominal one).
    while (method && !options.limit_source && j > 0 && advice.check.spectral_radius >= 1.0) {
      --j;
      ++advice.stepped_down;
      advice.check.spectral_radius = j > 0 ? radius(chosen.spindle_rad_s, j * step) : 0.0;
    }
    if (advice.stepped_down > 0) {
      OffsetScratch scratch;
      scratch.workspaces.resize(scan.dynamics.size());
      scan.fill_depth(scratch, chosen, j);
    }
    advice.check.next_done = j + 1 <= depth_steps;
    if (advice.check.next_done)
      advice.check.next_spectral_radius = radius(chosen.spindle_rad_s, (j + 1) * step);
  }
}

}  // namespace

CuttingAdvice advise_cutting(const tool::Tool& tool, const cutting::CuttingLaw& law,
                             const cutting::MillingProcess& process,
                             const std::vector<dynamics::ModalModel>& stations,
                             const AdviceLimits& limits, const AdviceOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const double depth_max = options.limit.depth_max_m;
  const double step = limits.depth_step_m;
  if (stations.empty())
    throw std::invalid_argument("advise_cutting: no station (structure) given");
  if (!(limits.speed_min_rad_s > 0.0) || limits.speed_count < 1 ||
      (limits.speed_count > 1 && !(limits.speed_max_rad_s > limits.speed_min_rad_s)))
    throw std::invalid_argument("advise_cutting: the speed range must be positive and increasing");
  if (!(depth_max > 0.0) || depth_max > tool.overhang_m() * (1.0 + 1e-12))
    throw std::invalid_argument("advise_cutting: depth_max must lie in (0, tool overhang]");
  if (!(step > 0.0) || step > depth_max * (1.0 + 1e-12) || depth_max / step > 100000.0)
    throw std::invalid_argument(
        "advise_cutting: the depth step must lie in (depth_max / 100000, depth_max]");
  if (!(limits.stability_margin > 0.0 && limits.stability_margin <= 1.0))
    throw std::invalid_argument("advise_cutting: the stability margin must lie in (0, 1]");
  if (limits.max_offset_m && !(*limits.max_offset_m > 0.0))
    throw std::invalid_argument("advise_cutting: the offset limit must be positive");
  if (limits.refine_count < 0 || options.peaks < 0)
    throw std::invalid_argument("advise_cutting: negative refine or peak count");

  const int teeth = tool.teeth();
  const int depth_steps = static_cast<int>(std::floor(depth_max / step * (1.0 + 1e-12)));
  std::vector<stability::RegenerativeModel> models;
  std::vector<PostureDynamics> dynamics;
  models.reserve(stations.size());
  for (const dynamics::ModalModel& station : stations) {
    models.emplace_back(tool, law, process, station);
    dynamics.push_back(modal_dynamics(station));
  }
  const LimitEngine engine(models, options.limit, options);

  AdviceScan scan(tool, law, process, limits, options, dynamics, engine, depth_steps);

  CuttingAdvice advice;
  advice.scan = scan.evaluate(
      stability::linear_range(limits.speed_min_rad_s, limits.speed_max_rad_s, limits.speed_count),
      0);
  const auto better = [](const SpeedAdvice& a, const SpeedAdvice& b) {
    return a.mrr_m3_per_s > b.mrr_m3_per_s;  // ties: the first (lower speed) stays
  };
  std::size_t best = 0;
  for (std::size_t i = 1; i < advice.scan.size(); ++i)
    if (better(advice.scan[i], advice.scan[best]))
      best = i;

  // Local maxima of the scanned MRR: the best cut of each lobe pocket.
  std::vector<SpeedAdvice> peaks;
  const std::size_t n = advice.scan.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double m = advice.scan[i].mrr_m3_per_s;
    if (m > 0.0 && (i == 0 || m > advice.scan[i - 1].mrr_m3_per_s) &&
        (i + 1 == n || m >= advice.scan[i + 1].mrr_m3_per_s))
      peaks.push_back(advice.scan[i]);
  }
  std::stable_sort(peaks.begin(), peaks.end(), better);
  if (peaks.size() > static_cast<std::size_t>(options.peaks))
    peaks.resize(static_cast<std::size_t>(options.peaks));
  advice.peaks = peaks;

  SpeedAdvice chosen = advice.scan[best];
  if (limits.refine_count > 0 && n > 1 && chosen.mrr_m3_per_s > 0.0) {
    // Fine rescan strictly between the best speed's neighbours (their ends
    // are scanned already).
    const double lo = advice.scan[best == 0 ? 0 : best - 1].spindle_rad_s;
    const double hi = advice.scan[best + 1 == n ? best : best + 1].spindle_rad_s;
    std::vector<double> fine = stability::linear_range(lo, hi, limits.refine_count + 2);
    fine = std::vector<double>(fine.begin() + 1, fine.end() - 1);
    const std::vector<SpeedAdvice> rows = scan.evaluate(fine, 1);
    for (const SpeedAdvice& row : rows)
      if (better(row, chosen))
        chosen = row;
    advice.scan.insert(advice.scan.end(), rows.begin(), rows.end());
  }

  recheck(models, stations, options, scan, chosen, advice);
  advice.best = chosen;
  advice.feasible = chosen.depth_m > 0.0;
  advice.margin_to_chatter = advice.feasible ? chosen.limit_depth_m / chosen.depth_m : 0.0;
  advice.feed_speed_m_per_s = process.feed_per_tooth_m * teeth * chosen.spindle_rad_s / kTwoPi;
  advice.elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return advice;
}

}  // namespace robomill::planning
