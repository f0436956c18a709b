#include "robomill/dynamics/modal_fit.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"

namespace robomill::dynamics {
namespace {

using cd = std::complex<double>;
using Eigen::Index;

// Poles with ζ ≥ 0.5 are not structural modes of a machine tool or robot;
// they are what the rational model uses to bend itself around the residual
// effects of modes outside the band.
constexpr double kMaxDamping = 0.5;

// Automatic bands: peaks of the smoothed summed magnitude are grouped so that
// the peaks of one band lie within this ratio of each other, at most this many
// per band; with band edges at the geometric means between groups a band spans
// about a decade. The LSCF poles are then resolved well inside the unit circle
// (the lowest mode of a band sits at least at angle π f/f_high ≈ 0.3 rad).
constexpr double kMaxPeakRatio = 6.0;
constexpr int kMaxPeaksPerBand = 5;
// A peak must rise this much (ratio of magnitudes) above the higher of the
// valleys that separate it from higher peaks; 2 % noise averaged over the five
// smoothing points moves the log magnitude by < 1 %.
constexpr double kMinPeakProminence = 1.2;
constexpr int kSmoothingHalfWidth = 2;

// A mode whose own term is smaller than this fraction of the fitted FRF in its
// half-power band, or smaller than this many times the local fit error, is a
// computational mode (fits noise or the band's residual effects).
constexpr double kMinContribution = 0.01;
constexpr double kContributionOverError = 3.0;

std::string hz(double f) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g Hz", f);
  return text;
}

std::string band_name(int index, const FitBand& band) {
  return "band " + std::to_string(index + 1) + " (" + hz(band.low_hz) + " to " + hz(band.high_hz) +
         ")";
}

// ---------------------------------------------------------------- input

/// The input as receptances on one grid without 0 Hz: frequency_hz (N),
/// omega (N), h (N x FRFs).
struct Data {
  Eigen::VectorXd frequency_hz;
  Eigen::VectorXd omega;
  Eigen::MatrixXcd h;
  int driving_point = -1;  ///< first FRF with response axis = reference axis
};

void check_frf(const Frf& frf, std::size_t index) {
  const std::string which = "FRF " + std::to_string(index + 1) + ": ";
  if (frf.frequency_hz.empty())
    throw std::invalid_argument(which + "empty frequency grid");
  if (frf.value.size() != frf.frequency_hz.size()) {
    throw std::invalid_argument(which + "frequency and value counts differ");
  }
  for (std::size_t k = 0; k < frf.frequency_hz.size(); ++k) {
    const double f = frf.frequency_hz[k];
    if (!std::isfinite(f) || f < 0.0 || (k > 0 && !(f > frf.frequency_hz[k - 1]))) {
      throw std::invalid_argument(which +
                                  "frequencies must be finite, ≥ 0 and strictly increasing");
    }
    if (!std::isfinite(frf.value[k].real()) || !std::isfinite(frf.value[k].imag())) {
      throw std::invalid_argument(which + "value at " + hz(f) + " is not finite");
    }
  }
  if (frf.response_axis < 0 || frf.response_axis > 2 || frf.reference_axis < 0 ||
      frf.reference_axis > 2) {
    throw std::invalid_argument(which + "axes must be 0, 1 or 2");
  }
}

Data prepare(const std::vector<Frf>& frfs) {
  if (frfs.empty())
    throw std::invalid_argument("modal fit: no FRF given");
  for (std::size_t i = 0; i < frfs.size(); ++i)
    check_frf(frfs[i], i);
  const std::vector<double>& grid = frfs.front().frequency_hz;
  for (std::size_t i = 1; i < frfs.size(); ++i) {
    const std::vector<double>& other = frfs[i].frequency_hz;
    bool same = other.size() == grid.size();
    for (std::size_t k = 0; same && k < grid.size(); ++k) {
      same = std::abs(other[k] - grid[k]) <= 1e-9 * std::max(1.0, std::abs(grid[k]));
    }
    if (!same) {
      throw std::invalid_argument("modal fit: FRF " + std::to_string(i + 1) +
                                  " is not on the frequency grid of FRF 1");
    }
  }
  // A 0 Hz point carries no dynamics, cannot be integrated from mobility or
  // accelerance, and the lower residual −1/(ω² M) is singular there.
  const std::size_t first = grid.front() > 0.0 ? 0 : 1;
  const Index n = static_cast<Index>(grid.size() - first);
  Data data;
  data.frequency_hz.resize(n);
  data.omega.resize(n);
  data.h.resize(n, static_cast<Index>(frfs.size()));
  for (Index k = 0; k < n; ++k) {
    data.frequency_hz[k] = grid[first + static_cast<std::size_t>(k)];
    data.omega[k] = kTwoPi * data.frequency_hz[k];
  }
  for (std::size_t i = 0; i < frfs.size(); ++i) {
    const Frf& frf = frfs[i];
    for (Index k = 0; k < n; ++k) {
      const cd value = frf.value[first + static_cast<std::size_t>(k)];
      const cd iw(0.0, data.omega[k]);
      data.h(k, static_cast<Index>(i)) = frf.kind == FrfKind::receptance ? value
                                         : frf.kind == FrfKind::mobility ? value / iw
                                                                         : value / (iw * iw);
    }
    if (data.driving_point < 0 && frf.response_axis == frf.reference_axis) {
      data.driving_point = static_cast<int>(i);
    }
  }
  return data;
}

/// First index with f ≥ low and one past the last with f ≤ high.
std::pair<Index, Index> index_range(const Data& data, double low_hz, double high_hz) {
  const double* begin = data.frequency_hz.data();
  const double* end = begin + data.frequency_hz.size();
  return {std::lower_bound(begin, end, low_hz) - begin,
          std::upper_bound(begin, end, high_hz) - begin};
}

// ---------------------------------------------------------------- bands

/// Peaks of the smoothed log of the summed, per-FRF normalized magnitude
/// (a mode shows in at least one FRF), with enough prominence.
std::vector<double> find_peaks(const Data& data) {
  const Index n = data.h.rows();
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(n);
  for (Index o = 0; o < data.h.cols(); ++o) {
    const Eigen::VectorXd magnitude = data.h.col(o).cwiseAbs();
    const double rms = std::sqrt(magnitude.squaredNorm() / static_cast<double>(n));
    if (rms > 0.0)
      sum += magnitude / rms;
  }
  Eigen::VectorXd log_sum(n);
  for (Index k = 0; k < n; ++k)
    log_sum[k] = std::log(std::max(sum[k], 1e-300));
  Eigen::VectorXd smooth(n);
  for (Index k = 0; k < n; ++k) {
    const Index a = std::max<Index>(0, k - kSmoothingHalfWidth);
    const Index b = std::min<Index>(n - 1, k + kSmoothingHalfWidth);
    smooth[k] = log_sum.segment(a, b - a + 1).mean();
  }
  // Topographic prominence ≥ the threshold: on each side the curve must dip
  // that far below the peak before it rises above it (or the data end). Each
  // walk stops as soon as that is decided, so noise maxima cost a few steps.
  const double min_prominence = std::log(kMinPeakProminence);
  auto dips = [&](Index k, Index step) {
    for (Index j = k + step; j >= 0 && j < n; j += step) {
      if (smooth[j] > smooth[k])
        return false;
      if (smooth[k] - smooth[j] >= min_prominence)
        return true;
    }
    return false;
  };
  std::vector<double> peaks;
  for (Index k = 1; k + 1 < n; ++k) {
    if (smooth[k] > smooth[k - 1] && smooth[k] >= smooth[k + 1] && dips(k, -1) && dips(k, 1))
      peaks.push_back(data.frequency_hz[k]);
  }
  return peaks;
}

std::vector<FitBand> automatic_bands(const Data& data) {
  const double low = data.frequency_hz[0];
  const double high = data.frequency_hz[data.frequency_hz.size() - 1];
  const std::vector<double> peaks = find_peaks(data);
  std::vector<std::vector<double>> groups;
  for (double f : peaks) {
    if (groups.empty() || f > kMaxPeakRatio * groups.back().front() ||
        static_cast<int>(groups.back().size()) >= kMaxPeaksPerBand) {
      groups.emplace_back();
    }
    groups.back().push_back(f);
  }
  std::vector<FitBand> bands;
  if (groups.empty())
    return {FitBand{low, high, 0}};
  for (std::size_t g = 0; g < groups.size(); ++g) {
    FitBand band;
    band.low_hz = g == 0 ? low : bands.back().high_hz;
    band.high_hz =
        g + 1 == groups.size() ? high : std::sqrt(groups[g].back() * groups[g + 1].front());
    bands.push_back(band);
  }
  return bands;
}

// ---------------------------------------------------------------- LSCF

struct Pole {
  double omega_n = 0.0;  ///< |λ|, rad/s
  double zeta = 0.0;     ///< −Re λ / |λ|
  cd lambda() const {
    return {-zeta * omega_n, omega_n * std::sqrt(std::max(0.0, 1.0 - zeta * zeta))};
  }
};

/// Poles (upper half plane) of the LSCF common-denominator model for every
/// order 1..max_order, fitted to the points [begin, end) of a band whose upper
/// edge sets the sampling time Δt = 1 / (2 f_high) (Guillaume et al. 2003,
/// Peeters et al. 2004).
///
/// Model per FRF o: H_o(ω) = N_o(z) / d(z), z = exp(iωΔt), with real
/// polynomial coefficients β_o (numerator) and α (shared denominator), both of
/// degree n. The linearized weighted error ε_o = w (N_o − d H_o) gives the
/// normal matrices R_o = Re Γᴴ Γ, S_o = Re Γᴴ Φ, T_o = Re Φᴴ Φ with
/// Γ_kj = w_k z_k^j and Φ_kj = −w_k z_k^j H_ok. Eliminating the numerators
/// leaves the reduced normal equations M α = 0, M = Σ_o (T_o − S_oᵀ R_o⁻¹ S_o),
/// solved with the highest coefficient α_n = 1: this removes the trivial
/// solution α = 0, and with it the z-domain LSCF estimates most noise poles as
/// unstable (negative damping), which keeps its stabilization diagrams clear
/// (Peeters et al. 2004). Each matrix is Toeplitz — its (j, l) entry depends
/// on l − j only — so all orders are sub-blocks of the highest order's
/// matrices, built from 2n + 1 lag sums in one pass over the data.
///
/// Basis: z = exp(iωΔt) rather than powers of iω (Laplace domain) or the
/// orthogonal polynomials of the rational-fraction polynomial method
/// (Richardson & Formenti 1982): the powers z^j are orthogonal over the full
/// unit circle and nearly so over a band that reaches Nyquist, so orders up to
/// 40 stay well conditioned without re-orthogonalizing per FRF, and the poles
/// follow from one companion matrix. The z-domain model is not the continuous
/// modal model (each mode's aliases need extra poles), which the higher orders
/// absorb; on noise-free data the poles are exact to ~1e-10.
///
/// Weighting: unit (after scaling each FRF to unit mean square in the band).
/// The equation error N − d H = d (Ĥ − H) already weights the output error by
/// |d|, small at resonances; with noise proportional to the response (hammer
/// tests) the equation-error noise |d| σ ≈ σ/|H| |N| is then roughly uniform.
/// Weighting by 1 / |H| instead would scale the resonance data by |d|² and
/// bias light damping (−20 % on the 0.81 % mode of 003 Tab. 1 at 2 % noise).
std::vector<std::vector<Pole>> lscf_poles(const Data& data, Index begin, Index end, double high_hz,
                                          int max_order) {
  const double dt = 1.0 / (2.0 * high_hz);
  const int n = max_order;
  const Index outputs = data.h.cols();
  std::vector<Eigen::MatrixXd> r_mat(outputs), s_mat(outputs), t_mat(outputs);
  Eigen::VectorXcd r(n + 1), t(n + 1), s(2 * n + 1);
  for (Index o = 0; o < outputs; ++o) {
    r.setZero();
    t.setZero();
    s.setZero();
    const auto h = data.h.col(o).segment(begin, end - begin);
    const double mean_square = h.squaredNorm() / static_cast<double>(h.size());
    const double scale = mean_square > 0.0 ? 1.0 / std::sqrt(mean_square) : 1.0;
    for (Index k = 0; k < h.size(); ++k) {
      const cd hk = scale * h[k];
      const double hk2 = std::norm(hk);
      const cd z = std::polar(1.0, data.omega[begin + k] * dt);
      cd zp(1.0, 0.0);  // z^p by recurrence: |z| = 1, so rounding stays at p ε
      for (int p = 0; p <= n; ++p) {
        r[p] += zp;
        t[p] += hk2 * zp;
        s[n + p] += hk * zp;
        if (p > 0)
          s[n - p] += hk * std::conj(zp);
        zp *= z;
      }
    }
    Eigen::MatrixXd& rm = r_mat[static_cast<std::size_t>(o)];
    Eigen::MatrixXd& sm = s_mat[static_cast<std::size_t>(o)];
    Eigen::MatrixXd& tm = t_mat[static_cast<std::size_t>(o)];
    rm.resize(n + 1, n + 1);
    sm.resize(n + 1, n + 1);
    tm.resize(n + 1, n + 1);
    for (int j = 0; j <= n; ++j) {
      for (int l = 0; l <= n; ++l) {
        rm(j, l) = r[std::abs(l - j)].real();
        tm(j, l) = t[std::abs(l - j)].real();
        sm(j, l) = -s[n + l - j].real();
      }
    }
  }

  std::vector<std::vector<Pole>> poles(static_cast<std::size_t>(n + 1));
  for (int m = 1; m <= n; ++m) {
    Eigen::MatrixXd reduced = Eigen::MatrixXd::Zero(m + 1, m + 1);
    for (Index o = 0; o < outputs; ++o) {
      const auto rb = r_mat[static_cast<std::size_t>(o)].topLeftCorner(m + 1, m + 1);
      const auto sb = s_mat[static_cast<std::size_t>(o)].topLeftCorner(m + 1, m + 1);
      const auto tb = t_mat[static_cast<std::size_t>(o)].topLeftCorner(m + 1, m + 1);
      const Eigen::LDLT<Eigen::MatrixXd> rf(rb);
      reduced += tb - sb.transpose() * rf.solve(sb);
    }
    const Eigen::VectorXd a = reduced.topLeftCorner(m, m).ldlt().solve(-reduced.col(m).head(m));
    if (!a.allFinite())
      continue;
    // Roots of z^m + a_{m−1} z^{m−1} + … + a_0: eigenvalues of the companion matrix.
    Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(m, m);
    for (int i = 1; i < m; ++i)
      companion(i, i - 1) = 1.0;
    companion.col(m - 1) = -a;
    const Eigen::EigenSolver<Eigen::MatrixXd> solver(companion, false);
    if (solver.info() != Eigen::Success)
      continue;
    for (const cd& z : solver.eigenvalues()) {
      if (!(z.imag() > 0.0) || std::abs(z) == 0.0)
        continue;
      const cd lambda = std::log(z) / dt;
      Pole pole;
      pole.omega_n = std::abs(lambda);
      pole.zeta = -lambda.real() / pole.omega_n;
      poles[static_cast<std::size_t>(m)].push_back(pole);
    }
  }
  return poles;
}

// ---------------------------------------------------------------- stabilization

struct SelectedPole {
  Pole pole;
  int band = 0;
  int stable_orders = 0;
};

/// Stabilization diagram of one band and its modes: a pole is stable when the
/// nearest physical pole of the previous order is within the frequency (and
/// damping) tolerance; stable poles are clustered by frequency (single linkage
/// with the frequency tolerance), and a cluster with stable poles at
/// `min_stable_orders` orders or more is a mode, with the median frequency and
/// median damping of its poles.
std::vector<SelectedPole> stabilize(const std::vector<std::vector<Pole>>& poles, int band_index,
                                    const FitBand& band, const ModalFitOptions& options,
                                    std::vector<StabilizationPoint>& diagram) {
  const double w_low = kTwoPi * band.low_hz, w_high = kTwoPi * band.high_hz;
  auto physical = [&](const Pole& p) {
    return p.zeta > 0.0 && p.zeta < kMaxDamping && p.omega_n >= w_low && p.omega_n <= w_high;
  };
  struct Candidate {
    double omega_n, zeta;
    int order;
  };
  std::vector<Candidate> stable;
  for (std::size_t m = 1; m < poles.size(); ++m) {
    for (const Pole& p : poles[m]) {
      if (!physical(p))
        continue;
      StabilizationPoint point;
      point.band = band_index;
      point.order = static_cast<int>(m);
      point.frequency_hz = p.omega_n / kTwoPi;
      point.damping_ratio = p.zeta;
      const Pole* nearest = nullptr;
      for (const Pole& q : poles[m - 1]) {
        if (physical(q) && (nearest == nullptr || std::abs(q.omega_n - p.omega_n) <
                                                      std::abs(nearest->omega_n - p.omega_n))) {
          nearest = &q;
        }
      }
      if (nearest != nullptr) {
        point.stable_frequency = std::abs(nearest->omega_n - p.omega_n) <=
                                 options.frequency_stability * nearest->omega_n;
        point.stable_damping =
            point.stable_frequency &&
            std::abs(nearest->zeta - p.zeta) <= options.damping_stability * nearest->zeta;
      }
      if (point.stable_damping)
        stable.push_back({p.omega_n, p.zeta, point.order});
      diagram.push_back(point);
    }
  }
  std::sort(stable.begin(), stable.end(),
            [](const Candidate& a, const Candidate& b) { return a.omega_n < b.omega_n; });
  std::vector<SelectedPole> selected;
  std::size_t first = 0;
  while (first < stable.size()) {
    std::size_t last = first + 1;
    while (last < stable.size() && stable[last].omega_n - stable[last - 1].omega_n <=
                                       options.frequency_stability * stable[last - 1].omega_n) {
      ++last;
    }
    std::vector<double> omega, zeta;
    std::vector<int> orders;
    for (std::size_t i = first; i < last; ++i) {
      omega.push_back(stable[i].omega_n);
      zeta.push_back(stable[i].zeta);
      orders.push_back(stable[i].order);
    }
    std::sort(orders.begin(), orders.end());
    const int distinct =
        static_cast<int>(std::unique(orders.begin(), orders.end()) - orders.begin());
    if (distinct >= options.min_stable_orders) {
      auto median = [](std::vector<double>& v) {
        const std::size_t h = v.size() / 2;
        std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h), v.end());
        if (v.size() % 2 == 1)
          return v[h];
        const double upper = v[h];
        return 0.5 *
               (upper + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h)));
      };
      SelectedPole pole;
      pole.pole.omega_n = median(omega);
      pole.pole.zeta = median(zeta);
      pole.band = band_index;
      pole.stable_orders = distinct;
      selected.push_back(pole);
    }
    first = last;
  }
  return selected;
}

