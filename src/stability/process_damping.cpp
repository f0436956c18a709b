#include "robomill/stability/process_damping.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "robomill/core/constants.hpp"
#include "robomill/core/parallel.hpp"
#include "robomill/cutting/engagement.hpp"
#include "robomill/cutting/milling_forces.hpp"

namespace robomill::stability {
namespace {

void require_positive(double value, const char* what) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    throw std::invalid_argument(std::string("process damping: ") + what + " must be positive");
  }
}

void validate(const ProcessDamping& p) {
  require_positive(p.indentation_n_per_m3, "indentation coefficient");
  require_positive(p.wear_land_m, "wear land");
  if (!(p.friction >= 0.0) || !std::isfinite(p.friction)) {
    throw std::invalid_argument("process damping: friction must be ≥ 0");
  }
  if (!(p.clearance_rad >= 0.0) || !(p.clearance_rad < 0.5 * kPi)) {
    throw std::invalid_argument("process damping: clearance angle must lie in [0, 90°)");
  }
  if (p.model == ProcessDampingModel::energy_balance && p.clearance_rad > 0.0) {
    require_positive(p.amplitude_m, "vibration amplitude (needed with a clearance angle)");
  }
}

/// ∫_0^{2π} ∫_0^β [sin θ − sin(θ − ξ) − α ξ]₊ cos θ dξ dθ by the trapezoidal
/// rule in θ (periodic) and the midpoint rule in ξ.
double indentation_work_integral(double beta, double alpha) {
  constexpr int n_theta = 256, n_xi = 256;
  double sum = 0.0;
  for (int i = 0; i < n_theta; ++i) {
    const double theta = kTwoPi * i / n_theta;
    const double c = std::cos(theta), s = std::sin(theta);
    double inner = 0.0;
    for (int j = 0; j < n_xi; ++j) {
      const double xi = beta * (j + 0.5) / n_xi;
      const double depth = s - std::sin(theta - xi) - alpha * xi;
      if (depth > 0.0)
        inner += depth;
    }
    sum += c * inner * beta / n_xi;
  }
  return sum * kTwoPi / n_theta;
}

/// ∫ sin²φ, ∫ cos²φ, ∫ sin φ cos φ, ∫ sin φ, ∫ cos φ, ∫ dφ over [a, b].
struct AngleIntegrals {
  double ss, cc, sc, s, c, one;
};

AngleIntegrals angle_integrals(double a, double b) {
  const double one = b - a;
  const double d2 = std::sin(2.0 * b) - std::sin(2.0 * a);
  const double sa = std::sin(a), sb = std::sin(b);
  return {0.5 * one - 0.25 * d2,
          0.5 * one + 0.25 * d2,
          0.5 * (sb * sb - sa * sa),
          std::cos(a) - std::cos(b),
          sb - sa,
          one};
}

}  // namespace

double equivalent_damping_n_s_per_m(double indentation_n_per_m3, double wear_land_m,
                                    double engaged_width_m, double cutting_speed_m_s) {
  require_positive(cutting_speed_m_s, "cutting speed");
  // 000 Eq 19.
  return indentation_n_per_m3 * wear_land_m * wear_land_m * engaged_width_m /
         (4.0 * cutting_speed_m_s);
}

double energy_balance_damping_n_s_per_m(double indentation_n_per_m3, double wear_land_m,
                                        double engaged_width_m, double cutting_speed_m_s,
                                        double chatter_frequency_hz, double clearance_rad,
                                        double amplitude_m) {
  require_positive(cutting_speed_m_s, "cutting speed");
  require_positive(chatter_frequency_hz, "chatter frequency");
  const double omega = kTwoPi * chatter_frequency_hz;
  const double k = omega / cutting_speed_m_s;  // wave number 2π/λ
  const double beta = k * wear_land_m;         // 2π w / λ
  if (clearance_rad == 0.0) {
    // (EB): C_eq · [sin(β/2)/(β/2)]², written to stay accurate for small β.
    const double half = 0.5 * beta;
    const double sinc = half > 1e-8 ? std::sin(half) / half : 1.0 - half * half / 6.0;
    return equivalent_damping_n_s_per_m(indentation_n_per_m3, wear_land_m, engaged_width_m,
                                        cutting_speed_m_s) *
           sinc * sinc;
  }
  require_positive(amplitude_m, "vibration amplitude");
  // c = K db / (π ω k) · J(β, α), α = tan γ / (k A): from c π ω A² = ∮ F ẏ dt with
  // F = K db ∫_0^w [p]₊ dx, θ = ωt, ξ = k x.
  const double alpha = std::tan(clearance_rad) / (k * amplitude_m);
  return indentation_n_per_m3 * engaged_width_m / (kPi * omega * k) *
         indentation_work_integral(beta, alpha);
}

