#include "robomill/stability/zero_order.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>

#include "robomill/core/constants.hpp"

namespace robomill::stability {
namespace {

double default_reference_depth_m(const RegenerativeModel& model) {
  const tool::Tool& tool = model.tool();
  const double limit = tool.type() == tool::ToolType::flat ? tool.diameter_m() : tool.radius_m();
  return std::min(model.max_depth_m(), limit);
}

double resolve_depth_max(const RegenerativeModel& model, const ZeroOrderOptions& options) {
  return options.depth_max_m > 0.0 ? options.depth_max_m : model.max_depth_m();
}

/// RegenerativeModel needs some modal model; W, and so A0, never reads it.
dynamics::ModalModel placeholder_modes() {
  return dynamics::ModalModel({dynamics::directional_mode(0, 1.0, 0.5, 1.0)});
}

/// The principal square root (as std::sqrt's, branch cut on the negative
/// real axis) without libm's csqrt and its overflow-safe hypot: the
/// discriminants here are far inside double's range, and csqrt was a sixth
/// of a program's uncertainty run. The larger part is formed from √((|z| ±
/// x)/2) without cancellation, the other as y over twice it.
std::complex<double> principal_sqrt(std::complex<double> z) noexcept {
  const double x = z.real(), y = z.imag();
  const double magnitude = std::sqrt(x * x + y * y);
  if (magnitude == 0.0)
    return {0.0, y};
  if (x >= 0.0) {
    const double t = std::sqrt(0.5 * (magnitude + x));
    return {t, y / (2.0 * t)};
  }
  const double t = std::sqrt(0.5 * (magnitude - x));
  return {std::abs(y) / (2.0 * t), std::copysign(t, y)};
}

/// Phase ε of (3): π + 2 arg λ, in (0, 2π) when Re λ > 0.
double phase_of(std::complex<double> lambda) noexcept {
  return kPi + 2.0 * std::atan(lambda.imag() / lambda.real());
}

/// The depth A0 is averaged at (the given one, or the default), after
/// checking the number of averaging samples.
double averaging_depth_m(const RegenerativeModel& model, int samples, double reference_depth_m) {
  if (samples < 1)
    throw std::invalid_argument("averaging samples must be ≥ 1");
  return reference_depth_m > 0.0 ? reference_depth_m : default_reference_depth_m(model);
}

}  // namespace

Eigen::Matrix3d mean_cutting_stiffness_per_depth(const RegenerativeModel& model, int samples,
                                                 double reference_depth_m) {
  const double depth = averaging_depth_m(model, samples, reference_depth_m);
  const double period_rad = kTwoPi / model.tool().teeth();
  // Midpoint rule over one tooth period: every tooth sweeps 2π/N, so together
  // they visit each edge angle once and the helix lag only shifts the phase.
  return model.cutting_stiffness_sum(period_rad, samples, depth) / (samples * depth);
}

Eigen::Matrix3d mean_cutting_stiffness_per_depth(const tool::Tool& tool,
                                                 const cutting::CuttingLaw& law,
                                                 const cutting::MillingProcess& process,
                                                 int samples, double reference_depth_m) {
  return mean_cutting_stiffness_per_depth(
      RegenerativeModel(tool, law, process, placeholder_modes()), samples, reference_depth_m);
}

Eigen::Matrix3d MeanCuttingStiffnessBasis::operator()(const cutting::LinearLaw& law) const {
  return law.Ktc_pa * per_shear_coefficient[0] + law.Krc_pa * per_shear_coefficient[1] +
         law.Kac_pa * per_shear_coefficient[2];
}

MeanCuttingStiffnessBasis mean_cutting_stiffness_basis(const RegenerativeModel& model, int samples,
                                                       double reference_depth_m) {
  const double depth = averaging_depth_m(model, samples, reference_depth_m);
  const double period_rad = kTwoPi / model.tool().teeth();
  MeanCuttingStiffnessBasis basis;
  basis.per_shear_coefficient =
      model.cutting_stiffness_sum_per_coefficient(period_rad, samples, depth);
  for (Eigen::Matrix3d& m : basis.per_shear_coefficient)
    m /= samples * depth;
  return basis;
}

MeanCuttingStiffnessBasis mean_cutting_stiffness_basis(const tool::Tool& tool,
                                                       const cutting::CuttingLaw& law,
                                                       const cutting::MillingProcess& process,
                                                       int samples, double reference_depth_m) {
  return mean_cutting_stiffness_basis(RegenerativeModel(tool, law, process, placeholder_modes()),
                                      samples, reference_depth_m);
}

std::vector<FrfPeak> modal_peaks(const dynamics::ModalModel& modes) {
  std::vector<FrfPeak> peaks;
  peaks.reserve(modes.modes().size());
  for (const dynamics::Mode& m : modes.modes()) {
    peaks.push_back({m.natural_frequency_hz, m.damping_ratio});
  }
  return peaks;
}

std::vector<double> chatter_frequency_grid_rad_s(const std::vector<FrfPeak>& peaks,
                                                 const ZeroOrderOptions& options) {
  double lowest = std::numeric_limits<double>::infinity(), highest = 0.0;
  for (const FrfPeak& p : peaks) {
    if (!(p.frequency_hz > 0.0) || !std::isfinite(p.frequency_hz)) {
      throw std::invalid_argument("FRF peak frequencies must be positive");
    }
    lowest = std::min(lowest, p.frequency_hz);
    highest = std::max(highest, p.frequency_hz);
  }
  const double f_min = options.min_frequency_hz > 0.0 ? options.min_frequency_hz : 0.5 * lowest;
  const double f_max = options.max_frequency_hz > 0.0 ? options.max_frequency_hz : 1.5 * highest;
  if (!(f_min > 0.0) || !std::isfinite(f_min) || !(f_max > f_min) || !std::isfinite(f_max)) {
    throw std::invalid_argument(
        "zero-order grid: give FRF peaks or a positive min/max chatter frequency");
  }
  if (options.global_points < 2 || options.points_per_peak < 0) {
    throw std::invalid_argument("zero-order grid: need ≥ 2 global points");
  }
  std::vector<double> grid;
  grid.reserve(static_cast<std::size_t>(options.global_points) +
               peaks.size() * static_cast<std::size_t>(options.points_per_peak));
  // Global grid, log-spaced: robot modes (tens of Hz) and tool modes (kHz)
  // are resolved alike.
  const double ratio = std::log(f_max / f_min);
  for (int i = 0; i < options.global_points; ++i) {
    grid.push_back(kTwoPi * f_min * std::exp(ratio * i / (options.global_points - 1)));
  }
  // Around each peak: offsets ζ ωn sinh(s); uniform within a bandwidth, where
  // the phase of G turns fastest, and log-spaced in the flanks.
  const double s_max = std::asinh(options.peak_half_bandwidths);
  std::size_t merged = grid.size();
  for (const FrfPeak& p : peaks) {
    const double wn = kTwoPi * p.frequency_hz;
    const double half_band = std::max(p.damping_ratio, 1e-5) * wn;
    const int count = options.points_per_peak;
    for (int i = 0; i < count; ++i) {
      const double s = count > 1 ? -s_max + 2.0 * s_max * i / (count - 1) : 0.0;
      const double w = wn + half_band * std::sinh(s);
      if (w > 0.0)
        grid.push_back(w);
    }
    // Each peak's points ascend: merge them in (the sorted union, as a sort
    // would give, in linear time).
    std::inplace_merge(grid.begin(), grid.begin() + static_cast<std::ptrdiff_t>(merged),
                       grid.end());
    merged = grid.size();
  }
  // Drop duplicates and points closer than round-off.
  std::vector<double> unique;
  unique.reserve(grid.size());
  for (double w : grid) {
    if (unique.empty() || w > unique.back() * (1.0 + 1e-12))
      unique.push_back(w);
  }
  return unique;
}

std::complex<double> characteristic_determinant(const Eigen::Matrix3d& a0,
                                                const Eigen::Matrix3cd& receptance, double depth_m,
                                                double omega_rad_s, double delay_s) {
  const std::complex<double> regeneration =
      1.0 - std::exp(std::complex<double>(0.0, -omega_rad_s * delay_s));
  const Eigen::Matrix3cd m =
      Eigen::Matrix3cd::Identity() -
      depth_m * regeneration * (a0.cast<std::complex<double>>() * receptance);
  return m.determinant();
}

ZeroOrderSolver::ZeroOrderSolver(const RegenerativeModel& model, const ZeroOrderOptions& options)
    : ZeroOrderSolver(
          mean_cutting_stiffness_per_depth(model, options.averaging_samples,
                                           options.reference_depth_m),
          model.tool().teeth(), [modes = model.modes()](double w) { return modes.receptance(w); },
          chatter_frequency_grid_rad_s(modal_peaks(model.modes()), options),
          resolve_depth_max(model, options), options.refine_margin, &model.modes()) {}

ZeroOrderSolver::ZeroOrderSolver(const RegenerativeModel& model, Frf frf,
                                 const std::vector<FrfPeak>& peaks, const ZeroOrderOptions& options)
    : ZeroOrderSolver(mean_cutting_stiffness_per_depth(model, options.averaging_samples,
                                                       options.reference_depth_m),
                      model.tool().teeth(), std::move(frf),
                      chatter_frequency_grid_rad_s(peaks, options),
                      resolve_depth_max(model, options), options.refine_margin) {}

ZeroOrderSolver::ZeroOrderSolver(const Eigen::Matrix3d& a0, int teeth,
                                 const dynamics::ModalModel& modes, const ZeroOrderOptions& options)
    : ZeroOrderSolver(
          a0, teeth, [modes](double w) { return modes.receptance(w); },
          chatter_frequency_grid_rad_s(modal_peaks(modes), options),
          options.depth_max_m > 0.0 ? options.depth_max_m : 1.0, options.refine_margin, &modes) {}

ZeroOrderSolver::ZeroOrderSolver(const Eigen::Matrix3d& a0, int teeth,
                                 const dynamics::ModalModel& modes, std::vector<double> grid_rad_s,
                                 double depth_max_m, double refine_margin)
    : ZeroOrderSolver(
          a0, teeth, [modes](double w) { return modes.receptance(w); }, std::move(grid_rad_s),
          depth_max_m, refine_margin, &modes) {}

ZeroOrderSolver::ZeroOrderSolver(const Eigen::Matrix3d& a0, int teeth, Frf frf,
                                 std::vector<double> grid_rad_s, double depth_max_m,
                                 double refine_margin, const dynamics::ModalModel* modes)
    : a0_(a0),
      teeth_(teeth),
      frf_(std::move(frf)),
      grid_(std::move(grid_rad_s)),
      depth_max_(depth_max_m),
      refine_margin_(refine_margin) {
  if (teeth_ < 1)
    throw std::invalid_argument("zero-order solver: teeth must be ≥ 1");
  if (!frf_)
    throw std::invalid_argument("zero-order solver: no FRF");
  if (!a0_.allFinite())
    throw std::invalid_argument("zero-order solver: A0 is not finite");
  if (!(depth_max_ > 0.0) || !std::isfinite(depth_max_)) {
    throw std::invalid_argument("zero-order solver: depth_max must be positive");
  }
  if (grid_.size() < 2 || !std::is_sorted(grid_.begin(), grid_.end()) || !(grid_.front() > 0.0)) {
    throw std::invalid_argument("zero-order solver: the grid needs ≥ 2 positive sorted points");
  }
  planar_ = a0_.col(2).isZero(0.0);
  branches_ = planar_ ? 2 : 3;
  if (planar_ && modes) {
    planar_modes_.reserve(modes->modes().size());
    for (const dynamics::Mode& m : modes->modes()) {
      const double wn = kTwoPi * m.natural_frequency_hz;
      const Eigen::RowVector2d loads = m.shape.transpose() * a0_.leftCols<2>();
      planar_modes_.push_back({wn * wn, 2.0 * m.damping_ratio * wn, m.shape.head<2>() * loads});
    }
  }
  build();
}

Eigen::Vector3cd ZeroOrderSolver::eigenvalues(double omega) const {
  using C = std::complex<double>;
  Eigen::Vector3cd out = Eigen::Vector3cd::Zero();
  if (planar_) {
    // Non-zero eigenvalues of A0 G = A0[:, 0:2] G[0:2, :] are those of
    // B = G[0:2, :] A0[:, 0:2] (2x2), from the quadratic in stable form.
    Eigen::Matrix2cd b;
    if (!planar_modes_.empty()) {
      // B = Σ h_r P_r, h_r as conj/|·|² (ModalModel::receptance's form).
      Eigen::Matrix2d real = Eigen::Matrix2d::Zero(), imag = Eigen::Matrix2d::Zero();
      for (const PlanarMode& m : planar_modes_) {
        const double re = m.natural_squared - omega * omega;
        const double im = m.damping_term * omega;
        const double scale = 1.0 / (re * re + im * im);
        real += (re * scale) * m.product;
        imag -= (im * scale) * m.product;
      }
      b.real() = real;
      b.imag() = imag;
    } else {
      b = frf_(omega).topRows<2>() * a0_.leftCols<2>().cast<C>();
    }
    const C half_trace = 0.5 * (b(0, 0) + b(1, 1));
    const C half_diff = 0.5 * (b(0, 0) - b(1, 1));
    C root = principal_sqrt(half_diff * half_diff + b(0, 1) * b(1, 0));
    if (std::real(std::conj(half_trace) * root) < 0.0)
      root = -root;
    const C first = half_trace + root;
    const C det = b(0, 0) * b(1, 1) - b(0, 1) * b(1, 0);
    out[0] = first;
    // det/first as det·conj(first)/|first|²: no libgcc __divdc3.
    out[1] = first != C(0.0, 0.0) ? det * std::conj(first) / std::norm(first) : half_trace - root;
    return out;
  }
  Eigen::ComplexEigenSolver<Eigen::Matrix3cd> solver;
  solver.compute(a0_.cast<C>() * frf_(omega), false);
  return solver.eigenvalues();
}

void ZeroOrderSolver::build() {
  // Curves that still lie below depth_max at an end of the grid continue
  // beyond it (a lobe's flank reaches far above the mode before ap exceeds
  // depth_max): extend that end by octaves, 200 log-spaced points each, up to
  // 64 times the top (1/64 of the bottom) frequency.
  constexpr int points_per_octave = 200;
  constexpr int max_octaves = 6;
  int top_octaves = 0, bottom_octaves = 0;
  const double re_floor = 0.5 / depth_max_;
  // Whether some branch at grid point i lies below depth_max: a question of
  // the point's eigenvalues, not of their branch labels, so the extensions
  // are decided on the ends' eigenvalues alone and the branches tracked once
  // over the final grid (as tracking after every extension would label them).
  std::vector<Eigen::Vector3cd> raw(grid_.size());
  std::vector<char> known(grid_.size(), 0);
  auto below_depth_max = [&](std::size_t i) {
    if (!known[i]) {
      raw[i] = eigenvalues(grid_[i]);
      known[i] = 1;
    }
    for (int b = 0; b < branches_; ++b) {
      const std::complex<double> l = raw[i][b];
      if (std::isfinite(l.real()) && std::isfinite(l.imag()) && l.real() > 0.0 &&
          l.real() > re_floor)
        return true;
    }
    return false;
  };
  for (;;) {
    const bool top = top_octaves < max_octaves && below_depth_max(grid_.size() - 1);
    const bool bottom = bottom_octaves < max_octaves && below_depth_max(0);
    if (!top && !bottom)
      break;
    if (top) {
      const double from = grid_.back();
      for (int i = 1; i <= points_per_octave; ++i) {
        grid_.push_back(from * std::exp2(static_cast<double>(i) / points_per_octave));
      }
      raw.resize(grid_.size());
      known.resize(grid_.size(), 0);
      ++top_octaves;
    }
    if (bottom) {
      const double from = grid_.front();
      std::vector<double> lower;
      lower.reserve(points_per_octave + grid_.size());
      for (int i = points_per_octave; i >= 1; --i) {
        lower.push_back(from * std::exp2(-static_cast<double>(i) / points_per_octave));
      }
      lower.insert(lower.end(), grid_.begin(), grid_.end());
      grid_ = std::move(lower);
      raw.insert(raw.begin(), points_per_octave, Eigen::Vector3cd::Zero());
      known.insert(known.begin(), points_per_octave, 0);
      ++bottom_octaves;
    }
  }
  track(raw, known);
}

void ZeroOrderSolver::track(std::vector<Eigen::Vector3cd>& raw_at, std::vector<char>& known) {
  const std::size_t n = grid_.size();
  const std::size_t nb = static_cast<std::size_t>(branches_);
  lambda_.assign(nb * n, {});
  epsilon_.assign(nb * n, 0.0);
  valid_.assign(nb * n, 0);
  // Permutations of up to three branches, for nearest-neighbour tracking.
  static constexpr int perms3[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                       {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  static constexpr int perms2[2][3] = {{0, 1, 2}, {1, 0, 2}};
  const int perm_count = branches_ == 3 ? 6 : 2;
  Eigen::Vector3cd previous = Eigen::Vector3cd::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    if (!known[i]) {
      raw_at[i] = eigenvalues(grid_[i]);
      known[i] = 1;
    }
    const Eigen::Vector3cd& raw = raw_at[i];
    Eigen::Vector3cd ordered = raw;
    if (i > 0) {
      // |raw[a] − previous[b]| once per pair (√|·|², not std::abs's
      // overflow-safe hypot: eigenvalues are far inside double's range, and
      // the tracking was a tenth of a path's uncertainty run).
      double apart[3][3] = {};
      for (int a = 0; a < branches_; ++a)
        for (int b = 0; b < branches_; ++b)
          apart[a][b] = std::sqrt(std::norm(raw[a] - previous[b]));
      double best = std::numeric_limits<double>::infinity();
      for (int p = 0; p < perm_count; ++p) {
        const int* perm = branches_ == 3 ? perms3[p] : perms2[p];
        double distance = 0.0;
        for (int b = 0; b < branches_; ++b)
          distance += apart[perm[b]][b];
        if (distance < best) {
          best = distance;
          for (int b = 0; b < branches_; ++b)
            ordered[b] = raw[perm[b]];
        }
      }
    }
    previous = ordered;
    for (std::size_t b = 0; b < nb; ++b) {
      const std::complex<double> l = ordered[static_cast<Eigen::Index>(b)];
      const std::size_t at = b * n + i;
      lambda_[at] = l;
      const bool ok = std::isfinite(l.real()) && std::isfinite(l.imag()) && l.real() > 0.0;
      valid_[at] = ok ? 1 : 0;
      epsilon_[at] = ok ? phase_of(l) : 0.0;
    }
  }
}

bool ZeroOrderSolver::refine(int branch, int interval, int lobe, double delay_s, double& omega,
                             double& depth) const {
  const std::size_t n = grid_.size();
  const std::size_t i0 = static_cast<std::size_t>(branch) * n + static_cast<std::size_t>(interval);
  const double w0 = grid_[static_cast<std::size_t>(interval)];
  const double w1 = grid_[static_cast<std::size_t>(interval) + 1];
  const std::complex<double> l0 = lambda_[i0], l1 = lambda_[i0 + 1];
  const double target = kTwoPi * lobe;
  // The branch's eigenvalue at ω: the one nearest the linear interpolation.
  auto branch_value = [&](double w) {
    const double t = (w - w0) / (w1 - w0);
    const std::complex<double> guess = l0 + t * (l1 - l0);
    const Eigen::Vector3cd all = eigenvalues(w);
    int best = 0;
    for (int b = 1; b < branches_; ++b) {
      if (std::norm(all[b] - guess) < std::norm(all[best] - guess))
        best = b;
    }
    return std::complex<double>(all[best]);
  };
  double a = w0, b = w1;
  double fa = w0 * delay_s - epsilon_[i0] - target;
  double fb = w1 * delay_s - epsilon_[i0 + 1] - target;
  if (fa == 0.0) {
    omega = a;
    depth = 0.5 / l0.real();
    return true;
  }
  if (fb == 0.0) {
    omega = b;
    depth = 0.5 / l1.real();
    return true;
  }
  if (fa * fb > 0.0)
    return false;
  std::complex<double> lc = l0;
  double c = a;
  // Illinois regula falsi on f(ω) = ωτ − ε(ω) − 2πk.
  for (int iteration = 0; iteration < 100; ++iteration) {
    c = b - fb * (b - a) / (fb - fa);
    lc = branch_value(c);
    if (!(lc.real() > 0.0))
      return false;
    const double fc = c * delay_s - phase_of(lc) - target;
    if (std::abs(fc) < 1e-12 || std::abs(b - a) < 4e-16 * c)
      break;
    if (fc * fb < 0.0) {
      a = b;
      fa = fb;
    } else {
      fa *= 0.5;
    }
    b = c;
    fb = fc;
  }
  const double residual = c * delay_s - phase_of(lc) - target;
  if (!(std::abs(residual) < 1e-6))
    return false;
  omega = c;
  depth = 0.5 / lc.real();
  return true;
}

ZeroOrderLimit ZeroOrderSolver::limit(double spindle_rad_s) const {
  if (!(spindle_rad_s > 0.0) || !std::isfinite(spindle_rad_s)) {
    throw std::invalid_argument("zero-order limit: spindle speed must be positive");
  }
  ZeroOrderLimit result;
  result.spindle_rad_s = spindle_rad_s;
  result.depth_limit_m = depth_max_;
  const double delay = kTwoPi / (teeth_ * spindle_rad_s);
  const std::size_t n = grid_.size();
  // A crossing with interpolated Re λ below this would lie above depth_max.
  const double re_floor = 0.5 / (depth_max_ * (1.0 + refine_margin_));

  struct Candidate {
    double depth;
    int branch, interval, lobe;
  };
  std::vector<Candidate> candidates;
  double best_depth = std::numeric_limits<double>::infinity();
  for (int b = 0; b < branches_; ++b) {
    const std::size_t base = static_cast<std::size_t>(b) * n;
    for (std::size_t i = 0; i + 1 < n; ++i) {
      if (!valid_[base + i] || !valid_[base + i + 1])
        continue;
      const double re0 = lambda_[base + i].real(), re1 = lambda_[base + i + 1].real();
      if (std::max(re0, re1) < re_floor)
        continue;
      const double f0 = grid_[i] * delay - epsilon_[base + i];
      const double f1 = grid_[i + 1] * delay - epsilon_[base + i + 1];
      const double lo = std::min(f0, f1), hi = std::max(f0, f1);
      const long k_first = std::max(0L, static_cast<long>(std::ceil(lo / kTwoPi)));
      const long k_last = static_cast<long>(std::floor(hi / kTwoPi));
      for (long k = k_first; k <= k_last; ++k) {
        const double t = f1 != f0 ? (kTwoPi * static_cast<double>(k) - f0) / (f1 - f0) : 0.0;
        const double re = re0 + t * (re1 - re0);
        if (!(re >= re_floor))
          continue;
        const double depth = 0.5 / re;
        if (depth > best_depth * (1.0 + refine_margin_))
          continue;
        best_depth = std::min(best_depth, depth);
        candidates.push_back({depth, b, static_cast<int>(i), static_cast<int>(k)});
      }
    }
  }
  if (candidates.empty())
    return result;
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& x, const Candidate& y) { return x.depth < y.depth; });
  double best = std::numeric_limits<double>::infinity();
  int refined = 0, tries = 0;
  for (const Candidate& c : candidates) {
    if (c.depth > candidates.front().depth * (1.0 + refine_margin_) && refined > 0)
      break;
    if (refined >= 16 || ++tries > 64)
      break;
    double omega = 0.0, depth = 0.0;
    if (!refine(c.branch, c.interval, c.lobe, delay, omega, depth))
      continue;
    ++refined;
    if (depth < best) {
      best = depth;
      if (depth <= depth_max_) {
        result.depth_limit_m = depth;
        result.limited = true;
        result.chatter_frequency_hz = omega / kTwoPi;
        result.lobe = c.lobe;
        result.branch = c.branch;
      }
    }
  }
  return result;
}

