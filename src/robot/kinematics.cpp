#include "robomill/robot/kinematics.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace robomill::robot {
namespace {

void check_q(const RobotModel& model, const Eigen::VectorXd& q, const char* what) {
  if (q.size() != model.dof()) {
    throw std::invalid_argument(std::string(what) + ": expected " + std::to_string(model.dof()) +
                                " joint values, got " + std::to_string(q.size()));
  }
  if (!q.allFinite())
    throw std::invalid_argument(std::string(what) + ": joint values must be finite");
}

Eigen::Isometry3d to_eigen(const KDL::Frame& f) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      t.linear()(r, c) = f.M(r, c);
    t.translation()[r] = f.p[r];
  }
  return t;
}

KDL::JntArray to_kdl_joints(const Eigen::VectorXd& q) {
  KDL::JntArray j(static_cast<unsigned>(q.size()));
  j.data = q;
  return j;
}

Eigen::VectorXd clamp_to_limits(const RobotModel& model, Eigen::VectorXd q) {
  for (int i = 0; i < q.size(); ++i) {
    const JointProperties& j = model.joints()[static_cast<std::size_t>(i)];
    q[i] = std::clamp(q[i], j.lower_rad, j.upper_rad);
  }
  return q;
}

// Rotation vector taking `from` to `to` (both cell frame), i.e. the angle-axis
// of to · fromᵀ: the first-order orientation error the angular rows of the
// geometric Jacobian map onto.
Eigen::Vector3d rotation_error(const Eigen::Matrix3d& to, const Eigen::Matrix3d& from) {
  const Eigen::AngleAxisd aa(to * from.transpose());
  return aa.angle() * aa.axis();
}

struct Attempt {
  Eigen::VectorXd q;
  double position_residual_m = std::numeric_limits<double>::infinity();
  double orientation_residual_rad = std::numeric_limits<double>::infinity();
  double cost = std::numeric_limits<double>::infinity();
  int iterations = 0;
  bool converged = false;
};

class IkProblem {
 public:
  IkProblem(const RobotModel& model, const Eigen::Isometry3d& target, const IkOptions& opt)
      : model_(model), target_(target), opt_(opt), rows_(opt.position_only ? 3 : 6) {}

  // Weighted residual e (position; orientation × weight) at q.
  Eigen::VectorXd residual(const Eigen::VectorXd& q, double& pos_m, double& ori_rad) const {
    const Eigen::Isometry3d t = tool_pose(model_, q);
    Eigen::VectorXd e(rows_);
    e.head<3>() = target_.translation() - t.translation();
    pos_m = e.head<3>().norm();
    ori_rad = 0.0;
    if (rows_ == 6) {
      const Eigen::Vector3d r = rotation_error(target_.linear(), t.linear());
      ori_rad = r.norm();
      e.tail<3>() = opt_.orientation_weight_m * r;
    }
    return e;
  }

  bool converged(double pos_m, double ori_rad) const {
    return pos_m <= opt_.position_tolerance_m &&
           (rows_ == 3 || ori_rad <= opt_.orientation_tolerance_rad);
  }

  // Damped Gauss-Newton step (H + λI) dq = g over the free joints: a joint
  // sitting on a limit whose step points outward is frozen and the step
  // re-solved (an active set), so the other joints still make full progress
  // when the optimum lies on a limit instead of crawling along clamped steps.
  Eigen::VectorXd projected_step(const Eigen::MatrixXd& h, const Eigen::VectorXd& g,
                                 const Eigen::VectorXd& q, double lambda) const {
    const int n = static_cast<int>(q.size());
    std::vector<bool> frozen(static_cast<std::size_t>(n), false);
    Eigen::VectorXd dq = Eigen::VectorXd::Zero(n);
    for (int pass = 0; pass <= n; ++pass) {
      Eigen::MatrixXd damped = h + lambda * Eigen::MatrixXd::Identity(n, n);
      Eigen::VectorXd rhs = g;
      for (int i = 0; i < n; ++i) {
        if (!frozen[static_cast<std::size_t>(i)])
          continue;
        damped.row(i).setZero();
        damped.col(i).setZero();
        damped(i, i) = 1.0;
        rhs[i] = 0.0;
      }
      dq = damped.ldlt().solve(rhs);
      bool changed = false;
      for (int i = 0; i < n; ++i) {
        const JointProperties& j = model_.joints()[static_cast<std::size_t>(i)];
        const bool outward =
            (q[i] <= j.lower_rad && dq[i] < 0.0) || (q[i] >= j.upper_rad && dq[i] > 0.0);
        if (outward && !frozen[static_cast<std::size_t>(i)]) {
          frozen[static_cast<std::size_t>(i)] = true;
          changed = true;
        }
      }
      if (!changed)
        break;
    }
    return dq;
  }