// ---------------------------------------------------------------- modal model

/// The model of all bands: poles λ_r (upper half plane), residues R_ro and, per
/// band b and FRF o, a real lower residual L_bo and upper residual U_bo:
///   Ĥ_o(ω) = Σ_r [R_ro/(iω − λ_r) + R̄_ro/(iω − λ̄_r)] − L_bo/ω² + U_bo   in band b.
/// The lower residual is the mass line of modes below the band, the upper one
/// the static compliance of modes above it; outside every band only the modes
/// count.
struct ModalParameters {
  std::vector<cd> lambda;
  std::vector<int> band;           ///< per mode: the band its pole came from
  std::vector<int> stable_orders;  ///< per mode
  Eigen::MatrixXcd residue;        ///< modes x FRFs
  Eigen::MatrixXd lower, upper;    ///< bands x FRFs
};

/// Rows [first, second) of the data fitted in each band.
using Ranges = std::vector<std::pair<Index, Index>>;

Index points_in(const Ranges& ranges) {
  Index used = 0;
  for (const auto& [begin, end] : ranges)
    used += end - begin;
  return used;
}

/// Output-error weight of one measured value: 1 / |H|, the inverse standard
/// deviation of noise proportional to the response (hammer tests), so that
/// every band and every anti-resonance counts.
double weight(const Data& data, Index k, Index o, double floor) {
  return 1.0 / std::max(std::abs(data.h(k, o)), floor);
}

