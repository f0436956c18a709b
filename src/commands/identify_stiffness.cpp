// robomill identify-stiffness DATA.csv --job ROBOT.yaml: the joint stiffness
// Kq from static loading tests (000 §6.1, model 000 Eq 3), and — with
// --synthesize — the displacements such a test would measure on the job's
// robot, to plan a test (which postures and loads make Kq observable) or to
// check the method on data with known answers.
//
// DATA.csv, one row per loading test (cell frame, loaded − unloaded):
//   q1_deg … qn_deg            the posture
//   fx_N, fy_N, fz_N           the applied force
//   mx_Nm, my_Nm, mz_Nm        optional: the applied moment about the loaded point
//   dx_mm, dy_mm, dz_mm        the measured displacement of the target
//   target_x_mm, target_y_mm, target_z_mm
//                              optional: the measured point (target ball), from
//                              the tool tip in the tool frame (default: the tip)
//   load_x_mm, load_y_mm, load_z_mm
//                              optional: where the load acts, from the tool tip
//                              in the tool frame (default: the tip). 000 records
//                              both points, so Jc ≠ Je in its Eq 3.
// A target on a joint's axis (the tip of a spindle on the flange axis) does
// not move when that joint turns: such data cannot identify the joint, and
// the command says so.
//
// The identification and the synthesis are analysis::joint_stiffness_from_tests's
// and analysis::synthesized_displacements_m's; this file reads DATA.csv against
// the job's robot and writes fit.csv, joint_stiffness.yaml and summary.json, or
// loading_tests.csv.

#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "json_helpers.hpp"
#include "robomill/analysis/joint_stiffness_identification.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/summary.hpp"

