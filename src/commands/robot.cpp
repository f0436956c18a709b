// robomill robot JOB: what the robot's structure is at a posture — tool pose,
// Jacobian, Cartesian compliance (000 Eq 3-4), principal stiffness, joint-space
// natural frequencies and tool-tip modes (004 Eq 1-2), the tool-tip FRF — and,
// with robot.map, the same figures over a grid of tool-tip positions. The
// figures are analysis::robot_at_posture's; this file writes them as frf.csv,
// modes.csv, map.csv and summary.json.

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "json_helpers.hpp"
#include "robomill/analysis/robot_at_posture.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/summary.hpp"

namespace robomill::commands {
namespace {

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

// summary.json's principal_stiffness, or why there is none.
nlohmann::json principal_stiffness_json(const analysis::RobotAtPosture& figures) {
  if (!figures.principal_stiffness)
    return {{"note", figures.principal_stiffness_note}};
  const robot::PrincipalStiffness& p = *figures.principal_stiffness;
  return {{"stiffness_N_per_m", detail::vector_json(p.stiffness_n_per_m)},
          {"directions", matrix_json(p.directions)},
          {"condition_number", p.condition_number}};
}

// frf.csv: the tool-tip receptance (cell frame) at each frequency.
io::CsvTable frf_table(const analysis::RobotAtPosture& figures) {
  io::CsvTable frf({"freq_hz", "hxx_re", "hxx_im", "hyy_re", "hyy_im", "hzz_re", "hzz_im", "hxy_re",
                    "hxy_im", "hxz_re", "hxz_im", "hyz_re", "hyz_im"});
  for (std::size_t i = 0; i < figures.frf_frequencies_hz.size(); ++i) {
    const double f = figures.frf_frequencies_hz[i];
    const Eigen::Matrix3cd& h = figures.frf_receptance_m_per_n[i];
    frf.add_row({f, h(0, 0).real(), h(0, 0).imag(), h(1, 1).real(), h(1, 1).imag(), h(2, 2).real(),
                 h(2, 2).imag(), h(0, 1).real(), h(0, 1).imag(), h(0, 2).real(), h(0, 2).imag(),
                 h(1, 2).real(), h(1, 2).imag()});
  }
  return frf;
}

// modes.csv: each mode's frequency, damping and tool-tip shape.
io::CsvTable modes_table(const robot::RobotModes& modes) {
  io::CsvTable table({"mode", "fn_hz", "zeta", "tip_shape_x", "tip_shape_y", "tip_shape_z"});
  for (Eigen::Index i = 0; i < modes.natural_frequencies_hz.size(); ++i) {
    table.add_row({static_cast<double>(i + 1), modes.natural_frequencies_hz[i],
                   modes.damping_ratios[i], modes.tip_shapes(0, i), modes.tip_shapes(1, i),
                   modes.tip_shapes(2, i)});
  }
  return table;
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

// summary.json's reduced_model (002 §2, Eq 8-23), or why there is none.
nlohmann::json reduced_model_json(const analysis::RobotAtPosture& figures) {
  if (!figures.reduced_model)
    return {{"note", figures.reduced_model_note}};
  const analysis::ReducedTipModel& r = *figures.reduced_model;
  return {{"dimension", r.dimension},
          {"mass", matrix_json(r.model.mass)},
          {"stiffness", matrix_json(r.model.stiffness)},
          {"natural_frequencies_hz", detail::vector_json(r.frequencies.reduced_hz)},
          {"full_natural_frequencies_hz", detail::vector_json(r.frequencies.full_hz)},
          {"relative_difference", detail::vector_json(r.frequencies.relative_difference)}};
}

// map.csv: every grid point, its figures and (reachable) joint angles.
io::CsvTable map_table(const analysis::WorkspaceMap& map, int dof) {
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
  for (const analysis::WorkspacePoint& p : map.points) {
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
      row.push_back(p.reachable ? p.q_rad[j] * kDegPerRad : 0.0);
    table.add_row(row);
  }
  return table;
}

// summary.json's map: the points, the reachable ones and the range of their
// lowest natural frequency.
nlohmann::json map_summary(const analysis::WorkspaceMap& map) {
  nlohmann::json summary = {{"points", map.points.size()}, {"reachable", map.reachable}};
  if (map.reachable > 0) {
    summary["lowest_fn_hz_min"] = map.lowest_frequency_min_hz;
    summary["lowest_fn_hz_max"] = map.lowest_frequency_max_hz;
  }
  return summary;
}

// The message's first line: the tool's position and the natural frequencies.
std::string robot_message(const analysis::RobotAtPosture& figures) {
  const Eigen::Isometry3d& pose = figures.tool_pose;
  std::string message = fmt::format("robot {} ({} joints): tool at [{:.1f}, {:.1f}, {:.1f}] mm",
                                    figures.robot_name, figures.dof, pose.translation().x() * 1e3,
                                    pose.translation().y() * 1e3, pose.translation().z() * 1e3);
  if (figures.modes) {
    message += "; natural frequencies";
    for (Eigen::Index i = 0; i < figures.modes->natural_frequencies_hz.size(); ++i)
      message += fmt::format(" {:.2f}", figures.modes->natural_frequencies_hz[i]);
    message += " Hz";
  }
  message += '\n';
  return message;
}

}  // namespace

CommandResult compute_robot(const job::Job& job, int threads) {
  const analysis::RobotAtPosture figures = analysis::robot_at_posture(job, threads);
  const Eigen::Isometry3d& pose = figures.tool_pose;

  nlohmann::json summary = {
      {"command", "robot"},
      {"job", job.source.string()},
      {"robot", figures.robot_name},
      {"dof", figures.dof},
      {"elapsed_s", figures.elapsed_s},
      {"posture_deg", detail::vector_json(figures.posture_rad, kDegPerRad)},
      {"tool_position_mm", detail::vector_json(pose.translation(), 1e3)},
      {"tool_rotation", matrix_json(pose.linear())},
      {"tool_rpy_deg", detail::vector_json(figures.tool_rpy_rad, kDegPerRad)},
      {"jacobian", matrix_json(figures.jacobian)},
      {"compliance", matrix_json(figures.compliance)},
      {"translational_compliance_m_per_N", matrix_json(figures.translational_compliance_m_per_n)},
      {"principal_stiffness", principal_stiffness_json(figures)},
      {"modal_table_tool_frame", modal_table_json(figures.modal_table_tool_frame)}};
  if (figures.modes) {
    summary["natural_frequencies_hz"] = detail::vector_json(figures.modes->natural_frequencies_hz);
    summary["damping_ratios"] = detail::vector_json(figures.modes->damping_ratios);
    summary["frf"] = {{"from_hz", figures.frf_from_hz},
                      {"to_hz", figures.frf_to_hz},
                      {"points", job.robot->frf_points}};
    summary["reduced_model"] = reduced_model_json(figures);
  } else {
    summary["natural_frequencies_hz"] = nlohmann::json::array();
    summary["dynamics_note"] = "no link masses (robot.links): statics only";
  }

  CommandResult result;
  if (figures.modes) {
    result.tables.emplace_back("frf", frf_table(figures));
    result.tables.emplace_back("modes", modes_table(*figures.modes));
  }
  if (figures.map) {
    summary["map"] = map_summary(*figures.map);
    result.tables.emplace_back("map", map_table(*figures.map, figures.dof));
  }
  result.summary = std::move(summary);

  std::string& message = result.message;
  message = robot_message(figures);
  if (figures.map) {
    message += fmt::format("  map: {} of {} points reachable\n", figures.map->reachable,
                           figures.map->points.size());
  }
  return result;
}

}  // namespace robomill::commands