double weight_floor(const Data& data, Index o) {
  return std::max(1e-12 * data.h.col(o).cwiseAbs().maxCoeff(), 1e-300);
}

/// The fitted receptances on the whole grid (N x FRFs).
Eigen::MatrixXcd model_frfs(const Data& data, const ModalParameters& p, const Ranges& ranges) {
  const Index n = data.h.rows(), outputs = data.h.cols();
  Eigen::MatrixXcd fitted = Eigen::MatrixXcd::Zero(n, outputs);
  for (Index o = 0; o < outputs; ++o) {
    for (Index k = 0; k < n; ++k) {
      const cd iw(0.0, data.omega[k]);
      cd value(0.0, 0.0);
      for (std::size_t r = 0; r < p.lambda.size(); ++r) {
        const cd res = p.residue(static_cast<Index>(r), o);
        value += res / (iw - p.lambda[r]) + std::conj(res) / (iw - std::conj(p.lambda[r]));
      }
      fitted(k, o) = value;
    }
    for (std::size_t b = 0; b < ranges.size(); ++b) {
      const Index bi = static_cast<Index>(b);
      for (Index k = ranges[b].first; k < ranges[b].second; ++k) {
        fitted(k, o) += -p.lower(bi, o) / (data.omega[k] * data.omega[k]) + p.upper(bi, o);
      }
    }
  }
  return fitted;
}

