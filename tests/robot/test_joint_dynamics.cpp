// Joint-space dynamics (004 §3.1 Eq 1-2): M(q) against the two-link closed
// form and a hand-built Σ m Jcᵀ Jc + Jωᵀ I Jω, 004's natural frequencies
// against an independent eigen-solve, tool-tip receptance (static limit,
// modal superposition), the ModalModel handed to the stability engine.

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <complex>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <numbers>
#include <stdexcept>

#include "example_robots.hpp"
#include "robomill/robot/joint_dynamics.hpp"
#include "robomill/robot/kinematics.hpp"
#include "robomill/robot/robot_model.hpp"
#include "robomill/robot/stiffness.hpp"

namespace test_joint_dynamics_cpp {

namespace {

using namespace robomill::robot;
using namespace robomill::test;

// Two-link planar arm (Spong, Robot Modeling and Control, §7.4.1):
// M11 = m1 lc1² + m2(l1² + lc2² + 2 l1 lc2 cos q2) + I1 + I2,
// M12 = m2(lc2² + l1 lc2 cos q2) + I2, M22 = m2 lc2² + I2 (I about z at c.o.m.).
struct TwoLink {
  double l1 = 0.9, l2 = 0.7, lc1 = 0.4, lc2 = 0.3, m1 = 12.0, m2 = 7.0, i1 = 0.4, i2 = 0.25;
  Eigen::Matrix2d closed_form(double q2) const {
    const double c2 = std::cos(q2);
    Eigen::Matrix2d m;
    m(0, 0) = m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + 2 * l1 * lc2 * c2) + i1 + i2;
    m(0, 1) = m(1, 0) = m2 * (lc2 * lc2 + l1 * lc2 * c2) + i2;
    m(1, 1) = m2 * lc2 * lc2 + i2;
    return m;
  }
  RobotDescription description(DhConvention convention) const {
    RobotDescription d;
    DhTable dh;
    dh.convention = convention;
    if (convention == DhConvention::standard) {
      // Frame i at the distal end of link i, x along the link.
      dh.rows = {{l1, 0, 0, 0}, {l2, 0, 0, 0}};
      dh.links = {link(m1, {lc1 - l1, 0, 0}, {0.05, 0.3, i1}),
                  link(m2, {lc2 - l2, 0, 0}, {0.02, 0.2, i2})};
    } else {
      // Frame i at joint i.
      dh.rows = {{0, 0, 0, 0}, {l1, 0, 0, 0}};
      dh.links = {link(m1, {lc1, 0, 0}, {0.05, 0.3, i1}), link(m2, {lc2, 0, 0}, {0.02, 0.2, i2})};
      d.flange_to_tool.translation() = Eigen::Vector3d(l2, 0, 0);
    }
    d.dh = dh;
    d.joints = {{-kPi, kPi, 1e5, -1.0}, {-kPi, kPi, 1e5, -1.0}};
    return d;
  }
};

TEST(MassMatrix, TwoLinkArmMatchesClosedForm) {
  const TwoLink arm;
  for (const DhConvention conv : {DhConvention::standard, DhConvention::modified}) {
    const RobotModel m(arm.description(conv));
    for (const double q2 : {0.0, 0.7, -2.1, kPi / 2}) {
      const Eigen::MatrixXd kdl = mass_matrix(m, Eigen::Vector2d(0.37, q2));
      const Eigen::Matrix2d ref = arm.closed_form(q2);
      for (int r = 0; r < 2; ++r)
        for (int c = 0; c < 2; ++c)
          EXPECT_NEAR(kdl(r, c), ref(r, c), 1e-10 * std::abs(ref(r, c))) << r << c << " q2 " << q2;
    }
  }
}

// M = Σ_i m_i Jc_iᵀ Jc_i + Jω_iᵀ R_i I_i R_iᵀ Jω_i from the links' frames (KDL
// forward kinematics per segment) and the tool Jacobian's columns: the linear
// velocity of link i's c.o.m. per joint j ≤ i is z_j × (p_c − o_j) =
// Jv_tip,j + z_j × (p_c − p_tip). Independent of KDL's ChainDynParam.
Eigen::MatrixXd hand_mass_matrix(const RobotModel& m, const Eigen::VectorXd& q) {
  const int n = m.dof();
  const Eigen::Matrix<double, 6, Eigen::Dynamic> j = tool_jacobian(m, q);
  const Eigen::Vector3d p_tip = tool_pose(m, q).translation();
  KDL::ChainFkSolverPos_recursive fk(m.chain());
  KDL::JntArray jq(static_cast<unsigned>(n));
  jq.data = q;
  Eigen::MatrixXd mm = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    KDL::Frame f;
    fk.JntToCart(jq, f, i + 1);
    Eigen::Matrix3d r;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        r(a, b) = f.M(a, b);
    const LinkInertia& li = m.description().dh->links[static_cast<std::size_t>(i)];
    const Eigen::Vector3d p_c =
        Eigen::Vector3d(f.p.x(), f.p.y(), f.p.z()) + r * li.center_of_mass_m;
    Eigen::MatrixXd jc = Eigen::MatrixXd::Zero(3, n), jw = Eigen::MatrixXd::Zero(3, n);
    for (int c = 0; c <= i; ++c) {
      const Eigen::Vector3d z = j.col(c).tail<3>();
      jc.col(c) = j.col(c).head<3>() + z.cross(p_c - p_tip);
      jw.col(c) = z;
    }
    mm += li.mass_kg * jc.transpose() * jc +
          jw.transpose() * (r * li.inertia_kg_m2 * r.transpose()) * jw;
  }
  return mm;
}