std::vector<ZeroOrderLimit> ZeroOrderSolver::limits(
    const std::vector<double>& spindle_rad_s) const {
  std::vector<ZeroOrderLimit> out;
  out.reserve(spindle_rad_s.size());
  for (double speed : spindle_rad_s)
    out.push_back(limit(speed));
  return out;
}

ZeroOrderLimit ZeroOrderSolver::minimum_limit() const {
  const std::size_t n = grid_.size();
  double best_re = 0.0;
  int best_branch = -1;
  std::size_t best_i = 0;
  for (int b = 0; b < branches_; ++b) {
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t at = static_cast<std::size_t>(b) * n + i;
      if (valid_[at] && lambda_[at].real() > best_re) {
        best_re = lambda_[at].real();
        best_branch = b;
        best_i = i;
      }
    }
  }
  ZeroOrderLimit result;
  result.depth_limit_m = depth_max_;
  if (best_branch < 0)
    return result;
  // Golden-section search for the largest Re λ between the neighbours.
  const std::size_t base = static_cast<std::size_t>(best_branch) * n;
  const std::complex<double> anchor = lambda_[base + best_i];
  auto re_at = [&](double w, std::complex<double>& value) {
    const Eigen::Vector3cd all = eigenvalues(w);
    int pick = 0;
    for (int b = 1; b < branches_; ++b) {
      if (std::norm(all[b] - anchor) < std::norm(all[pick] - anchor))
        pick = b;
    }
    value = all[pick];
    return value.real();
  };
  double lo = grid_[best_i > 0 ? best_i - 1 : 0];
  double hi = grid_[std::min(best_i + 1, n - 1)];
  const double golden = 0.5 * (std::sqrt(5.0) - 1.0);
  std::complex<double> v1, v2;
  double x1 = hi - golden * (hi - lo), x2 = lo + golden * (hi - lo);
  double r1 = re_at(x1, v1), r2 = re_at(x2, v2);
  for (int it = 0; it < 80 && hi - lo > 1e-13 * hi; ++it) {
    if (r1 > r2) {
      hi = x2;
      x2 = x1;
      r2 = r1;
      v2 = v1;
      x1 = hi - golden * (hi - lo);
      r1 = re_at(x1, v1);
    } else {
      lo = x1;
      x1 = x2;
      r1 = r2;
      v1 = v2;
      x2 = lo + golden * (hi - lo);
      r2 = re_at(x2, v2);
    }
  }
  double omega = r1 > r2 ? x1 : x2;
  std::complex<double> value = r1 > r2 ? v1 : v2;
  if (!(value.real() >= best_re)) {
    omega = grid_[best_i];
    value = anchor;
  }
  const double depth = 0.5 / value.real();
  result.chatter_frequency_hz = omega / kTwoPi;
  result.branch = best_branch;
  result.lobe = 0;
  result.spindle_rad_s = kTwoPi * omega / (teeth_ * phase_of(value));
  if (depth <= depth_max_) {
    result.depth_limit_m = depth;
    result.limited = true;
  }
  return result;
}

}  // namespace robomill::stability