double edge_damping_n_s_per_m(const ProcessDamping& params, double engaged_width_m,
                              double cutting_speed_m_s, double chatter_frequency_hz) {
  if (params.model == ProcessDampingModel::linear_equivalent) {
    return equivalent_damping_n_s_per_m(params.indentation_n_per_m3, params.wear_land_m,
                                        engaged_width_m, cutting_speed_m_s);
  }
  return energy_balance_damping_n_s_per_m(params.indentation_n_per_m3, params.wear_land_m,
                                          engaged_width_m, cutting_speed_m_s, chatter_frequency_hz,
                                          params.clearance_rad, params.amplitude_m);
}

Eigen::Matrix3d process_damping_matrix(const RegenerativeModel& model, const ProcessDamping& params,
                                       double spindle_rad_s, double axial_depth_m,
                                       double chatter_frequency_hz) {
  validate(params);
  require_positive(spindle_rad_s, "spindle speed");
  const tool::Tool& tool = model.tool();
  const cutting::MillingProcess& process = model.process();
  const bool straight = tool.type() == tool::ToolType::flat;
  // Flat end mills: every element has radius R and κ = π/2, so one element is
  // exact (the helix only shifts the phase, which the average ignores).
  const int count = straight ? 1 : cutting::default_axial_elements(tool, axial_depth_m);
  const auto edge = tool::discretize_edge(tool, axial_depth_m, count);
  const double teeth_over_2pi = tool.teeth() / kTwoPi;
  const double mu = params.friction;
  Eigen::Matrix3d damping = Eigen::Matrix3d::Zero();
  for (const tool::EdgeElement& element : edge) {
    const cutting::Engagement window = cutting::radial_engagement(
        tool.radius_m(), element.radius_m, process.radial_depth_m, process.direction);
    if (window.empty())
      continue;
    const double c_e = edge_damping_n_s_per_m(
        params, element.chip_width_m, element.radius_m * spindle_rad_s, chatter_frequency_hz);
    const bool cylindrical = element.kappa_rad == 0.5 * kPi;
    const double sk = cylindrical ? 1.0 : std::sin(element.kappa_rad);
    const double ck = cylindrical ? 0.0 : std::cos(element.kappa_rad);
    const AngleIntegrals I = angle_integrals(window.entry_rad, window.exit_rad);
    // ∫ (n − μ t) nᵀ dφ with n = (sκ sin φ, sκ cos φ, −cκ), t = (−cos φ, sin φ, 0).
    Eigen::Matrix3d block;
    block << sk * sk * I.ss + mu * sk * I.sc, sk * sk * I.sc + mu * sk * I.cc,
        -ck * sk * I.s - mu * ck * I.c,  //
        sk * sk * I.sc - mu * sk * I.ss, sk * sk * I.cc - mu * sk * I.sc,
        -ck * sk * I.c + mu * ck * I.s,  //
        -ck * sk * I.s, -ck * sk * I.c, ck * ck * I.one;
    damping += c_e * teeth_over_2pi * block;
  }
  return damping;
}

double mode_process_damping_n_s_per_m(const Eigen::Matrix3d& damping, const dynamics::Mode& mode) {
  const double norm = mode.shape.norm();
  if (!(norm > 0.0))
    throw std::invalid_argument("mode shape must be non-zero");
  const Eigen::Vector3d u = mode.shape / norm;
  return u.dot(damping * u);
}

dynamics::ModalModel with_added_damping(const dynamics::ModalModel& modes,
                                        const Eigen::Matrix3d& damping) {
  std::vector<dynamics::Mode> out = modes.modes();
  for (dynamics::Mode& m : out) {
    const double wn = kTwoPi * m.natural_frequency_hz;
    // 2 ζ ωn is the mass-normalized modal damping; φᵀ C φ adds to it.
    const double zeta = m.damping_ratio + m.shape.dot(damping * m.shape) / (2.0 * wn);
    m.damping_ratio = std::clamp(zeta, 1e-6, 0.999);
  }
  return dynamics::ModalModel(std::move(out));
}

dynamics::ModalModel process_damped_modes(const RegenerativeModel& model,
                                          const ProcessDamping& params, double spindle_rad_s,
                                          double axial_depth_m, double chatter_frequency_hz) {
  return with_added_damping(
      model.modes(),
      process_damping_matrix(model, params, spindle_rad_s, axial_depth_m, chatter_frequency_hz));
}

namespace {

/// The fixed-point iteration of the header for one speed and one set of modes.
class DampedLimit {
 public:
  DampedLimit(const RegenerativeModel& model, const std::optional<ProcessDamping>& params,
              const Eigen::Matrix3d& a0, const std::vector<double>& grid,
              const dynamics::ModalModel& modes, const ZeroOrderSolver& structural,
              double depth_max, const ProcessDampedOptions& options)
      : model_(model),
        params_(params),
        a0_(a0),
        grid_(grid),
        modes_(modes),
        structural_(structural),
        depth_max_(depth_max),
        options_(options) {}

