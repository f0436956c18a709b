// robomill robot JOB: what the robot's structure is at a posture — tool pose,
// Jacobian, Cartesian compliance (000 Eq 3-4), principal stiffness, joint-space
// natural frequencies and tool-tip modes (004 Eq 1-2), the tool-tip FRF — and,
// with robot.map, the same figures over a grid of tool-tip positions.

#include <fmt/format.h>
#include <Eigen/Eigenvalues>

#include <chrono>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "robomill/commands/commands.hpp"
#include "robomill/core/error.hpp"
#include "robomill/core/parallel.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/summary.hpp"
#include "robomill/robot/joint_dynamics.hpp"
#include "robomill/robot/kinematics.hpp"
#include "robomill/robot/reduced_model.hpp"
#include "robomill/robot/stiffness.hpp"

namespace robomill::commands {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

nlohmann::json matrix_json(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      row.push_back(m(i, j));
    rows.push_back(row);
  }
  return rows;
}

nlohmann::json vector_json(const Eigen::VectorXd& v, double scale = 1.0) {
  nlohmann::json values = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i)
    values.push_back(v[i] * scale);
  return values;
}

/// One grid point of the workspace map.
struct MapPoint {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  bool reachable = false;
  Eigen::VectorXd q;
  double lowest_frequency_hz = 0.0;
  double compliance_feed_m_per_n = 0.0, compliance_normal_m_per_n = 0.0;
  double compliance_axial_m_per_n = 0.0;
  double condition_number = 0.0;
};

/// Compliance along a unit direction: dᵀ C d.
double directional_compliance(const Eigen::Matrix3d& c, const Eigen::Vector3d& d) {
  return d.dot(c * d);
}