namespace robomill::commands {
namespace {

/// Columns that must appear together, or not at all.
std::optional<std::array<int, 3>> column_triple(const io::CsvTable& data,
                                                const std::array<const char*, 3>& names,
                                                bool required, const std::string& source) {
  std::array<int, 3> index{};
  int found = 0;
  for (int k = 0; k < 3; ++k) {
    index[k] = data.find(names[k]);
    found += index[k] >= 0;
  }
  if (found == 3)
    return index;
  if (found == 0 && !required)
    return std::nullopt;
  throw InputError(
      source, 1,
      fmt::format("columns {}, {}, {} are {}; found {} of them", names[0], names[1], names[2],
                  required ? "required" : "given together or not at all", found));
}

/// Reads DATA.csv for a robot with `dof` joints; the measured displacement
/// is optional only when it is about to be synthesized.
std::vector<analysis::LoadingTest> read_loading_tests(const std::filesystem::path& file,
                                                      const robot::RobotModel& model,
                                                      bool need_displacement,
                                                      std::vector<std::string>& columns_out) {
  const io::CsvTable data = io::read_csv(file);
  const std::string source = file.string();
  columns_out = data.columns();
  const int dof = model.dof();
  std::vector<int> q_columns;
  for (int j = 0; j < dof; ++j) {
    const std::string name = fmt::format("q{}_deg", j + 1);
    q_columns.push_back(data.find(name));
    if (q_columns.back() < 0) {
      throw InputError(source, 1,
                       fmt::format("missing column '{}': the robot has {} joints, so q1_deg … "
                                   "q{}_deg are required",
                                   name, dof, dof));
    }
  }
  if (data.find(fmt::format("q{}_deg", dof + 1)) >= 0) {
    throw InputError(
        source, 1, fmt::format("column q{}_deg, but the job's robot has {} joints", dof + 1, dof));
  }
  const auto force = column_triple(data, {"fx_N", "fy_N", "fz_N"}, true, source);
  const auto moment = column_triple(data, {"mx_Nm", "my_Nm", "mz_Nm"}, false, source);
  const auto displacement =
      column_triple(data, {"dx_mm", "dy_mm", "dz_mm"}, need_displacement, source);
  const auto target =
      column_triple(data, {"target_x_mm", "target_y_mm", "target_z_mm"}, false, source);
  const auto offset = column_triple(data, {"load_x_mm", "load_y_mm", "load_z_mm"}, false, source);
  if (data.rows() == 0)
    throw InputError(source, 2, "no loading tests (the file has a header only)");

  std::vector<analysis::LoadingTest> tests;
  for (std::size_t row = 0; row < data.rows(); ++row) {
    analysis::LoadingTest t;
    // read_csv skips blank and comment lines, so the row index is the best
    // position we can name: "test N" counts data rows from 1.
    t.test = static_cast<int>(row) + 1;
    t.q_rad.resize(dof);
    for (int j = 0; j < dof; ++j) {
      const double degrees = data.at(row, q_columns[j]);
      const auto& joint = model.joints()[static_cast<std::size_t>(j)];
      t.q_rad[j] = degrees / kDegPerRad;
      if (t.q_rad[j] < joint.lower_rad - 1e-12 || t.q_rad[j] > joint.upper_rad + 1e-12) {
        throw InputError(source, 0,
                         fmt::format("test {}: q{}_deg = {:g} is outside joint {}'s range [{:g}, "
                                     "{:g}] deg (angles are in degrees)",
                                     t.test, j + 1, degrees, j + 1, joint.lower_rad * kDegPerRad,
                                     joint.upper_rad * kDegPerRad));
      }
    }
    for (int k = 0; k < 3; ++k) {
      t.wrench[k] = data.at(row, (*force)[k]);
      if (moment)
        t.wrench[3 + k] = data.at(row, (*moment)[k]);
      if (displacement)
        t.displacement_m[k] = data.at(row, (*displacement)[k]) * 1e-3;
      if (target)
        t.target_offset_tool_m[k] = data.at(row, (*target)[k]) * 1e-3;
      if (offset)
        t.load_offset_tool_m[k] = data.at(row, (*offset)[k]) * 1e-3;
    }
    t.has_moment = moment.has_value();
    if (t.wrench.isZero(0.0))
      throw InputError(source, 0,
                       fmt::format("test {}: no load (force and moment are zero)", t.test));
    tests.push_back(std::move(t));
  }
  return tests;
}

/// loading_tests.csv: the tests with the displacements synthesized for them
/// (analysis::synthesized_displacements_m), in the data file's units.
io::CsvTable synthesized_tests(const robot::RobotModel& model,
                               const std::vector<analysis::LoadingTest>& tests,
                               const std::vector<Eigen::Vector3d>& displacements_m,
                               bool with_moment) {
  std::vector<std::string> columns;
  for (int j = 0; j < model.dof(); ++j)
    columns.push_back(fmt::format("q{}_deg", j + 1));
  for (const char* c : {"fx_N", "fy_N", "fz_N"})
    columns.push_back(c);
  if (with_moment) {
    for (const char* c : {"mx_Nm", "my_Nm", "mz_Nm"})
      columns.push_back(c);
  }
  for (const char* c : {"target_x_mm", "target_y_mm", "target_z_mm", "load_x_mm", "load_y_mm",
                        "load_z_mm", "dx_mm", "dy_mm", "dz_mm"})
    columns.push_back(c);
  io::CsvTable table(columns);
  for (std::size_t i = 0; i < tests.size(); ++i) {
    const analysis::LoadingTest& t = tests[i];
    const Eigen::Vector3d& d = displacements_m[i];
    std::vector<double> row;
    for (int j = 0; j < model.dof(); ++j)
      row.push_back(t.q_rad[j] * kDegPerRad);
    for (int k = 0; k < (with_moment ? 6 : 3); ++k)
      row.push_back(t.wrench[k]);
    for (int k = 0; k < 3; ++k)
      row.push_back(t.target_offset_tool_m[k] * 1e3);
    for (int k = 0; k < 3; ++k)
      row.push_back(t.load_offset_tool_m[k] * 1e3);
    for (int k = 0; k < 3; ++k)
      row.push_back(d[k] * 1e3);
    table.add_row(row);
  }
  return table;
}

}  // namespace

CommandResult compute_identify_stiffness(const job::Job& job,
                                         const IdentifyStiffnessSettings& options) {
  const robot::RobotModel model = analysis::loading_test_robot(job);
  std::vector<std::string> columns;
  const std::vector<analysis::LoadingTest> tests =
      read_loading_tests(options.data_file, model, !options.synthesize, columns);

  if (options.synthesize) {
    if (!(options.noise >= 0.0) || !std::isfinite(options.noise) || options.noise > 1.0)
      throw InputError("--noise", 0, fmt::format("must lie in [0, 1], got {:g}", options.noise));
    const bool with_moment = std::find(columns.begin(), columns.end(), "mx_Nm") != columns.end();
    CommandResult result;
    result.tables.emplace_back("loading_tests",
                               synthesized_tests(model, tests,
                                                 analysis::synthesized_displacements_m(
                                                     model, tests, options.noise, options.seed),
                                                 with_moment));
    result.message =
        fmt::format("synthesized {} loading tests on {} (job Kq, {:g} % noise, seed {})",
                    tests.size(), model.name(), 100.0 * options.noise, options.seed);
    return result;
  }

  const analysis::JointStiffnessIdentification identification =
      analysis::joint_stiffness_from_tests(model, tests, options.max_condition, options.data_file);
  const robot::StiffnessIdentification& id = identification.fit;
  const Eigen::VectorXd& prior = identification.job_stiffness_nm_per_rad;
  io::CsvTable fit({"test", "dx_mm", "dy_mm", "dz_mm", "model_dx_mm", "model_dy_mm", "model_dz_mm",
                    "residual_um"});
  for (std::size_t i = 0; i < tests.size(); ++i) {
    const analysis::LoadingTest& t = tests[i];
    const Eigen::Vector3d& model_m = identification.model_displacement_m[i];
    fit.add_row({static_cast<double>(t.test), t.displacement_m.x() * 1e3,
                 t.displacement_m.y() * 1e3, t.displacement_m.z() * 1e3, model_m.x() * 1e3,
                 model_m.y() * 1e3, model_m.z() * 1e3, id.residual_norm_m[i] * 1e6});
  }

  nlohmann::json joints = nlohmann::json::array();
  for (int j = 0; j < model.dof(); ++j) {
    const double se = id.stiffness_standard_error_nm_per_rad[j];
    joints.push_back({{"joint", j + 1},
                      {"stiffness_Nm_per_rad", id.stiffness_nm_per_rad[j]},
                      {"standard_error_Nm_per_rad", se},
                      {"relative_standard_error", se / id.stiffness_nm_per_rad[j]},
                      {"job_stiffness_Nm_per_rad", prior[j]},
                      {"ratio_to_job", id.stiffness_nm_per_rad[j] / prior[j]}});
  }
  const nlohmann::json summary = {
      {"command", "identify-stiffness"},
      {"data", options.data_file.string()},
      {"job", job.source.string()},
      {"robot", model.name()},
      {"tests", tests.size()},
      {"equations", id.equations},
      {"degrees_of_freedom", id.degrees_of_freedom},
      {"joint_stiffness_Nm_per_rad", detail::vector_json(id.stiffness_nm_per_rad)},
      {"standard_error_Nm_per_rad", detail::vector_json(id.stiffness_standard_error_nm_per_rad)},
      {"joints", joints},
      {"condition_number", id.condition_number},
      {"rms_residual_um", id.rms_residual_m * 1e6},
      {"r_squared", id.r_squared}};

  // A snippet to paste into the job's robot section.
  std::ostringstream snippet;
  snippet << fmt::format(
      "# identified by robomill identify-stiffness from {} ({} tests, condition "
      "{:.3g}, RMS residual {:.3g} um)\n",
      options.data_file.filename().string(), tests.size(), id.condition_number,
      id.rms_residual_m * 1e6);
  snippet << "joint_stiffness: [";
  for (int j = 0; j < model.dof(); ++j)
    snippet << (j ? ", " : "") << fmt::format("{:.4g}", id.stiffness_nm_per_rad[j]);
  snippet << "]   # N*m/rad\n";

  CommandResult result;
  result.tables.emplace_back("fit", std::move(fit));
  result.texts.emplace_back("joint_stiffness.yaml", snippet.str());
  result.summary = summary;
  std::string& message = result.message;
  message = fmt::format(
      "joint stiffness of {} from {} loading tests (condition {:.3g}, RMS "
      "residual {:.3g} um, R² {:.6f}):\n",
      model.name(), tests.size(), id.condition_number, id.rms_residual_m * 1e6, id.r_squared);
  for (int j = 0; j < model.dof(); ++j) {
    const double k = id.stiffness_nm_per_rad[j];
    message +=
        fmt::format("  joint {}: {:.4g} N*m/rad, standard error {:.2f} %  (job: {:.4g})\n", j + 1,
                    k, 100.0 * id.stiffness_standard_error_nm_per_rad[j] / k, prior[j]);
  }
  return result;
}

}  // namespace robomill::commands