const Eigen::Vector3d kPostures004[] = {
    {0.0, 0.0, 0.0}, {0.0, 0.5, -0.6}, {0.8, -0.9, 1.0}, {-1.5, 1.2, -1.0}, {2.0, 0.3, 0.9}};

TEST(RobotModes, Frequencies004MatchIndependentEigenSolve) {
  const RobotModel m(robot_004());
  Eigen::VectorXd previous;
  for (const Eigen::Vector3d& q : kPostures004) {
    const Eigen::MatrixXd mk = mass_matrix(m, q);
    const Eigen::MatrixXd mh = hand_mass_matrix(m, q);
    EXPECT_LT((mk - mh).norm(), 1e-12 * mh.norm());
    // det(K − ω² M) = 0 as the eigenvalues of M⁻¹ K (non-symmetric solver).
    const Eigen::MatrixXd a = mh.inverse() * joint_stiffness_matrix(m);
    const Eigen::EigenSolver<Eigen::MatrixXd> es(a);
    std::vector<double> f_ref;
    for (int i = 0; i < 3; ++i) {
      EXPECT_LT(std::abs(es.eigenvalues()[i].imag()), 1e-9 * std::abs(es.eigenvalues()[i].real()));
      f_ref.push_back(std::sqrt(es.eigenvalues()[i].real()) / (2 * kPi));
    }
    std::sort(f_ref.begin(), f_ref.end());
    const RobotModes modes = robot_modes(m, q);
    for (int i = 0; i < 3; ++i) {
      EXPECT_GT(modes.natural_frequencies_hz[i], 0.0);
      EXPECT_NEAR(modes.natural_frequencies_hz[i], f_ref[static_cast<std::size_t>(i)],
                  1e-9 * f_ref[static_cast<std::size_t>(i)]);
      EXPECT_NEAR(modes.damping_ratios[i], 0.06, 1e-12);
    }
    // Mass normalization and K-orthogonality.
    const Eigen::MatrixXd& phi = modes.joint_shapes;
    EXPECT_LT((phi.transpose() * mk * phi - Eigen::Matrix3d::Identity()).norm(), 1e-10);
    const Eigen::Vector3d w2 = modes.natural_rad_s.cwiseAbs2();
    EXPECT_LT((phi.transpose() * joint_stiffness_matrix(m) * phi - Eigen::MatrixXd(w2.asDiagonal()))
                  .norm(),
              1e-9 * w2.maxCoeff());
    EXPECT_LT((modes.tip_shapes - tool_jacobian(m, q).topRows<3>() * phi).norm(), 1e-14);
    if (previous.size() == 3) {
      EXPECT_GT((modes.natural_frequencies_hz - previous).norm(), 0.1);  // posture-dependent
    }
    previous = modes.natural_frequencies_hz;
    std::printf("[validation] 004 robot q = [%.2f, %.2f, %.2f] rad: fn = %.3f, %.3f, %.3f Hz\n",
                q[0], q[1], q[2], modes.natural_frequencies_hz[0], modes.natural_frequencies_hz[1],
                modes.natural_frequencies_hz[2]);
  }
}