/// Least-squares frequency-domain residues (LSFD; Peeters et al. 2004; Heylen,
/// Lammens & Sas, "Modal Analysis Theory and Testing", 1997) with the poles
/// fixed: the model above is linear in R, L and U, fitted per FRF over the
/// points of all bands at once (so each mode has one residue per FRF and each
/// band its own residuals). Weighted by 1 / |H|; real and imaginary parts are
/// stacked, columns scaled to unit norm, solved by column-pivoting QR.
void fit_residues(const Data& data, ModalParameters& p, const Ranges& ranges) {
  const Index modes = static_cast<Index>(p.lambda.size());
  const Index bands = static_cast<Index>(ranges.size());
  const Index outputs = data.h.cols();
  const Index columns = 2 * modes + 2 * bands;
  p.residue.resize(modes, outputs);
  p.lower.resize(bands, outputs);
  p.upper.resize(bands, outputs);
  Eigen::MatrixXd design(2 * points_in(ranges), columns);
  Eigen::VectorXd rhs(design.rows());
  for (Index o = 0; o < outputs; ++o) {
    design.setZero();
    const double floor = weight_floor(data, o);
    Index row = 0;
    for (Index b = 0; b < bands; ++b) {
      const auto [begin, end] = ranges[static_cast<std::size_t>(b)];
      for (Index k = begin; k < end; ++k) {
        const double w = weight(data, k, o, floor);
        const cd iw(0.0, data.omega[k]);
        for (Index r = 0; r < modes; ++r) {
          const cd lambda = p.lambda[static_cast<std::size_t>(r)];
          const cd a = 1.0 / (iw - lambda), c = 1.0 / (iw - std::conj(lambda));
          const cd re = w * (a + c), im = w * cd(0.0, 1.0) * (a - c);
          design(row, 2 * r) = re.real();
          design(row + 1, 2 * r) = re.imag();
          design(row, 2 * r + 1) = im.real();
          design(row + 1, 2 * r + 1) = im.imag();
        }
        design(row, 2 * modes + 2 * b) = -w / (data.omega[k] * data.omega[k]);
        design(row, 2 * modes + 2 * b + 1) = w;
        rhs[row] = w * data.h(k, o).real();
        rhs[row + 1] = w * data.h(k, o).imag();
        row += 2;
      }
    }
    const Eigen::VectorXd scale = design.colwise().norm().transpose().cwiseMax(1e-300);
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(design *
                                                         scale.cwiseInverse().asDiagonal());
    const Eigen::VectorXd x = qr.solve(rhs).cwiseQuotient(scale);
    for (Index r = 0; r < modes; ++r)
      p.residue(r, o) = cd(x[2 * r], x[2 * r + 1]);
    for (Index b = 0; b < bands; ++b) {
      p.lower(b, o) = x[2 * modes + 2 * b];
      p.upper(b, o) = x[2 * modes + 2 * b + 1];
    }
  }
}