  ZeroOrderLimit solve(double spindle_rad_s) {
    speed_ = spindle_rad_s;
    evaluations_ = 0;
    ZeroOrderLimit current = evaluate(0.0, 0.0);  // structural damping only
    if (!params_ || !current.limited)
      return finish(current, true);
    double a = current.depth_limit_m, f = current.chatter_frequency_hz;
    double previous_a = 0.0;  // the iterate before a (a = L(previous_a))
    int plain_steps = 0;
    ZeroOrderLimit last = current;
    while (evaluations_ < options_.max_evaluations) {
      const ZeroOrderLimit next = evaluate(a, f);
      last = next;
      if (!next.limited)
        return finish(next, true);  // the fixed point lies above depth_max
      const double a_next = next.depth_limit_m, f_next = next.chatter_frequency_hz;
      if (close(a_next, a) && close(f_next, f))
        return finish(next, true);
      ++plain_steps;
      // Aitken Δ² on three rising iterates previous_a < a < a_next.
      const double d1 = a - previous_a, d2 = a_next - a;
      if (plain_steps >= 2 && d1 > 0.0 && d2 > 0.0 && d2 < d1 &&
          evaluations_ < options_.max_evaluations) {
        plain_steps = 0;
        const double q = d2 / d1;
        const double extrapolated = std::min(a_next + d2 * q / (1.0 - q), depth_max_);
        const ZeroOrderLimit trial = evaluate(extrapolated, f_next);
        last = trial;
        // L(a_x) > depth_max ≥ a_x: a_x lies below the fixed point, so the
        // fixed point lies above depth_max.
        if (!trial.limited)
          return finish(trial, true);
        if (trial.depth_limit_m >= extrapolated) {
          // a_x is below the fixed point: continue the rising iteration from it.
          previous_a = extrapolated;
          a = trial.depth_limit_m;
          f = trial.chatter_frequency_hz;
          if (close(a, extrapolated))
            return finish(trial, true);
          continue;
        }
        // Overshoot: g(a) = L(a) − a changes sign between a (g = d2 > 0) and a_x.
        return bracket(a, d2, next, extrapolated, trial.depth_limit_m - extrapolated, trial);
      }
      previous_a = a;
      a = a_next;
      f = f_next;
    }
    return finish(last, false);
  }

  int evaluations() const noexcept { return evaluations_; }

 private:
  bool close(double x, double y) const {
    return std::abs(x - y) <= options_.tolerance * std::max(std::abs(x), std::abs(y));
  }

  ZeroOrderLimit evaluate(double depth, double frequency_hz) {
    ++evaluations_;
    // Without process damping the solver is the structure's alone, the same
    // at every speed: built once (process_damped_limits), not per speed.
    if (!params_ || !(depth > 0.0))
      return structural_.limit(speed_);
    const double contact = std::min(depth, model_.max_depth_m());
    const dynamics::ModalModel modes = with_added_damping(
        modes_, process_damping_matrix(model_, *params_, speed_, contact, frequency_hz));
    const ZeroOrderSolver solver(a0_, model_.tool().teeth(), modes, grid_, depth_max_,
                                 options_.zero_order.refine_margin);
    return solver.limit(speed_);
  }

  /// Illinois regula falsi on g(a) = L(a) − a over [lo, hi], g(lo) > 0 > g(hi).
  ZeroOrderLimit bracket(double lo, double g_lo, ZeroOrderLimit at_lo, double hi, double g_hi,
                         ZeroOrderLimit at_hi) {
    double f = at_hi.chatter_frequency_hz;
    ZeroOrderLimit best = std::abs(g_lo) < std::abs(g_hi) ? at_lo : at_hi;
    double best_g = std::min(std::abs(g_lo), std::abs(g_hi));
    while (evaluations_ < options_.max_evaluations) {
      const double x = hi - g_hi * (hi - lo) / (g_hi - g_lo);
      const ZeroOrderLimit r = evaluate(x, f);
      if (!r.limited) {  // g = +∞: x is below the fixed point
        lo = x;
        g_lo = depth_max_ - x;
        continue;
      }
      f = r.chatter_frequency_hz;
      const double g = r.depth_limit_m - x;
      if (std::abs(g) < best_g) {
        best_g = std::abs(g);
        best = r;
      }
      if (std::abs(g) <= options_.tolerance * x || std::abs(hi - lo) <= options_.tolerance * x) {
        return finish(r, true);
      }
      if (g < 0.0) {
        hi = x;
        g_hi = g;
        g_lo *= 0.5;
      } else {
        lo = x;
        g_lo = g;
        g_hi *= 0.5;
      }
    }
    return finish(best, false);
  }