TEST(RobotModes, FrequencyRangeOver004Workspace) {
  // 004 Fig 7d: natural frequencies near 66.7 Hz (twice the 33.3 Hz tooth
  // frequency) at some workpiece placements. Report each mode's range over a
  // grid of the joint ranges (q1 does not change M: the first axis is vertical).
  const RobotModel m(robot_004());
  // Two readings of joint 3's zero: a straight arm (this file's robot_004)
  // and the forearm perpendicular to the upper arm (the 004 example's, which
  // makes Table 2's poses reachable; docs/planning.md).
  RobotDescription bent = robot_004();
  bent.dh->rows[2].theta_offset_rad = -kPi / 2;
  const RobotModel m_bent(bent);
  for (const RobotModel* model : {&m, &m_bent}) {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = Eigen::Vector3d::Zero();
    for (int a = 0; a <= 12; ++a) {
      for (int b = 0; b <= 12; ++b) {
        const Eigen::Vector3d q(0.0, -kPi / 2 + kPi * a / 12, -kPi / 3 + 2 * kPi / 3 * b / 12);
        const Eigen::VectorXd f = robot_modes(*model, q).natural_frequencies_hz;
        lo = lo.cwiseMin(f);
        hi = hi.cwiseMax(f);
      }
    }
    EXPECT_GT(lo.minCoeff(), 0.0);
    std::printf(
        "[validation] 004 robot (q3 = 0 %s) over q2 ∈ [-π/2, π/2], q3 ∈ [-π/3, π/3]: mode 1 "
        "%.2f–%.2f Hz, mode 2 %.2f–%.2f Hz, mode 3 %.2f–%.2f Hz (004 Fig 7d: near 66.7 Hz at "
        "some placements)\n",
        model == &m ? "straight arm" : "forearm ⊥ upper arm", lo[0], hi[0], lo[1], hi[1], lo[2],
        hi[2]);
  }
  // Invariance in q1: the mass matrix does not depend on the first joint.
  EXPECT_LT((robot_modes(m, Eigen::Vector3d(1.3, 0.4, 0.5)).natural_frequencies_hz -
             robot_modes(m, Eigen::Vector3d(-0.4, 0.4, 0.5)).natural_frequencies_hz)
                .norm(),
            1e-9);
}

TEST(Receptance, StaticLimitIsTranslationalCompliance) {
  const RobotModel m(robot_004());
  const Eigen::Vector3d q(0.8, -0.9, 1.0);
  const Eigen::Matrix3d c = translational_compliance(m, q);
  const Eigen::Matrix3cd h0 = tool_tip_receptance(m, q, 0.0);
  EXPECT_LT((h0.real() - c).norm(), 1e-12 * c.norm());
  EXPECT_LT(h0.imag().norm(), 1e-15 * c.norm());
  // ω → 0: the deviation is first order in ω, about 2ζω/ω₁ ≈ 4e-9 here.
  const Eigen::Matrix3cd h_small = tool_tip_receptance(m, q, 1e-6);
  EXPECT_LT((h_small - c.cast<std::complex<double>>()).norm(), 1e-6 * c.norm());
}

TEST(Receptance, EqualsModalSuperpositionWithModalDamping) {
  const RobotModel m(robot_004());
  const Eigen::Vector3d q(-1.5, 1.2, -1.0);
  const RobotModes modes = robot_modes(m, q);
  for (const double ratio : {0.3, 1.0, 1.7, 2.9}) {
    const double w = ratio * modes.natural_rad_s[1];
    Eigen::Matrix3cd sum = Eigen::Matrix3cd::Zero();
    for (int i = 0; i < 3; ++i) {
      const double wi = modes.natural_rad_s[i];
      const std::complex<double> den(wi * wi - w * w, 2.0 * 0.06 * wi * w);
      const Eigen::Vector3d u = modes.tip_shapes.col(i);
      sum += (u * u.transpose()).cast<std::complex<double>>() / den;
    }
    const Eigen::Matrix3cd h = tool_tip_receptance(m, q, w);
    EXPECT_LT((h - sum).norm(), 1e-9 * sum.norm()) << "ω/ω2 = " << ratio;
    EXPECT_LT((h - h.transpose()).norm(), 1e-12 * h.norm());  // reciprocity
  }
}