// ---------------------------------------------------------------- refinement

/// Where refine's parameter vector θ holds each value: the poles (Re, Im)
/// first, then per output its residues (Re, Im) and each band's lower and
/// upper residual.
struct ThetaLayout {
  Index modes, outputs, nb, per_output, columns;
};

/// θ of the parameters q.
Eigen::VectorXd pack(const ThetaLayout& l, const ModalParameters& q) {
  const Index modes = l.modes;
  const Index outputs = l.outputs;
  const Index nb = l.nb;
  const Index per_output = l.per_output;
  const Index columns = l.columns;
  Eigen::VectorXd theta(columns);
  for (Index r = 0; r < modes; ++r) {
    theta[2 * r] = q.lambda[static_cast<std::size_t>(r)].real();
    theta[2 * r + 1] = q.lambda[static_cast<std::size_t>(r)].imag();
  }
  for (Index o = 0; o < outputs; ++o) {
    const Index base = 2 * modes + o * per_output;
    for (Index r = 0; r < modes; ++r) {
      theta[base + 2 * r] = q.residue(r, o).real();
      theta[base + 2 * r + 1] = q.residue(r, o).imag();
    }
    for (Index b = 0; b < nb; ++b) {
      theta[base + 2 * modes + 2 * b] = q.lower(b, o);
      theta[base + 2 * modes + 2 * b + 1] = q.upper(b, o);
    }
  }
  return theta;
}

/// The parameters q of θ.
void unpack(const ThetaLayout& l, const Eigen::VectorXd& theta, ModalParameters& q) {
  const Index modes = l.modes;
  const Index outputs = l.outputs;
  const Index nb = l.nb;
  const Index per_output = l.per_output;
  for (Index r = 0; r < modes; ++r)
    q.lambda[static_cast<std::size_t>(r)] = cd(theta[2 * r], theta[2 * r + 1]);
  for (Index o = 0; o < outputs; ++o) {
    const Index base = 2 * modes + o * per_output;
    for (Index r = 0; r < modes; ++r)
      q.residue(r, o) = cd(theta[base + 2 * r], theta[base + 2 * r + 1]);
    for (Index b = 0; b < nb; ++b) {
      q.lower(b, o) = theta[base + 2 * modes + 2 * b];
      q.upper(b, o) = theta[base + 2 * modes + 2 * b + 1];
    }
  }
}

/// Whether every pole of θ is physical (positive frequency, damping in
/// (0, kMaxDamping)) and inside the band its mode was found in.
bool physical(const Eigen::VectorXd& theta, Index modes, const ModalParameters& p,
              const std::vector<FitBand>& bands) {
  for (Index r = 0; r < modes; ++r) {
    const cd lambda(theta[2 * r], theta[2 * r + 1]);
    const double omega_n = std::abs(lambda), zeta = -lambda.real() / omega_n;
    const FitBand& band = bands[static_cast<std::size_t>(p.band[static_cast<std::size_t>(r)])];
    if (!(lambda.imag() > 0.0 && zeta > 0.0 && zeta < kMaxDamping &&
          omega_n >= kTwoPi * band.low_hz && omega_n <= kTwoPi * band.high_hz)) {
      return false;
    }
  }
  return true;
}