  // Levenberg-Marquardt on ½‖e(q)‖² with the geometric Jacobian (de = −J dq
  // to first order), every trial step clamped into the joint limits.
  Attempt solve_from(const Eigen::VectorXd& q0) const {
    Attempt a;
    a.q = clamp_to_limits(model_, q0);
    Eigen::VectorXd e = residual(a.q, a.position_residual_m, a.orientation_residual_rad);
    a.cost = e.squaredNorm();
    double lambda = -1.0;
    for (; a.iterations < opt_.max_iterations; ++a.iterations) {
      if (converged(a.position_residual_m, a.orientation_residual_rad)) {
        a.converged = true;
        break;
      }
      Eigen::MatrixXd j = tool_jacobian(model_, a.q).topRows(rows_);
      if (rows_ == 6)
        j.bottomRows<3>() *= opt_.orientation_weight_m;
      const Eigen::MatrixXd h = j.transpose() * j;
      const Eigen::VectorXd g = j.transpose() * e;
      if (lambda < 0.0)
        lambda = 1e-3 * std::max(h.diagonal().maxCoeff(), 1e-12);
      bool accepted = false;
      for (int trial = 0; trial < 30 && !accepted; ++trial) {
        const Eigen::VectorXd dq = projected_step(h, g, a.q, lambda);
        const Eigen::VectorXd q_new = clamp_to_limits(model_, a.q + dq);
        double pos = 0.0;
        double ori = 0.0;
        const Eigen::VectorXd e_new = residual(q_new, pos, ori);
        if (e_new.allFinite() && e_new.squaredNorm() < a.cost) {
          a.q = q_new;
          e = e_new;
          a.cost = e.squaredNorm();
          a.position_residual_m = pos;
          a.orientation_residual_rad = ori;
          lambda = std::max(lambda * 0.1, 1e-15);
          accepted = true;
        } else {
          lambda *= 10.0;
        }
      }
      if (!accepted)
        break;  // no descent: a local minimum of the residual (e.g. out of reach)
    }
    if (!a.converged)
      a.converged = converged(a.position_residual_m, a.orientation_residual_rad);
    return a;
  }

 private:
  const RobotModel& model_;
  Eigen::Isometry3d target_;
  IkOptions opt_;
  int rows_;
};

// Seed k of a Kronecker (Weyl) sequence over the joint box: deterministic
// and evenly spread, so restarts are reproducible.
Eigen::VectorXd spread_seed(const RobotModel& model, int k) {
  static constexpr double kPrimes[] = {2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37};
  Eigen::VectorXd q(model.dof());
  for (int i = 0; i < q.size(); ++i) {
    const JointProperties& j = model.joints()[static_cast<std::size_t>(i)];
    const double alpha = std::sqrt(kPrimes[i % 12]) + static_cast<double>(i / 12);
    const double u = std::fmod(0.5 + k * alpha, 1.0);
    q[i] = j.lower_rad + (j.upper_rad - j.lower_rad) * u;
  }
  return q;
}

}  // namespace

Eigen::Isometry3d tool_pose(const RobotModel& model, const Eigen::VectorXd& q) {
  check_q(model, q, "tool_pose");
  KDL::ChainFkSolverPos_recursive fk(model.chain());
  KDL::Frame f;
  if (fk.JntToCart(to_kdl_joints(q), f) < 0)
    throw std::runtime_error("tool_pose: KDL forward kinematics failed");
  return model.description().base * to_eigen(f);
}

Eigen::Matrix<double, 6, Eigen::Dynamic> tool_jacobian(const RobotModel& model,
                                                       const Eigen::VectorXd& q) {
  check_q(model, q, "tool_jacobian");
  KDL::ChainJntToJacSolver solver(model.chain());
  KDL::Jacobian jac(static_cast<unsigned>(model.dof()));
  if (solver.JntToJac(to_kdl_joints(q), jac) < 0)
    throw std::runtime_error("tool_jacobian: KDL Jacobian solver failed");
  // KDL: reference point at the chain's end (tool tip), expressed in the
  // robot base frame; rotate both halves into the cell frame.
  const Eigen::Matrix3d r = model.description().base.linear();
  Eigen::Matrix<double, 6, Eigen::Dynamic> j(6, model.dof());
  j.topRows<3>() = r * jac.data.topRows<3>();
  j.bottomRows<3>() = r * jac.data.bottomRows<3>();
  return j;
}