std::vector<MapPoint> workspace_map(const robot::RobotModel& model,
                                    const job::RobotSettings::Map& grid,
                                    const Eigen::VectorXd& seed, bool has_mass, int threads) {
  const int nx = grid.counts[0], ny = grid.counts[1], nz = grid.counts[2];
  std::vector<MapPoint> points(static_cast<std::size_t>(nx) * ny * nz);
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
      MapPoint& p = points[(static_cast<std::size_t>(iz) * ny + iy) * nx + ix];
      p.position_m = {coordinate(grid.from_m.x(), grid.to_m.x(), nx, ix),
                      coordinate(grid.from_m.y(), grid.to_m.y(), ny, iy),
                      coordinate(grid.from_m.z(), grid.to_m.z(), nz, iz)};
      const robot::IkResult solution = robot::inverse_kinematics_about_axis(
          model, p.position_m, grid.tool_axis, grid.redundancy_rad, q, ik);
      p.q = solution.q;
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
  return points;
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

// summary.json's principal_stiffness, or why there is none.
nlohmann::json principal_stiffness_json(const robot::RobotModel& model, const Eigen::VectorXd& q) {
  nlohmann::json principal;
  try {
    const robot::PrincipalStiffness p = robot::principal_stiffness(model, q);
    principal = {{"stiffness_N_per_m", vector_json(p.stiffness_n_per_m)},
                 {"directions", matrix_json(p.directions)},
                 {"condition_number", p.condition_number}};
  } catch (const std::invalid_argument& e) {
    principal = {{"note", e.what()}};
  }
  return principal;
}

// frf.csv's rows: the tool-tip receptance (cell frame) at `points`
// frequencies from `from_hz` to `to_hz`.
void add_frf_rows(io::CsvTable& frf, const robot::RobotModel& model, const Eigen::VectorXd& q,
                  double from_hz, double to_hz, int points) {
  for (int i = 0; i < points; ++i) {
    const double f = from_hz + (to_hz - from_hz) * i / (points - 1);
    const Eigen::Matrix3cd h = robot::tool_tip_receptance(model, q, 2.0 * std::numbers::pi * f);
    frf.add_row({f, h(0, 0).real(), h(0, 0).imag(), h(1, 1).real(), h(1, 1).imag(), h(2, 2).real(),
                 h(2, 2).imag(), h(0, 1).real(), h(0, 1).imag(), h(0, 2).real(), h(0, 2).imag(),
                 h(1, 2).real(), h(1, 2).imag()});
  }
}

// modes.csv's rows: each mode's frequency, damping and tool-tip shape.
void add_mode_rows(io::CsvTable& modes_table, const robot::RobotModes& modes) {
  for (Eigen::Index i = 0; i < modes.natural_frequencies_hz.size(); ++i) {
    modes_table.add_row({static_cast<double>(i + 1), modes.natural_frequencies_hz[i],
                         modes.damping_ratios[i], modes.tip_shapes(0, i), modes.tip_shapes(1, i),
                         modes.tip_shapes(2, i)});
  }
}

// summary.json's modal_table_tool_frame.
nlohmann::json modal_table_json(const std::vector<robot::DirectionalModalParameters>& directional) {
  nlohmann::json modal_table = nlohmann::json::array();
  for (const auto& m : directional) {
    modal_table.push_back({{"mode", m.mode + 1},
                           {"direction", std::string(1, "xyz"[m.axis])},
                           {"fn_hz", m.natural_frequency_hz},
                           {"zeta", m.damping_ratio},
                           {"k_N_per_m", m.stiffness_n_per_m},
                           {"m_kg", m.mass_kg}});
  }
  return modal_table;
}

// 002 §2 (Eq 8-23): the reduced tip model, 6-D where the compliance is
// invertible (six joints away from singularities), else translational 3-D;
// its frequencies against the full joint-space eigenproblem.
nlohmann::json reduced_model_json(const robot::RobotModel& model, const Eigen::VectorXd& q,
                                  const Eigen::Matrix<double, 6, Eigen::Dynamic>& jacobian) {
  nlohmann::json reduced;
  const Eigen::MatrixXd m = robot::mass_matrix(model, q);
  const Eigen::VectorXd kq = model.joint_stiffness();
  for (const int dimension : {6, 3}) {
    if (dimension == 6 && model.dof() < 6)
      continue;
    try {
      const Eigen::MatrixXd j =
          dimension == 6 ? Eigen::MatrixXd(jacobian) : robot::linear_jacobian(jacobian);
      const robot::ReducedModel r = robot::reduce_model(j, kq, m);
      const robot::FrequencyComparison c = robot::compare_with_full_model(r, kq, m);
      reduced = {{"dimension", dimension},
                 {"mass", matrix_json(r.mass)},
                 {"stiffness", matrix_json(r.stiffness)},
                 {"natural_frequencies_hz", vector_json(c.reduced_hz)},
                 {"full_natural_frequencies_hz", vector_json(c.full_hz)},
                 {"relative_difference", vector_json(c.relative_difference)}};
      break;
    } catch (const std::invalid_argument& e) {
      reduced = {{"note", e.what()}};
    }
  }
  return reduced;
}

// map.csv: every grid point, its figures and (reachable) joint angles.
io::CsvTable map_table(const std::vector<MapPoint>& map, int dof) {
  std::vector<std::string> columns = {"x_mm",
                                      "y_mm",
                                      "z_mm",
                                      "reachable",
                                      "lowest_fn_hz",
                                      "compliance_feed_um_per_N",
                                      "compliance_normal_um_per_N",
                                      "compliance_axial_um_per_N",
                                      "condition_number"};
  for (int j = 0; j < dof; ++j)
    columns.push_back(fmt::format("q{}_deg", j + 1));
  io::CsvTable table(columns);
  for (const MapPoint& p : map) {
    std::vector<double> row = {p.position_m.x() * 1e3,
                               p.position_m.y() * 1e3,
                               p.position_m.z() * 1e3,
                               p.reachable ? 1.0 : 0.0,
                               p.lowest_frequency_hz,
                               p.compliance_feed_m_per_n * 1e6,
                               p.compliance_normal_m_per_n * 1e6,
                               p.compliance_axial_m_per_n * 1e6,
                               p.condition_number};
    for (int j = 0; j < dof; ++j)
      row.push_back(p.reachable ? p.q[j] * kDegPerRad : 0.0);
    table.add_row(row);
  }
  return table;
}

// summary.json's map: the points, the reachable ones and the range of their
// lowest natural frequency.
nlohmann::json map_summary(const std::vector<MapPoint>& map) {
  int reachable = 0;
  double lowest = INFINITY, highest = 0.0;
  for (const MapPoint& p : map) {
    if (p.reachable) {
      ++reachable;
      lowest = std::min(lowest, p.lowest_frequency_hz);
      highest = std::max(highest, p.lowest_frequency_hz);
    }
  }
  nlohmann::json summary = {{"points", map.size()}, {"reachable", reachable}};
  if (reachable > 0) {
    summary["lowest_fn_hz_min"] = lowest;
    summary["lowest_fn_hz_max"] = highest;
  }
  return summary;
}

// The message's first line: the tool's position and the natural frequencies.
std::string robot_message(const robot::RobotModel& model, const Eigen::Isometry3d& pose,
                          const std::optional<robot::RobotModes>& modes) {
  std::string message = fmt::format("robot {} ({} joints): tool at [{:.1f}, {:.1f}, {:.1f}] mm",
                                    model.name(), model.dof(), pose.translation().x() * 1e3,
                                    pose.translation().y() * 1e3, pose.translation().z() * 1e3);
  if (modes) {
    message += "; natural frequencies";
    for (Eigen::Index i = 0; i < modes->natural_frequencies_hz.size(); ++i)
      message += fmt::format(" {:.2f}", modes->natural_frequencies_hz[i]);
    message += " Hz";
  }
  message += '\n';
  return message;
}

}  // namespace