  ZeroOrderLimit finish(ZeroOrderLimit limit, bool converged) const {
    limit.iterations = evaluations_;
    limit.converged = converged;
    if (!limit.limited) {
      limit.depth_limit_m = depth_max_;
      limit.chatter_frequency_hz = 0.0;
      limit.lobe = -1;
      limit.branch = -1;
    }
    return limit;
  }

  const RegenerativeModel& model_;
  const std::optional<ProcessDamping>& params_;
  const Eigen::Matrix3d& a0_;
  const std::vector<double>& grid_;
  const dynamics::ModalModel& modes_;
  const ZeroOrderSolver& structural_;  // modes_ without process damping
  double depth_max_;
  const ProcessDampedOptions& options_;
  double speed_ = 0.0;
  int evaluations_ = 0;
};

}  // namespace

std::vector<ZeroOrderLimit> process_damped_limits(const RegenerativeModel& model,
                                                  const std::optional<ProcessDamping>& params,
                                                  const std::vector<double>& spindle_rad_s,
                                                  const ProcessDampedOptions& options) {
  if (params)
    validate(*params);
  if (options.max_evaluations < 2) {
    throw std::invalid_argument("process damping: max_evaluations must be ≥ 2");
  }
  const ZeroOrderOptions& zo = options.zero_order;
  const Eigen::Matrix3d a0 =
      options.mean_stiffness_per_depth
          ? *options.mean_stiffness_per_depth
          : mean_cutting_stiffness_per_depth(model, zo.averaging_samples, zo.reference_depth_m);
  const std::vector<double> grid = chatter_frequency_grid_rad_s(modal_peaks(model.modes()), zo);
  const double depth_max = zo.depth_max_m > 0.0 ? zo.depth_max_m : model.max_depth_m();

  // The mode sets: all modes (coupled) or each mode alone (envelope).
  std::vector<dynamics::ModalModel> sets;
  if (options.method == MultiModeMethod::coupled) {
    sets.push_back(model.modes());
  } else {
    for (int q = 0; q < model.modes().size(); ++q)
      sets.push_back(model.modes().subset({q}));
  }
  // Each set's solver without process damping: its grid and branch tracking
  // do not depend on the speed, so one serves every speed (and is the whole
  // computation when there is no process damping).
  std::vector<ZeroOrderSolver> structural;
  structural.reserve(sets.size());
  for (const dynamics::ModalModel& set : sets) {
    structural.emplace_back(a0, model.tool().teeth(), set, grid, depth_max, zo.refine_margin);
  }
  std::vector<ZeroOrderLimit> out(spindle_rad_s.size());
  core::parallel_for(spindle_rad_s.size(), options.threads, [&](std::size_t i) {
    ZeroOrderLimit best;
    int evaluations = 0;
    bool converged = true;
    for (std::size_t q = 0; q < sets.size(); ++q) {
      DampedLimit solver(model, params, a0, grid, sets[q], structural[q], depth_max, options);
      ZeroOrderLimit r = solver.solve(spindle_rad_s[i]);
      evaluations += r.iterations;
      converged = converged && r.converged;
      r.mode = options.method == MultiModeMethod::envelope ? static_cast<int>(q) : -1;
      if (q == 0 || r.depth_limit_m < best.depth_limit_m)
        best = r;
    }
    best.spindle_rad_s = spindle_rad_s[i];
    best.iterations = evaluations;
    best.converged = converged;
    out[i] = best;
  });
  return out;
}

std::vector<ZeroOrderLimit> envelope_limits(const Eigen::Matrix3d& mean_stiffness_per_depth,
                                            int teeth, const dynamics::ModalModel& modes,
                                            const std::vector<double>& spindle_rad_s,
                                            const ZeroOrderOptions& options) {
  const std::vector<double> grid = chatter_frequency_grid_rad_s(modal_peaks(modes), options);
  const double depth_max = options.depth_max_m > 0.0 ? options.depth_max_m : 1.0;
  std::vector<ZeroOrderLimit> out(spindle_rad_s.size());
  for (int q = 0; q < modes.size(); ++q) {
    const dynamics::ModalModel one = modes.subset({q});
    const ZeroOrderSolver solver(mean_stiffness_per_depth, teeth, one, grid, depth_max,
                                 options.refine_margin);
    for (std::size_t i = 0; i < spindle_rad_s.size(); ++i) {
      ZeroOrderLimit r = solver.limit(spindle_rad_s[i]);
      r.mode = q;
      if (q == 0 || r.depth_limit_m < out[i].depth_limit_m)
        out[i] = r;
    }
  }
  return out;
}

}  // namespace robomill::stability