Eigen::Matrix<double, 6, Eigen::Dynamic> point_jacobian(const RobotModel& model,
                                                        const Eigen::VectorXd& q,
                                                        const Eigen::Vector3d& offset_tool_m) {
  if (!offset_tool_m.allFinite())
    throw std::invalid_argument("point_jacobian: the offset must be finite");
  Eigen::Matrix<double, 6, Eigen::Dynamic> j = tool_jacobian(model, q);
  const Eigen::Vector3d r = tool_pose(model, q).linear() * offset_tool_m;
  // v_p = v + ω × r = v − [r]× ω, column by column.
  for (Eigen::Index c = 0; c < j.cols(); ++c) {
    const Eigen::Vector3d omega = j.block<3, 1>(3, c);
    j.block<3, 1>(0, c) += omega.cross(r);
  }
  return j;
}

IkResult inverse_kinematics(const RobotModel& model, const Eigen::Isometry3d& target_tool_pose,
                            const Eigen::VectorXd& q_seed, const IkOptions& options) {
  check_q(model, q_seed, "inverse_kinematics seed");
  if (!target_tool_pose.matrix().allFinite())
    throw std::invalid_argument("inverse_kinematics: the target pose must be finite");
  if (!(options.position_tolerance_m > 0.0) || !(options.orientation_tolerance_rad > 0.0) ||
      options.max_iterations < 1 || options.restarts < 0 || !(options.orientation_weight_m > 0.0)) {
    throw std::invalid_argument(
        "inverse_kinematics: tolerances and orientation weight must be positive, "
        "max_iterations ≥ 1, restarts ≥ 0");
  }
  const IkProblem problem(model, target_tool_pose, options);
  IkResult result;
  Attempt best = problem.solve_from(q_seed);
  result.iterations = best.iterations;
  result.attempts = 1;
  // The branch reached from the seed is the one a path follower wants; only
  // when it fails do restarts search the joint box.
  if (!best.converged) {
    for (int k = 1; k <= options.restarts; ++k) {
      const Attempt a = problem.solve_from(spread_seed(model, k));
      result.iterations += a.iterations;
      ++result.attempts;
      const bool better =
          a.converged ? (!best.converged || (a.q - q_seed).norm() < (best.q - q_seed).norm())
                      : (!best.converged && a.cost < best.cost);
      if (better)
        best = a;
    }
  }
  result.q = best.q;
  result.converged = best.converged;
  result.position_residual_m = best.position_residual_m;
  result.orientation_residual_rad = best.orientation_residual_rad;
  return result;
}

Eigen::Matrix3d tool_orientation_about_axis(const Eigen::Vector3d& tool_axis,
                                            double redundancy_angle_rad) {
  if (!tool_axis.allFinite() || !(tool_axis.norm() > 0.0) || !std::isfinite(redundancy_angle_rad))
    throw std::invalid_argument("tool axis must be finite and non-zero, angle finite");
  const Eigen::Vector3d z = tool_axis.normalized();
  Eigen::Vector3d ref = Eigen::Vector3d::UnitX();
  if (z.cross(ref).norm() < 1e-6)
    ref = Eigen::Vector3d::UnitY();
  const Eigen::Vector3d x0 = (ref - ref.dot(z) * z).normalized();
  Eigen::Matrix3d r;
  r.col(0) = x0;
  r.col(1) = z.cross(x0);
  r.col(2) = z;
  return r * Eigen::AngleAxisd(redundancy_angle_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

IkResult inverse_kinematics_about_axis(const RobotModel& model,
                                       const Eigen::Vector3d& tip_position_m,
                                       const Eigen::Vector3d& tool_axis,
                                       double redundancy_angle_rad, const Eigen::VectorXd& q_seed,
                                       const IkOptions& options) {
  if (!tip_position_m.allFinite())
    throw std::invalid_argument("inverse_kinematics_about_axis: tip position must be finite");
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.translation() = tip_position_m;
  if (!options.position_only)
    target.linear() = tool_orientation_about_axis(tool_axis, redundancy_angle_rad);
  return inverse_kinematics(model, target, q_seed, options);
}

}  // namespace robomill::robot
