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

#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <sstream>

#include "robomill/commands/commands.hpp"
#include "robomill/core/error.hpp"
#include "robomill/core/random.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/summary.hpp"
#include "robomill/robot/kinematics.hpp"
#include "robomill/robot/stiffness.hpp"
#include "robomill/robot/stiffness_identification.hpp"

namespace robomill::commands {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

/// One row of the data file, in SI.
struct LoadingTest {
  int line = 0;  ///< 1-based line number of the row in the file (header is 1)
  Eigen::VectorXd q;
  robot::Vector6d wrench = robot::Vector6d::Zero();  ///< force N, moment N·m
  bool has_moment = false;
  Eigen::Vector3d displacement_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d target_offset_tool_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d load_offset_tool_m = Eigen::Vector3d::Zero();
};

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
std::vector<LoadingTest> read_loading_tests(const std::filesystem::path& file,
                                            const robot::RobotModel& model, bool need_displacement,
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

  std::vector<LoadingTest> tests;
  for (std::size_t row = 0; row < data.rows(); ++row) {
    LoadingTest t;
    // read_csv skips blank and comment lines, so the row index is the best
    // position we can name: "test N" counts data rows from 1.
    t.line = static_cast<int>(row) + 1;
    t.q.resize(dof);
    for (int j = 0; j < dof; ++j) {
      const double degrees = data.at(row, q_columns[j]);
      const auto& joint = model.joints()[static_cast<std::size_t>(j)];
      t.q[j] = degrees / kDegPerRad;
      if (t.q[j] < joint.lower_rad - 1e-12 || t.q[j] > joint.upper_rad + 1e-12) {
        throw InputError(source, 0,
                         fmt::format("test {}: q{}_deg = {:g} is outside joint {}'s range [{:g}, "
                                     "{:g}] deg (angles are in degrees)",
                                     t.line, j + 1, degrees, j + 1, joint.lower_rad * kDegPerRad,
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
                       fmt::format("test {}: no load (force and moment are zero)", t.line));
    tests.push_back(std::move(t));
  }
  return tests;
}

/// --synthesize: 000 Eq 3 forward with the job's Kq, plus Gaussian noise of
/// `relative` times each test's displacement magnitude on every component
/// (the "1 % displacement noise" of a laser tracker).
io::CsvTable synthesize(const robot::RobotModel& model, const std::vector<LoadingTest>& tests,
                        double relative, std::uint32_t seed, bool with_moment) {
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
  core::StandardNormal normal(seed);
  for (const LoadingTest& t : tests) {
    Eigen::Vector3d d = robot::deflection_between(model, t.q, t.target_offset_tool_m,
                                                  t.load_offset_tool_m, t.wrench)
                            .head<3>();
    const double sigma = relative * d.norm();
    for (int k = 0; k < 3; ++k)
      d[k] += sigma * normal();
    std::vector<double> row;
    for (int j = 0; j < model.dof(); ++j)
      row.push_back(t.q[j] * kDegPerRad);
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

nlohmann::json vector_json(const Eigen::VectorXd& v) {
  nlohmann::json values = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i)
    values.push_back(v[i]);
  return values;
}

}  // namespace

CommandResult compute_identify_stiffness(const job::Job& job,
                                         const IdentifyStiffnessSettings& options) {
  job::require(job, {job::Section::robot});
  const robot::RobotModel model(job.robot->description);
  std::vector<std::string> columns;
  const std::vector<LoadingTest> tests =
      read_loading_tests(options.data_file, model, !options.synthesize, columns);

  if (options.synthesize) {
    if (!(options.noise >= 0.0) || !std::isfinite(options.noise) || options.noise > 1.0)
      throw InputError("--noise", 0, fmt::format("must lie in [0, 1], got {:g}", options.noise));
    const bool with_moment = std::find(columns.begin(), columns.end(), "mx_Nm") != columns.end();
    CommandResult result;
    result.tables.emplace_back("loading_tests",
                               synthesize(model, tests, options.noise, options.seed, with_moment));
    result.message =
        fmt::format("synthesized {} loading tests on {} (job Kq, {:g} % noise, seed {})",
                    tests.size(), model.name(), 100.0 * options.noise, options.seed);
    return result;
  }

  // 000 Eq 3 per test: Jc the measured point's Jacobian (the tool tip),
  // Je the loaded point's; displacements are positions only.
  std::vector<robot::StiffnessSample> samples;
  samples.reserve(tests.size());
  for (const LoadingTest& t : tests) {
    robot::StiffnessSample s;
    s.jacobian = robot::point_jacobian(model, t.q, t.target_offset_tool_m);
    if (t.load_offset_tool_m != t.target_offset_tool_m)
      s.force_jacobian = robot::point_jacobian(model, t.q, t.load_offset_tool_m);
    s.load = t.has_moment ? Eigen::VectorXd(t.wrench) : Eigen::VectorXd(t.wrench.head<3>());
    s.displacement_m = t.displacement_m;
    samples.push_back(std::move(s));
  }
  robot::StiffnessIdentificationOptions identification_options;
  identification_options.max_condition_number = options.max_condition;
  robot::StiffnessIdentification id;
  try {
    id = robot::identify_joint_stiffness(samples, identification_options);
  } catch (const std::invalid_argument& error) {
    // An ill-posed data set is a property of the input file.
    throw InputError(options.data_file.string(), 0, error.what());
  }

  const Eigen::VectorXd prior = model.joint_stiffness();
  io::CsvTable fit({"test", "dx_mm", "dy_mm", "dz_mm", "model_dx_mm", "model_dy_mm", "model_dz_mm",
                    "residual_um"});
  for (std::size_t i = 0; i < tests.size(); ++i) {
    const LoadingTest& t = tests[i];
    // Model displacement with the identified Kq: Jc diag(c) Jeᵀ w.
    const Eigen::MatrixXd& je =
        samples[i].force_jacobian.size() ? samples[i].force_jacobian : samples[i].jacobian;
    const Eigen::VectorXd tau = je.topRows(samples[i].load.size()).transpose() * samples[i].load;
    const Eigen::Vector3d model_m =
        samples[i].jacobian.topRows<3>() * id.compliance_rad_per_nm.cwiseProduct(tau);
    fit.add_row({static_cast<double>(t.line), t.displacement_m.x() * 1e3,
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
      {"joint_stiffness_Nm_per_rad", vector_json(id.stiffness_nm_per_rad)},
      {"standard_error_Nm_per_rad", vector_json(id.stiffness_standard_error_nm_per_rad)},
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