/// Nonlinear least-squares refinement of poles, residues and residuals
/// together on the output error Σ |w (Ĥ − H)|², w = 1 / |H|, over all bands:
/// the modal-model formulation of the maximum-likelihood estimator of
/// El-Kafafy, De Troyer, Peeters & Guillaume (MSSP 37, 2013), with 1 / |H|
/// standing in for the inverse noise standard deviation, solved by
/// Levenberg–Marquardt (Marquardt's scaling by the Jacobian's column norms; one
/// QR of the Jacobian per iteration, trial steps from its small triangular
/// factor). The LSCF is a
/// linearized equation-error estimator: with noise its poles scatter over
/// the model orders and light or close modes carry a bias the median over the
/// stabilization diagram does not remove; the output error has its minimum at
/// the continuous-time modal model that fits the data best. A step is
/// accepted only if it lowers the cost and keeps every pole physical and
/// inside its band, so the refinement never worsens the fit.
void refine(const Data& data, ModalParameters& p, const Ranges& ranges,
            const std::vector<FitBand>& bands) {
  const Index modes = static_cast<Index>(p.lambda.size());
  const Index outputs = data.h.cols();
  const Index nb = static_cast<Index>(ranges.size());
  const Index per_output = 2 * modes + 2 * nb;
  const Index columns = 2 * modes + outputs * per_output;
  const Index rows = 2 * points_in(ranges) * outputs;
  if (modes == 0 || rows <= columns)
    return;

  const ThetaLayout layout{modes, outputs, nb, per_output, columns};

  std::vector<double> floors(static_cast<std::size_t>(outputs));
  for (Index o = 0; o < outputs; ++o)
    floors[static_cast<std::size_t>(o)] = weight_floor(data, o);
  std::vector<cd> lambda(static_cast<std::size_t>(modes));
  std::vector<cd> a(static_cast<std::size_t>(modes)), c(static_cast<std::size_t>(modes));
  // Weighted residual e (rows) and, when jacobian is given, ∂e/∂θ.
  auto evaluate = [&](const Eigen::VectorXd& theta, Eigen::VectorXd& e, Eigen::MatrixXd* jacobian) {
    for (Index r = 0; r < modes; ++r)
      lambda[static_cast<std::size_t>(r)] = cd(theta[2 * r], theta[2 * r + 1]);
    if (jacobian != nullptr)
      jacobian->setZero();
    Index row = 0;
    for (Index o = 0; o < outputs; ++o) {
      const Index base = 2 * modes + o * per_output;
      for (Index b = 0; b < nb; ++b) {
        const auto [begin, end] = ranges[static_cast<std::size_t>(b)];
        const double lower = theta[base + 2 * modes + 2 * b];
        const double upper = theta[base + 2 * modes + 2 * b + 1];
        for (Index k = begin; k < end; ++k) {
          const double w = weight(data, k, o, floors[static_cast<std::size_t>(o)]);
          const double omega2 = data.omega[k] * data.omega[k];
          const cd iw(0.0, data.omega[k]);
          cd model = -lower / omega2 + upper;
          for (Index r = 0; r < modes; ++r) {
            const std::size_t ri = static_cast<std::size_t>(r);
            const cd res(theta[base + 2 * r], theta[base + 2 * r + 1]);
            a[ri] = 1.0 / (iw - lambda[ri]);
            c[ri] = 1.0 / (iw - std::conj(lambda[ri]));
            model += res * a[ri] + std::conj(res) * c[ri];
          }
          const cd error = w * (model - data.h(k, o));
          e[row] = error.real();
          e[row + 1] = error.imag();
          if (jacobian != nullptr) {
            Eigen::MatrixXd& j = *jacobian;
            for (Index r = 0; r < modes; ++r) {
              const std::size_t ri = static_cast<std::size_t>(r);
              const cd res(theta[base + 2 * r], theta[base + 2 * r + 1]);
              // ∂/∂Re λ and ∂/∂Im λ of R/(iω − λ) + R̄/(iω − λ̄).
              const cd da = res * a[ri] * a[ri], dc = std::conj(res) * c[ri] * c[ri];
              const cd d_sigma = w * (da + dc), d_omega = w * cd(0.0, 1.0) * (da - dc);
              const cd d_re = w * (a[ri] + c[ri]), d_im = w * cd(0.0, 1.0) * (a[ri] - c[ri]);
              j(row, 2 * r) = d_sigma.real();
              j(row + 1, 2 * r) = d_sigma.imag();
              j(row, 2 * r + 1) = d_omega.real();
              j(row + 1, 2 * r + 1) = d_omega.imag();
              j(row, base + 2 * r) = d_re.real();
              j(row + 1, base + 2 * r) = d_re.imag();
              j(row, base + 2 * r + 1) = d_im.real();
              j(row + 1, base + 2 * r + 1) = d_im.imag();
            }
            j(row, base + 2 * modes + 2 * b) = -w / omega2;
            j(row, base + 2 * modes + 2 * b + 1) = w;
          }
          row += 2;
        }
      }
    }
    return e.squaredNorm();
  };

  constexpr int kMaxIterations = 50;
  constexpr double kRelativeDecrease = 1e-12;
  // An RMS relative error of 1e-13 is rounding, far below any measurement:
  // past it the steps only chase round-off (noise-free data).
  const double converged_cost = 1e-26 * static_cast<double>(rows);
  Eigen::VectorXd theta = pack(layout, p);
  Eigen::VectorXd e(rows), trial_e(rows);
  Eigen::MatrixXd jacobian(rows, columns);
  double cost = evaluate(theta, e, &jacobian);
  double mu = 1e-4;
  for (int iteration = 0; iteration < kMaxIterations && cost > converged_cost; ++iteration) {
    // Scaled Jacobian J D⁻¹ = Q T; the damped step solves
    // min ‖T δ̃ + Qᵀe‖² + μ ‖δ̃‖², δ = D⁻¹ δ̃, with only the small T.
    const Eigen::VectorXd scale = jacobian.colwise().norm().transpose().cwiseMax(1e-300);
    jacobian *= scale.cwiseInverse().asDiagonal();
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(jacobian);
    const Eigen::VectorXd qte = (qr.householderQ().transpose() * e).head(columns);
    const Eigen::MatrixXd t = qr.matrixQR().topRows(columns).triangularView<Eigen::Upper>();
    bool accepted = false;
    while (!accepted && mu < 1e10) {
      Eigen::MatrixXd damped(2 * columns, columns);
      damped << t, std::sqrt(mu) * Eigen::MatrixXd::Identity(columns, columns);
      Eigen::VectorXd target = Eigen::VectorXd::Zero(2 * columns);
      target.head(columns) = -qte;
      const Eigen::VectorXd step = damped.householderQr().solve(target).cwiseQuotient(scale);
      const Eigen::VectorXd candidate = theta + step;
      if (step.allFinite() && physical(candidate, modes, p, bands)) {
        const double trial = evaluate(candidate, trial_e, nullptr);
        if (trial < cost) {
          const double decrease = cost - trial;
          theta = candidate;
          cost = trial;
          mu = std::max(mu * 0.1, 1e-12);
          accepted = true;
          if (decrease <= kRelativeDecrease * cost) {
            unpack(layout, theta, p);
            return;
          }
          break;
        }
      }
      mu *= 10.0;
    }
    if (!accepted)
      break;
    cost = evaluate(theta, e, &jacobian);
  }
  unpack(layout, theta, p);
}