TEST(Receptance, ModalModelInToolFrameMatchesRotatedReceptance) {
  const RobotModel m(robot_004());
  const Eigen::Vector3d q(0.8, -0.9, 1.0);
  // Tool frame: x (feed) along cell y, z (tool axis) along cell z.
  const Eigen::Matrix3d cell_to_tool =
      Eigen::AngleAxisd(-kPi / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const robomill::dynamics::ModalModel mm = tool_tip_modal_model(m, q, cell_to_tool);
  ASSERT_EQ(mm.size(), 3);
  const RobotModes modes = robot_modes(m, q);
  for (const double w : {50.0, modes.natural_rad_s[0], 900.0}) {
    const Eigen::Matrix3cd expected = cell_to_tool.cast<std::complex<double>>() *
                                      tool_tip_receptance(m, q, w) *
                                      cell_to_tool.transpose().cast<std::complex<double>>();
    EXPECT_LT((mm.receptance(w) - expected).norm(), 1e-9 * expected.norm());
  }
  const auto params = directional_modal_parameters(m, q, cell_to_tool);
  ASSERT_FALSE(params.empty());
  for (const DirectionalModalParameters& p : params) {
    const double wn = 2 * kPi * p.natural_frequency_hz;
    EXPECT_NEAR(p.stiffness_n_per_m / p.mass_kg, wn * wn, 1e-9 * wn * wn);
    const double phi_d = mm.modes()[static_cast<std::size_t>(p.mode)].shape[p.axis];
    EXPECT_NEAR(p.mass_kg, 1.0 / (phi_d * phi_d), 1e-9 * p.mass_kg);
    EXPECT_NEAR(p.damping_ratio, 0.06, 1e-12);
  }
  EXPECT_THROW(tool_tip_modal_model(m, q, 2.0 * Eigen::Matrix3d::Identity()),
               std::invalid_argument);
}

TEST(Damping, ExplicitMixedAndMissing) {
  RobotDescription d = robot_004();
  d.joints[0].damping_nms_per_rad = 500.0;  // explicit on joint 1, modal on 2 and 3
  const RobotModel mixed(d);
  const Eigen::Vector3d q(0.8, -0.9, 1.0);
  const Eigen::MatrixXd c = joint_damping_matrix(mixed, q);
  EXPECT_DOUBLE_EQ(c(0, 0), 500.0);
  EXPECT_EQ(c(0, 1), 0.0);
  EXPECT_EQ(c(2, 0), 0.0);
  const Eigen::MatrixXd c_modal = joint_damping_matrix(RobotModel(robot_004()), q);
  EXPECT_LT((c.bottomRightCorner<2, 2>() - c_modal.bottomRightCorner<2, 2>()).norm(),
            1e-12 * c_modal.norm());
  // Receptance with non-proportional damping: finite and reciprocal.
  const RobotModes modes = robot_modes(mixed, q);
  const Eigen::Matrix3cd h = tool_tip_receptance(mixed, q, modes.natural_rad_s[0]);
  EXPECT_TRUE(h.allFinite());
  EXPECT_LT((h - h.transpose()).norm(), 1e-12 * h.norm());

  // No damping at all: the stability engine's model cannot be built.
  d = robot_004();
  d.modal_damping_ratio = 0.0;
  const RobotModel undamped(d);
  EXPECT_THROW(tool_tip_modal_model(undamped, q, Eigen::Matrix3d::Identity()),
               std::invalid_argument);
  // A massless robot has no modes.
  d = robot_004();
  d.dh->links.clear();
  EXPECT_THROW(robot_modes(RobotModel(d), q), std::invalid_argument);
}

}  // namespace

}  // namespace test_joint_dynamics_cpp
