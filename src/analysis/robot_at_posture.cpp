#include "robomill/analysis/robot_at_posture.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <numbers>
#include <stdexcept>

#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"
#include "robomill/core/parallel.hpp"
#include "robomill/robot/kinematics.hpp"

namespace robomill::analysis {
namespace {

/// Compliance along a unit direction: dᵀ C d.
double directional_compliance(const Eigen::Matrix3d& c, const Eigen::Vector3d& d) {
  return d.dot(c * d);
}

WorkspaceMap workspace_map(const robot::RobotModel& model, const job::RobotSettings::Map& grid,
                           const Eigen::VectorXd& seed, bool has_mass, int threads) {
  const int nx = grid.counts[0], ny = grid.counts[1], nz = grid.counts[2];
  WorkspaceMap map;
  std::vector<WorkspacePoint>& points = map.points;
  points.resize(static_cast<std::size_t>(nx) * ny * nz);
  auto coordinate = [](double from, double to, int count, int i) {
    return count == 1 ? from : from + (to - from) * i / (count - 1);
  };
  robot::IkOptions ik;
  ik.position_only = model.dof() < 6;
  ik.position_tolerance_m = 1e-9;
  ik.orientation_tolerance_rad = 1e-9;
  const Eigen::Vector3d normal = grid.tool_axis.cross(grid.feed);
  // One row along x per work item; along a row each point starts from the
  // previous solution (continuation), so neighbours stay on one IK branch and
  // the result does not depend on the thread count.
  core::parallel_for(static_cast<std::size_t>(ny) * nz, threads, [&](std::size_t row) {
    const int iy = static_cast<int>(row) % ny, iz = static_cast<int>(row) / ny;
    Eigen::VectorXd q = seed;
    for (int ix = 0; ix < nx; ++ix) {
      WorkspacePoint& p = points[(static_cast<std::size_t>(iz) * ny + iy) * nx + ix];
      p.position_m = {coordinate(grid.from_m.x(), grid.to_m.x(), nx, ix),
                      coordinate(grid.from_m.y(), grid.to_m.y(), ny, iy),
                      coordinate(grid.from_m.z(), grid.to_m.z(), nz, iz)};
      const robot::IkResult solution = robot::inverse_kinematics_about_axis(
          model, p.position_m, grid.tool_axis, grid.redundancy_rad, q, ik);
      p.q_rad = solution.q;
      p.reachable = solution.converged;
      if (!p.reachable)
        continue;
      q = solution.q;
      const Eigen::Matrix3d c = robot::translational_compliance(model, q);
      p.compliance_feed_m_per_n = directional_compliance(c, grid.feed);
      p.compliance_normal_m_per_n = directional_compliance(c, normal);
      p.compliance_axial_m_per_n = directional_compliance(c, grid.tool_axis);
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(c);
      const double smallest = eigen.eigenvalues().minCoeff();
      p.condition_number = smallest > 0.0 ? eigen.eigenvalues().maxCoeff() / smallest : 0.0;
      if (has_mass)
        p.lowest_frequency_hz = robot::robot_modes(model, q).natural_frequencies_hz.minCoeff();
    }
  });
  // The reachable points and the range of their lowest natural frequency.
  for (const WorkspacePoint& p : points) {
    if (p.reachable) {
      ++map.reachable;
      map.lowest_frequency_min_hz = std::min(map.lowest_frequency_min_hz, p.lowest_frequency_hz);
      map.lowest_frequency_max_hz = std::max(map.lowest_frequency_max_hz, p.lowest_frequency_hz);
    }
  }
  return map;
}

// robot.posture as joint angles, checked: one angle per joint, each within
// its joint's range.
Eigen::VectorXd checked_posture(const job::RobotSettings& settings,
                                const robot::RobotModel& model) {
  if (settings.posture_rad.empty()) {
    throw InputError(
        "robot.posture", 0,
        fmt::format("required: the {} joint angles to analyse (deg by default)", model.dof()));
  }
  const Eigen::VectorXd q =
      Eigen::Map<const Eigen::VectorXd>(settings.posture_rad.data(), model.dof());
  if (!model.within_limits(q)) {
    for (int i = 0; i < model.dof(); ++i) {
      const auto& joint = model.joints()[static_cast<std::size_t>(i)];
      if (q[i] < joint.lower_rad || q[i] > joint.upper_rad) {
        throw InputError(
            fmt::format("robot.posture[{}]", i), 0,
            fmt::format("{:g} deg is outside joint {}'s range [{:g}, {:g}] deg", q[i] * kDegPerRad,
                        i + 1, joint.lower_rad * kDegPerRad, joint.upper_rad * kDegPerRad));
      }
    }
  }
  return q;
}

// The tool-tip FRF (cell frame) over the job's range or 0.5-2 × the modes:
// `points` frequencies from `from_hz` to `to_hz`.
void tool_tip_frf(const robot::RobotModel& model, const job::RobotSettings& settings,
                  RobotAtPosture& result) {
  const robot::RobotModes& modes = *result.modes;
  const double from_hz = settings.frf_from_hz > 0.0 ? settings.frf_from_hz
                                                    : 0.5 * modes.natural_frequencies_hz.minCoeff();
  const double to_hz =
      settings.frf_to_hz > 0.0 ? settings.frf_to_hz : 2.0 * modes.natural_frequencies_hz.maxCoeff();
  if (!(to_hz > from_hz))
    throw InputError("robot.frf.to", 0, fmt::format("must exceed from ({:g} Hz)", from_hz));
  result.frf_from_hz = from_hz;
  result.frf_to_hz = to_hz;
  const int points = settings.frf_points;
  for (int i = 0; i < points; ++i) {
    const double f = from_hz + (to_hz - from_hz) * i / (points - 1);
    result.frf_frequencies_hz.push_back(f);
    result.frf_receptance_m_per_n.push_back(
        robot::tool_tip_receptance(model, result.posture_rad, 2.0 * std::numbers::pi * f));
  }
}

// 002 §2 (Eq 8-23): the reduced tip model, 6-D where the compliance is
// invertible (six joints away from singularities), else translational 3-D;
// its frequencies against the full joint-space eigenproblem.
void reduced_tip_model(const robot::RobotModel& model, RobotAtPosture& result) {
  const Eigen::VectorXd& q = result.posture_rad;
  const Eigen::MatrixXd m = robot::mass_matrix(model, q);
  const Eigen::VectorXd kq = model.joint_stiffness();
  for (const int dimension : {6, 3}) {
    if (dimension == 6 && model.dof() < 6)
      continue;
    try {
      const Eigen::MatrixXd j = dimension == 6 ? Eigen::MatrixXd(result.jacobian)
                                               : robot::linear_jacobian(result.jacobian);
      const robot::ReducedModel r = robot::reduce_model(j, kq, m);
      const robot::FrequencyComparison c = robot::compare_with_full_model(r, kq, m);
      result.reduced_model = ReducedTipModel{dimension, r, c};
      result.reduced_model_note.clear();
      break;
    } catch (const std::invalid_argument& e) {
      result.reduced_model_note = e.what();
    }
  }
}

}  // namespace

RobotAtPosture robot_at_posture(const job::Job& job, int threads) {
  job::require(job, {job::Section::robot});
  const job::RobotSettings& settings = *job.robot;
  const auto start = std::chrono::steady_clock::now();
  const robot::RobotModel model(settings.description);
  RobotAtPosture result;
  result.robot_name = model.name();
  result.dof = model.dof();
  result.posture_rad = checked_posture(settings, model);
  const Eigen::VectorXd& q = result.posture_rad;

  result.tool_pose = robot::tool_pose(model, q);
  result.jacobian = robot::tool_jacobian(model, q);
  result.compliance = robot::cartesian_compliance(model, q);
  result.translational_compliance_m_per_n = robot::translational_compliance(model, q);
  // A DH robot without link masses has statics only (000 §6.1 gives the
  // KR600's stiffness, not its masses): no modes, FRF or frequency map then.
  const bool has_mass = !(settings.description.dh && settings.description.dh->links.empty());
  if (has_mass) {
    result.modes = robot::robot_modes(model, q);
    // The tool frame of the pose (x, y, z of the tool): the modal table is
    // given along the tool's own axes, which is how a hammer test at the tip
    // and the stability engine see it.
    result.modal_table_tool_frame =
        robot::directional_modal_parameters(model, q, result.tool_pose.linear().transpose());
  }

  try {
    result.principal_stiffness = robot::principal_stiffness(model, q);
  } catch (const std::invalid_argument& e) {
    result.principal_stiffness_note = e.what();
  }

  if (result.modes) {
    tool_tip_frf(model, settings, result);
    reduced_tip_model(model, result);
  }

  if (settings.map)
    result.map = workspace_map(model, *settings.map, q, has_mass, threads);
  result.elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  result.tool_rpy_rad = result.tool_pose.linear().eulerAngles(2, 1, 0).reverse();
  return result;
}

}  // namespace robomill::analysis