// ---------------------------------------------------------------- quality

/// A mode's report: frequency, damping, modal constants, driving-point
/// stiffness and mass, and its quality over the half-power band fn(1 ± ζ)
/// (widened to 3 points) against the fitted FRFs.
FittedMode describe(const Data& data, const ModalParameters& p, const Eigen::MatrixXcd& fitted,
                    const std::vector<FitBand>& bands, Index r) {
  const cd lambda = p.lambda[static_cast<std::size_t>(r)];
  FittedMode mode;
  const double omega_n = std::abs(lambda);
  mode.natural_frequency_hz = omega_n / kTwoPi;
  mode.damping_ratio = -lambda.real() / omega_n;
  for (Index o = 0; o < data.h.cols(); ++o) {
    // R/(iω − λ) + R̄/(iω − λ̄) = A/(ωn² − ω² + 2iζωnω) when A = 2iωd R.
    mode.modal_constant.push_back(cd(0.0, 2.0 * lambda.imag()) * p.residue(r, o));
  }
  if (data.driving_point >= 0) {
    const double a = mode.modal_constant[static_cast<std::size_t>(data.driving_point)].real();
    if (a > 0.0) {
      mode.mass_kg = 1.0 / a;
      mode.stiffness_n_per_m = omega_n * omega_n / a;
    }
  }
  const FitBand& band = bands[static_cast<std::size_t>(p.band[static_cast<std::size_t>(r)])];
  mode.band_low_hz = band.low_hz;
  mode.band_high_hz = band.high_hz;
  mode.stable_orders = p.stable_orders[static_cast<std::size_t>(r)];

  const double f = mode.natural_frequency_hz, zeta = mode.damping_ratio;
  auto [begin, end] = index_range(data, f * (1.0 - zeta), f * (1.0 + zeta));
  const Index n = data.frequency_hz.size();
  while (end - begin < std::min<Index>(3, n)) {
    const bool left = begin > 0, right = end < n;
    if (left && (!right || f - data.frequency_hz[begin - 1] <= data.frequency_hz[end] - f)) {
      --begin;
    } else {
      ++end;
    }
  }
  double residual = 0.0, measured = 0.0, model = 0.0;
  cd cross(0.0, 0.0);
  for (Index o = 0; o < data.h.cols(); ++o) {
    for (Index k = begin; k < end; ++k) {
      const cd h = data.h(k, o), g = fitted(k, o);
      residual += std::norm(h - g);
      measured += std::norm(h);
      model += std::norm(g);
      cross += std::conj(h) * g;
    }
  }
  const Index reference = std::max(0, data.driving_point);
  const cd res = p.residue(r, reference);
  double own = 0.0, total = 0.0;
  for (Index k = begin; k < end; ++k) {
    const cd iw(0.0, data.omega[k]);
    own += std::norm(res / (iw - lambda) + std::conj(res) / (iw - std::conj(lambda)));
    total += std::norm(fitted(k, reference));
  }
  mode.fit_error = measured > 0.0 ? std::sqrt(residual / measured) : 0.0;
  mode.assurance = measured > 0.0 && model > 0.0 ? std::norm(cross) / (measured * model) : 0.0;
  mode.contribution = total > 0.0 ? std::sqrt(own / total) : 0.0;
  return mode;
}

/// A computational mode: its own term is negligible in its half-power band
/// (below 1 % of the fitted FRF or 3 times the local fit error: it fits noise
/// or bends the model around the residual effects near a band edge), or its
/// driving-point modal constant φ_p² is not positive.
bool computational(const Data& data, const FittedMode& mode) {
  if (mode.contribution < kMinContribution ||
      mode.contribution < kContributionOverError * mode.fit_error) {
    return true;
  }
  return data.driving_point >= 0 &&
         !(mode.modal_constant[static_cast<std::size_t>(data.driving_point)].real() > 0.0);
}

/// Fits the residues, reports every mode and removes computational ones,
/// refitting until none is left. Returns the modes kept and the fitted FRFs.
std::vector<FittedMode> settle(const Data& data, ModalParameters& p, const Ranges& ranges,
                               const std::vector<FitBand>& bands, bool fit_first,
                               Eigen::MatrixXcd& fitted, std::vector<FittedMode>& rejected) {
  for (bool fit = fit_first;; fit = true) {
    if (fit)
      fit_residues(data, p, ranges);
    fitted = model_frfs(data, p, ranges);
    std::vector<FittedMode> modes;
    ModalParameters kept = p;
    kept.lambda.clear();
    kept.band.clear();
    kept.stable_orders.clear();
    for (Index r = 0; r < static_cast<Index>(p.lambda.size()); ++r) {
      FittedMode mode = describe(data, p, fitted, bands, r);
      if (computational(data, mode)) {
        rejected.push_back(std::move(mode));
        continue;
      }
      const std::size_t ri = static_cast<std::size_t>(r);
      kept.lambda.push_back(p.lambda[ri]);
      kept.band.push_back(p.band[ri]);
      kept.stable_orders.push_back(p.stable_orders[ri]);
      modes.push_back(std::move(mode));
    }
    if (kept.lambda.size() == p.lambda.size())
      return modes;
    for (int b : p.band) {
      if (std::find(kept.band.begin(), kept.band.end(), b) == kept.band.end()) {
        throw NumericalError("modal fit: no physical mode in " +
                             band_name(b, bands[static_cast<std::size_t>(b)]) +
                             ": its stable poles were all rejected as computational (negligible "
                             "in their half-power bands or a non-positive driving-point modal "
                             "constant)");
      }
    }
    p = std::move(kept);
  }
}