CommandResult compute_robot(const job::Job& job, int threads) {
  job::require(job, {job::Section::robot});
  const job::RobotSettings& settings = *job.robot;
  const auto start = std::chrono::steady_clock::now();
  const robot::RobotModel model(settings.description);
  const Eigen::VectorXd q = checked_posture(settings, model);

  const Eigen::Isometry3d pose = robot::tool_pose(model, q);
  const Eigen::Matrix<double, 6, Eigen::Dynamic> jacobian = robot::tool_jacobian(model, q);
  const robot::Matrix6d compliance = robot::cartesian_compliance(model, q);
  const Eigen::Matrix3d translational = robot::translational_compliance(model, q);
  // A DH robot without link masses has statics only (000 §6.1 gives the
  // KR600's stiffness, not its masses): no modes, FRF or frequency map then.
  const bool has_mass = !(settings.description.dh && settings.description.dh->links.empty());
  std::optional<robot::RobotModes> modes;
  std::vector<robot::DirectionalModalParameters> directional;
  if (has_mass) {
    modes = robot::robot_modes(model, q);
    // The tool frame of the pose (x, y, z of the tool): the modal table is
    // given along the tool's own axes, which is how a hammer test at the tip
    // and the stability engine see it.
    directional = robot::directional_modal_parameters(model, q, pose.linear().transpose());
  }

  const nlohmann::json principal = principal_stiffness_json(model, q);

  // Tool-tip FRF (cell frame) over the job's range or 0.5-2 × the modes.
  io::CsvTable frf({"freq_hz", "hxx_re", "hxx_im", "hyy_re", "hyy_im", "hzz_re", "hzz_im", "hxy_re",
                    "hxy_im", "hxz_re", "hxz_im", "hyz_re", "hyz_im"});
  io::CsvTable modes_table({"mode", "fn_hz", "zeta", "tip_shape_x", "tip_shape_y", "tip_shape_z"});
  double from_hz = 0.0, to_hz = 0.0;
  if (modes) {
    from_hz = settings.frf_from_hz > 0.0 ? settings.frf_from_hz
                                         : 0.5 * modes->natural_frequencies_hz.minCoeff();
    to_hz = settings.frf_to_hz > 0.0 ? settings.frf_to_hz
                                     : 2.0 * modes->natural_frequencies_hz.maxCoeff();
    if (!(to_hz > from_hz))
      throw InputError("robot.frf.to", 0, fmt::format("must exceed from ({:g} Hz)", from_hz));
    add_frf_rows(frf, model, q, from_hz, to_hz, settings.frf_points);
    add_mode_rows(modes_table, *modes);
  }
  const nlohmann::json modal_table = modal_table_json(directional);

  nlohmann::json reduced;
  if (modes)
    reduced = reduced_model_json(model, q, jacobian);

  std::optional<std::vector<MapPoint>> map;
  if (settings.map)
    map = workspace_map(model, *settings.map, q, has_mass, threads);
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const Eigen::Vector3d rpy = pose.linear().eulerAngles(2, 1, 0).reverse();
  nlohmann::json summary = {{"command", "robot"},
                            {"job", job.source.string()},
                            {"robot", model.name()},
                            {"dof", model.dof()},
                            {"elapsed_s", elapsed_s},
                            {"posture_deg", vector_json(q, kDegPerRad)},
                            {"tool_position_mm", vector_json(pose.translation(), 1e3)},
                            {"tool_rotation", matrix_json(pose.linear())},
                            {"tool_rpy_deg", vector_json(rpy, kDegPerRad)},
                            {"jacobian", matrix_json(jacobian)},
                            {"compliance", matrix_json(compliance)},
                            {"translational_compliance_m_per_N", matrix_json(translational)},
                            {"principal_stiffness", principal},
                            {"modal_table_tool_frame", modal_table}};
  if (modes) {
    summary["natural_frequencies_hz"] = vector_json(modes->natural_frequencies_hz);
    summary["damping_ratios"] = vector_json(modes->damping_ratios);
    summary["frf"] = {{"from_hz", from_hz}, {"to_hz", to_hz}, {"points", settings.frf_points}};
    summary["reduced_model"] = reduced;
  } else {
    summary["natural_frequencies_hz"] = nlohmann::json::array();
    summary["dynamics_note"] = "no link masses (robot.links): statics only";
  }

  CommandResult result;
  if (modes) {
    result.tables.emplace_back("frf", std::move(frf));
    result.tables.emplace_back("modes", std::move(modes_table));
  }
  if (map) {
    summary["map"] = map_summary(*map);
    result.tables.emplace_back("map", map_table(*map, model.dof()));
  }
  result.summary = std::move(summary);

  std::string& message = result.message;
  message = robot_message(model, pose, modes);
  if (map) {
    message += fmt::format("  map: {} of {} points reachable\n",
                           result.summary["map"]["reachable"].get<int>(), map->size());
  }
  return result;
}

}  // namespace robomill::commands
