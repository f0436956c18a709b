// The fast Floquet solver (free-flight runs collapsed into powers of e^{A0 h},
// delayed terms added to identity columns, fixed-size kernels, the reduced
// Van Loan generator for SDM) against the textbook construction: the full
// augmented state z_k = [x_k; η_{k−1} … η_{k−m} (; η'_{k−1})], one dense
// transition matrix per step, Ψ their product, all multipliers by a dense
// eigensolver. Both are the same discretization (Insperger & Stépán 2004 for
// SDM, Ding et al. 2010 for FDM/FDM2), so the spectral radii agree to
// round-off; the tolerance 1e-8 relative leaves room for the eigenvalue
// sensitivity of the non-normal Ψ (the two products round differently).

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <numbers>
#include <unsupported/Eigen/MatrixFunctions>

#include "benchmark_1dof.hpp"
#include "robomill/stability/floquet.hpp"

namespace test_floquet_reference_cpp {

namespace {

using namespace robomill;
using stability::FloquetMethod;

// [e^{Ah}, ∫e^{A(h−s)} ds, ∫e^{A(h−s)} s ds, ∫e^{A(h−s)} s² ds] (Van Loan).
struct Integrals {
  Eigen::MatrixXd exponential, f1, f2, f3;
};
Integrals integrals(const Eigen::MatrixXd& a, double h) {
  const Eigen::Index d = a.rows();
  Eigen::MatrixXd generator = Eigen::MatrixXd::Zero(4 * d, 4 * d);
  generator.topLeftCorner(d, d) = a;
  for (int b = 0; b < 3; ++b)
    generator.block(b * d, (b + 1) * d, d, d).setIdentity();
  const Eigen::MatrixXd e = (generator * h).exp();
  return {e.block(0, 0, d, d), e.block(0, d, d, d), e.block(0, 2 * d, d, d),
          2.0 * e.block(0, 3 * d, d, d)};
}

double reference_radius(FloquetMethod method, const Eigen::VectorXd& omega,
                        const Eigen::VectorXd& zeta, int m, double delay_s,
                        const stability::CouplingSamples& p, double scale,
                        const stability::CouplingSamples* c, double c_scale) {
  const int n = static_cast<int>(omega.size());
  const bool fdm2 = method == FloquetMethod::fdm2;
  const int history = 2 * n;           // η_{k−1−j} at rows history + j n
  const int velocity = 2 * n + m * n;  // η'_{k−1} (FDM2)
  const int size = velocity + (fdm2 ? n : 0);
  const double h = delay_s / m;
  Eigen::MatrixXd a0 = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  a0.topRightCorner(n, n).setIdentity();
  a0.bottomLeftCorner(n, n).diagonal() = -omega.array().square();
  a0.bottomRightCorner(n, n).diagonal() = -2.0 * zeta.array() * omega.array();
  const Integrals base = integrals(a0, h);

  Eigen::MatrixXd psi = Eigen::MatrixXd::Identity(size, size);
  for (int k = 0; k < m; ++k) {
    // Rows of x_{k+1} as a function of z_k.
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(2 * n, size);
    Eigen::MatrixXd lhs = Eigen::MatrixXd::Identity(2 * n, 2 * n);
    // Column of η_{k−m} and of η_{k+1−m} in z_k.
    const int old_column = history + (m - 1) * n;
    const int new_column = m > 1 ? history + (m - 2) * n : 0;
    auto sample = [&](const stability::CouplingSamples& s, int i) -> Eigen::MatrixXd {
      return s.nodes[static_cast<std::size_t>(i)];
    };
    if (method == FloquetMethod::sdm) {
      const Eigen::MatrixXd mean = scale * p.means[static_cast<std::size_t>(k)];
      Eigen::MatrixXd a = a0;
      a.bottomLeftCorner(n, n) += mean;
      if (c)
        a.bottomRightCorner(n, n) -= c_scale * c->means[static_cast<std::size_t>(k)];
      const Integrals step = integrals(a, h);
      rhs.leftCols(2 * n) = step.exponential;
      rhs.middleCols(old_column, n) -= (step.f1 - step.f2 / h).rightCols(n) * mean;
      rhs.middleCols(new_column, n) -= (step.f2 / h).rightCols(n) * mean;
    } else {
      Eigen::MatrixXd w_prev, w_now, w_next;
      const Eigen::MatrixXd d_now = (base.f1 - base.f2 / h).rightCols(n);
      const Eigen::MatrixXd d_next = (base.f2 / h).rightCols(n);
      if (fdm2) {
        w_prev = (base.f3 / (h * h) - base.f2 / (2.0 * h)).rightCols(n);
        w_now = (base.f1 - 2.0 * base.f3 / (h * h)).rightCols(n);
        w_next = (base.f3 / (h * h) + base.f2 / (2.0 * h)).rightCols(n);
      } else {
        w_now = d_now;
        w_next = d_next;
      }
      const Eigen::MatrixXd p_now = scale * sample(p, k), p_next = scale * sample(p, k + 1);
      rhs.leftCols(2 * n) = base.exponential;
      rhs.leftCols(n) += w_now * p_now;
      if (c)
        rhs.middleCols(n, n) -= c_scale * w_now * sample(*c, k);
      if (fdm2) {
        const int previous = (k + m - 1) % m;
        rhs.middleCols(history, n) += scale * w_prev * sample(p, previous);
        if (c)
          rhs.middleCols(velocity, n) -= c_scale * w_prev * sample(*c, previous);
      }
      rhs.middleCols(old_column, n) -= d_now * p_now;
      rhs.middleCols(new_column, n) -= d_next * p_next;
      lhs.leftCols(n) -= w_next * p_next;
      if (c)
        lhs.rightCols(n) += c_scale * w_next * sample(*c, k + 1);
    }
    Eigen::MatrixXd transition = Eigen::MatrixXd::Zero(size, size);
    transition.topRows(2 * n) = lhs.partialPivLu().solve(rhs);
    // Shift: η_k (top of x_k) enters the history; η'_k becomes the previous velocity.
    transition.block(history, 0, n, n).setIdentity();
    for (int j = 1; j < m; ++j)
      transition.block(history + j * n, history + (j - 1) * n, n, n).setIdentity();
    if (fdm2)
      transition.block(velocity, n, n, n).setIdentity();
    psi = transition * psi;
  }
  Eigen::EigenSolver<Eigen::MatrixXd> eigen(psi, false);
  return eigen.eigenvalues().cwiseAbs().maxCoeff();
}

struct Case {
  int modes;
  double radial_immersion;
  int steps;
};

// 1-4 modes use the fixed-size kernels, 5 the dynamic one; m = 1 and 2 are
// the edge cases of the delayed reads; a/D = 0.05 has long free-flight runs,
// a slot none.
TEST(FloquetReference, FastSolverMatchesTheDenseStepByStepProduct) {
  const std::vector<Case> cases = {{1, 0.05, 40}, {1, 1.0, 20},  {2, 0.05, 30}, {2, 0.5, 12},
                                   {3, 0.3, 16},  {4, 0.05, 20}, {5, 0.2, 10},  {1, 0.05, 1},
                                   {1, 0.5, 2},   {2, 1.0, 3}};
  int compared = 0;
  for (const Case& c : cases) {
    const auto model = test::benchmark_modes(c.modes, c.radial_immersion);
    const auto coupling = model.sample(1.0, c.steps);
    const auto damping = model.sample_damping(1.0, c.steps, 0.3);
    const Eigen::VectorXd omega = model.modes().natural_rad_s();
    const Eigen::VectorXd zeta = model.modes().damping_ratios();
    for (FloquetMethod method : {FloquetMethod::sdm, FloquetMethod::fdm, FloquetMethod::fdm2}) {
      stability::FloquetSolver solver(method, {omega, zeta}, c.steps);
      for (const double rpm : {6000.0, 14300.0}) {
        const double delay = 60.0 / (model.tool().teeth() * rpm);
        solver.set_delay(delay);
        for (const double depth : {0.3e-3, 2e-3}) {
          for (const bool with_damping : {false, true}) {
            // −C_eq' of 000 Eq 19 at this speed (K_sp 1.5e14, w 40 µm).
            const double c_scale =
                -1.5e14 * 40e-6 * 40e-6 / (4.0 * 5e-3 * rpm * std::numbers::pi / 30.0) * depth;
            const auto* d = with_damping ? &damping : nullptr;
            const double fast = solver.solve(coupling, depth, d, c_scale).spectral_radius;
            const double reference =
                reference_radius(method, omega, zeta, c.steps, delay, coupling, depth, d, c_scale);
            EXPECT_NEAR(fast / reference, 1.0, 1e-8)
                << c.modes << " modes, a/D " << c.radial_immersion << ", m " << c.steps
                << ", method " << static_cast<int>(method) << ", " << rpm << " rpm, " << depth * 1e3
                << " mm, damping " << with_damping;
            ++compared;
          }
        }
      }
    }
  }
  EXPECT_EQ(compared, 10 * 3 * 2 * 2 * 2);
}

}  // namespace

}  // namespace test_floquet_reference_cpp