void check_options(const ModalFitOptions& options) {
  if (options.max_order < 2)
    throw std::invalid_argument("modal fit: max_order must be ≥ 2");
  if (!(options.frequency_stability > 0.0) || !(options.damping_stability > 0.0)) {
    throw std::invalid_argument("modal fit: stability tolerances must be positive");
  }
  if (options.min_stable_orders < 1) {
    throw std::invalid_argument("modal fit: min_stable_orders must be ≥ 1");
  }
}

}  // namespace

ModalFit fit_modes(const std::vector<Frf>& frfs, const ModalFitOptions& options) {
  check_options(options);
  const Data data = prepare(frfs);
  const Index n = data.frequency_hz.size();
  if (n < 3)
    throw std::invalid_argument("modal fit: fewer than 3 frequencies above 0 Hz");
  const double data_low = data.frequency_hz[0], data_high = data.frequency_hz[n - 1];

  ModalFit fit;
  fit.bands_used = options.bands.empty() ? automatic_bands(data) : options.bands;
  const int band_count = static_cast<int>(fit.bands_used.size());
  const double slack = 1e-9 * data_high;
  Ranges ranges;  // residual-fit partition: [low, high) per band, the last one closed
  ModalParameters params;
  for (int b = 0; b < band_count; ++b) {
    FitBand& band = fit.bands_used[static_cast<std::size_t>(b)];
    const std::string name = band_name(b, band);
    if (!std::isfinite(band.low_hz) || !std::isfinite(band.high_hz) ||
        !(band.high_hz > band.low_hz)) {
      throw std::invalid_argument("modal fit: " + name + " needs finite low < high");
    }
    if (band.low_hz < data_low - slack || band.high_hz > data_high + slack) {
      throw std::invalid_argument("modal fit: " + name + " lies outside the data (" + hz(data_low) +
                                  " to " + hz(data_high) + ")");
    }
    if (b > 0 && band.low_hz < fit.bands_used[static_cast<std::size_t>(b - 1)].high_hz - slack) {
      throw std::invalid_argument("modal fit: " + name +
                                  " overlaps the previous band (bands must increase)");
    }
    if (band.max_order < 0 || band.max_order == 1) {
      throw std::invalid_argument("modal fit: " + name + " max_order must be 0 or ≥ 2");
    }
    const auto [begin, end] = index_range(data, band.low_hz - slack, band.high_hz + slack);
    const Index points = end - begin;
    // Each complex point gives two real equations for n + 1 numerator
    // coefficients per FRF; n + 1 points keep the reduced normal matrix regular.
    int order = band.max_order > 0 ? band.max_order : options.max_order;
    if (points < order + 1) {
      if (band.max_order > 0 || points < 3) {
        throw std::invalid_argument("modal fit: " + name + " holds " + std::to_string(points) +
                                    " points, model order " + std::to_string(order) + " needs " +
                                    std::to_string(order + 1));
      }
      order = static_cast<int>(points - 1);
    }
    band.max_order = order;
    const auto poles = lscf_poles(data, begin, end, band.high_hz, order);
    const std::vector<SelectedPole> found = stabilize(poles, b, band, options, fit.stabilization);
    if (found.empty()) {
      throw NumericalError("modal fit: no pole is stable over " +
                           std::to_string(options.min_stable_orders) + " orders in " + name);
    }
    for (const SelectedPole& pole : found) {
      params.lambda.push_back(pole.pole.lambda());
      params.band.push_back(b);
      params.stable_orders.push_back(pole.stable_orders);
    }
    // Where bands touch, the shared point belongs to the lower band.
    ranges.emplace_back(std::max(begin, ranges.empty() ? Index{0} : ranges.back().second), end);
  }

  Eigen::MatrixXcd fitted;
  fit.modes = settle(data, params, ranges, fit.bands_used, true, fitted, fit.rejected);
  if (options.refine) {
    refine(data, params, ranges, fit.bands_used);
    fit.modes = settle(data, params, ranges, fit.bands_used, false, fitted, fit.rejected);
  }
  std::sort(fit.modes.begin(), fit.modes.end(), [](const FittedMode& a, const FittedMode& b) {
    return a.natural_frequency_hz < b.natural_frequency_hz;
  });

  double residual = 0.0, measured = 0.0;
  for (const auto& [begin, end] : ranges) {
    residual += (data.h.middleRows(begin, end - begin) - fitted.middleRows(begin, end - begin))
                    .squaredNorm();
    measured += data.h.middleRows(begin, end - begin).squaredNorm();
  }
  fit.overall_error = measured > 0.0 ? std::sqrt(residual / measured) : 0.0;

  for (std::size_t i = 0; i < frfs.size(); ++i) {
    Frf out;
    out.kind = frfs[i].kind;
    out.response_axis = frfs[i].response_axis;
    out.reference_axis = frfs[i].reference_axis;
    out.label = frfs[i].label.empty() ? "fit" : frfs[i].label + " fit";
    out.frequency_hz.assign(data.frequency_hz.data(), data.frequency_hz.data() + n);
    out.value.resize(static_cast<std::size_t>(n));
    for (Index k = 0; k < n; ++k) {
      const cd iw(0.0, data.omega[k]);
      const cd h = fitted(k, static_cast<Index>(i));
      out.value[static_cast<std::size_t>(k)] = out.kind == FrfKind::receptance ? h
                                               : out.kind == FrfKind::mobility ? h * iw
                                                                               : h * iw * iw;
    }
    fit.fitted.push_back(std::move(out));
  }
  return fit;
}

}  // namespace robomill::dynamics
