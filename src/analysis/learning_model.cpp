#include "robomill/analysis/learning_model.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "robomill/analysis/job_draws.hpp"
#include "robomill/analysis/stability_diagram.hpp"
#include "robomill/analysis/structure.hpp"
#include "robomill/core/error.hpp"
#include "robomill/planning/workpiece_placement.hpp"
#include "robomill/robot/joint_dynamics.hpp"
#include "robomill/robot/kinematics.hpp"
#include "robomill/robot/robot_model.hpp"
#include "robomill/stability/lobes.hpp"
#include "robomill/tool/tool.hpp"
#include "robomill/uncertainty/draws.hpp"

namespace robomill::analysis {
namespace {

using Settings = job::UncertaintySettings;

/// The smallest and largest u a quantile is asked for (as uncertainty::draw).
constexpr double kUnitMin = 0x1.0p-53, kUnitMax = 1.0 - 0x1.0p-53;

/// The modal table's row and field of "dynamics.modes[3].fn" (or
/// "dynamics.modes.3.fn"); false for any other path.
bool parse_mode_path(const std::string& path, int& row, std::string& field) {
  constexpr std::string_view prefix = "dynamics.modes";
  if (!path.starts_with(prefix))
    return false;
  std::string rest = path.substr(prefix.size());
  if (rest.empty() || (rest[0] != '[' && rest[0] != '.'))
    return false;
  rest.erase(0, 1);
  std::size_t digits = 0;
  while (digits < rest.size() && std::isdigit(static_cast<unsigned char>(rest[digits])))
    ++digits;
  if (digits == 0)
    return false;
  row = std::stoi(rest.substr(0, digits));
  rest.erase(0, digits);
  if (!rest.empty() && rest[0] == ']')
    rest.erase(0, 1);
  if (rest.empty() || rest[0] != '.')
    return false;
  field = rest.substr(1);
  return true;
}

/// The posture of experiments[index] from its `position` (the tool tip in
/// the workpiece frame, the tool along the workpiece's z): the tip and axis
/// placed by workpiece.pose (004 Eq 7), the rotation about the axis by
/// robot_path.redundancy, inverse kinematics from robot.posture, as the
/// robot along a program finds its postures.
std::vector<double> posture_at_position(const job::Job& job, const robot::RobotModel& model,
                                        std::size_t index) {
  const job::Experiment& e = job.experiments[index];
  const std::string field = fmt::format("experiments[{}].position", index);
  if (!job.workpiece || !job.workpiece->pose)
    throw InputError(field, e.line,
                     "needs workpiece.pose (and workpiece.table): where the part sits in the "
                     "cell, to place the tool tip");
  const Eigen::Isometry3d to_cell =
      planning::workpiece_to_cell(job.workpiece->cell, *job.workpiece->pose);
  const Eigen::Vector3d tip = to_cell * *e.position_m;
  const Eigen::Vector3d axis = to_cell.linear() * Eigen::Vector3d::UnitZ();
  const double redundancy_rad = job.robot_path ? job.robot_path->redundancy_rad : 0.0;
  const Eigen::VectorXd seed = Eigen::Map<const Eigen::VectorXd>(
      job.robot->posture_rad.data(), static_cast<Eigen::Index>(job.robot->posture_rad.size()));
  robot::IkOptions options;
  options.position_only = model.dof() < 6;
  options.position_tolerance_m = 1e-9;
  options.orientation_tolerance_rad = 1e-9;
  const robot::IkResult solution =
      robot::inverse_kinematics_about_axis(model, tip, axis, redundancy_rad, seed, options);
  if (!solution.converged)
    throw InputError(field, e.line,
                     fmt::format("the robot cannot reach [{:.1f}, {:.1f}, {:.1f}] mm of the "
                                 "workpiece with the tool along its z (closest: {:.3g} mm, "
                                 "{:.3g} deg off): check the position and workpiece.pose",
                                 1e3 * e.position_m->x(), 1e3 * e.position_m->y(),
                                 1e3 * e.position_m->z(), 1e3 * solution.position_residual_m,
                                 solution.orientation_residual_rad * 180.0 / std::numbers::pi));
  return std::vector<double>(solution.q.data(), solution.q.data() + solution.q.size());
}

}  // namespace

LearningModel::LearningModel(const job::Job& job) {
  job::require(job, {job::Section::tool, job::Section::cutting, job::Section::process,
                     job::Section::stability});
  if (!job.uncertainty)
    throw InputError("uncertainty", 0,
                     "learn updates the job's uncertain inputs: give an uncertainty: section "
                     "with the variables and their priors (docs/learning.md)");
  const Settings& u = *job.uncertainty;
  if (!u.posterior.empty())
    throw InputError("uncertainty.posterior", u.posterior_line,
                     "learn starts from the prior and every experiment: remove "
                     "uncertainty.posterior (give the variables' distributions)");
  const bool from_robot = job.dynamics_source == job::Job::DynamicsSource::robot;
  if (!from_robot && (job.dynamics_source != job::Job::DynamicsSource::table || job.modes.empty()))
    throw InputError("dynamics", 0,
                     "learn works on the modal table (dynamics.modes) or a robot's modes "
                     "(dynamics.from_robot) in this version; measured FRFs and fitted modes are "
                     "not yet learned");
  const auto* law = std::get_if<cutting::LinearLaw>(&*job.cutting);
  if (!law)
    throw InputError("cutting.law", 0, "learn needs the linear law (law: linear)");
  nominal_ = {*law, job.modes, Eigen::VectorXd(), 0.0};
  if (!from_robot)
    places_ = {{}};
  experiment_postures_.resize(job.experiments.size());
  if (from_robot)
    set_up_robot(job);
  teeth_ = job.tool->teeth;
  double deepest = job.stability->depth_max_m;
  for (const job::Experiment& e : job.experiments)
    deepest = std::max(deepest, e.axial_depth_m);
  search_depth_m_ = 1.25 * deepest;
  set_up_cuts(job);

  using F = Setter::Field;
  const std::vector<std::pair<std::string, F>> coefficients = {
      {"cutting.Ktc", F::ktc}, {"cutting.Krc", F::krc}, {"cutting.Kac", F::kac},
      {"cutting.Kte", F::kte}, {"cutting.Kre", F::kre}, {"cutting.Kae", F::kae}};
  for (std::size_t j = 0; j < u.variables.size(); ++j) {
    const Settings::Variable& v = u.variables[j];
    names_.push_back(v.name);
    priors_.emplace_back(
        std::visit([](const auto& p) { return uncertainty::Distribution(p); }, *v.distribution));
    for (const Settings::Target& t : v.targets) {
      Setter setter;
      setter.variable = static_cast<int>(j);
      setter.nominal = t.nominal_si;
      setter.scale = v.mode == Settings::Mode::scale;
      const auto coefficient = std::find_if(coefficients.begin(), coefficients.end(),
                                            [&](const auto& c) { return c.first == t.path; });
      int row = -1;
      std::string field;
      if (coefficient != coefficients.end()) {
        setter.field = coefficient->second;
      } else if (from_robot && t.path.starts_with("robot.joint_stiffness[")) {
        setter.field = F::joint_stiffness;
        setter.mode = std::stoi(t.path.substr(std::string("robot.joint_stiffness[").size()));
      } else if (from_robot && t.path == "robot.damping_ratio") {
        setter.field = F::robot_damping;
      } else if (!from_robot && parse_mode_path(t.path, row, field) &&
                 row < static_cast<int>(job.modes.size()) &&
                 (field == "fn" || field == "zeta" || field == "k")) {
        setter.mode = row;
        setter.field = field == "fn" ? F::fn : field == "zeta" ? F::zeta : F::k;
      } else {
        throw InputError(fmt::format("uncertainty.variables[{}].path", j), t.line,
                         fmt::format("'{}' (variable '{}'): learn varies the linear law's "
                                     "coefficients (cutting.Ktc, Krc, Kac, Kte, Kre, Kae), the "
                                     "modal table's fn, zeta and k (dynamics.modes[i].fn ...) or "
                                     "a robot's robot.joint_stiffness and robot.damping_ratio "
                                     "(with dynamics.from_robot) in this version",
                                     t.path, v.name));
      }
      setters_.push_back(setter);
    }
  }
  if (u.correlation)
    correlation_factor_ = uncertainty::correlation_factor(*u.correlation, dimension());
  check_against_the_job(job);
}

void LearningModel::set_up_robot(const job::Job& job) {
  if (!job.robot || job.robot->posture_rad.empty())
    throw InputError("robot.posture", 0,
                     "learn with dynamics.from_robot needs robot.posture (the experiments' "
                     "posture where they give none)");
  const robot::RobotDescription& d = job.robot->description;
  nominal_.joint_stiffness.resize(static_cast<Eigen::Index>(d.joints.size()));
  for (std::size_t j = 0; j < d.joints.size(); ++j) {
    if (d.joints[j].damping_nms_per_rad != robot::kDeriveDamping)
      throw InputError("robot.joints", 0,
                       "learn takes a robot's damping as one modal damping ratio "
                       "(robot.damping_ratio): remove the joints' own damping");
    nominal_.joint_stiffness(static_cast<Eigen::Index>(j)) = d.joints[j].stiffness_nm_per_rad;
  }
  nominal_.robot_damping_ratio = d.modal_damping_ratio;
  const auto add = [&](const std::vector<double>& posture) {
    if (std::find(places_.begin(), places_.end(), posture) == places_.end())
      places_.push_back(posture);
  };
  add(job.robot->posture_rad);
  try {
    const robot::RobotModel model(d);
    for (std::size_t i = 0; i < job.experiments.size(); ++i) {
      const job::Experiment& e = job.experiments[i];
      if (e.position_m)
        experiment_postures_[i] = posture_at_position(job, model, i);
      else if (!e.posture_rad.empty())
        experiment_postures_[i] = e.posture_rad;
      else if (e.hammer())
        throw InputError(fmt::format("experiments[{}].posture", i), e.line,
                         "a hammer test (frf:) on a robot needs the posture it was measured at "
                         "(posture: joint angles, or position: the tool tip in the workpiece "
                         "frame); the modes change with the posture");
      if (!experiment_postures_[i].empty())
        add(experiment_postures_[i]);
    }
    if (job.learn)
      for (const std::vector<double>& place : job.learn->places_rad)
        add(place);
    for (const std::vector<double>& posture : places_) {
      const Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(
          posture.data(), static_cast<Eigen::Index>(posture.size()));
      // The modes along the tool's own axes, as analysis::structure_modes.
      const Eigen::Matrix3d to_tool = robot::tool_pose(model, q).linear().transpose();
      robot_places_.push_back(
          {robot::mass_matrix(model, q), to_tool * robot::tool_jacobian(model, q).topRows<3>()});
    }
  } catch (const std::invalid_argument& error) {
    throw InputError("robot", 0, error.what());
  }
}

void LearningModel::set_up_cuts(const job::Job& job) {
  tool_.emplace(*job.tool);
  if (job.learn)
    method_ = job.learn->method;
  steps_ = job.stability->discretization;
  const auto add = [&](double radial_depth_m, cutting::MillingDirection direction) {
    for (const Cut& c : cuts_)
      if (c.process.radial_depth_m == radial_depth_m && c.process.direction == direction)
        return;
    cutting::MillingProcess process = *job.process;
    process.radial_depth_m = radial_depth_m;
    process.direction = direction;
    cuts_.push_back(
        {process, stability::mean_cutting_stiffness_basis(*tool_, *job.cutting, process)});
  };
  add(job.process->radial_depth_m, job.process->direction);
  for (const job::Experiment& e : job.experiments)
    if (!e.hammer())
      add(e.radial_depth_m.value_or(job.process->radial_depth_m),
          e.direction.value_or(job.process->direction));
}

int LearningModel::cut_of(const job::Experiment& test) const {
  const cutting::MillingProcess& own = cuts_.front().process;
  const double ae = test.radial_depth_m.value_or(own.radial_depth_m);
  const cutting::MillingDirection direction = test.direction.value_or(own.direction);
  for (std::size_t c = 0; c < cuts_.size(); ++c)
    if (cuts_[c].process.radial_depth_m == ae && cuts_[c].process.direction == direction)
      return static_cast<int>(c);
  throw std::invalid_argument("LearningModel::cut_of: not one of the cuts");
}

bool LearningModel::modes(const Eigen::VectorXd& x, int place,
                          std::vector<dynamics::Mode>& out) const {
  Structure structure;
  return apply(x, structure) && modes_at(structure, place, out);
}

int LearningModel::place_of(const std::vector<double>& posture_rad) const {
  if (posture_rad.empty())
    return 0;
  const auto it = std::find(places_.begin(), places_.end(), posture_rad);
  if (it == places_.end())
    throw std::invalid_argument("LearningModel::place_of: not one of the places");
  return static_cast<int>(it - places_.begin());
}

bool LearningModel::modes_at(const Structure& structure, int place,
                             std::vector<dynamics::Mode>& modes) const {
  modes.clear();
  if (robot_places_.empty()) {
    for (const job::ModeSpec& spec : structure.modes) {
      // As job::modal_model: the mass-normalized shape e ωn/√k.
      const double omega = 2.0 * std::numbers::pi * spec.natural_frequency_hz;
      modes.push_back({spec.natural_frequency_hz, spec.damping_ratio,
                       spec.direction_vector * (omega / std::sqrt(spec.stiffness_n_per_m))});
    }
    return true;
  }
  // K φ = ω² M φ with Φᵀ M Φ = I (robot::robot_modes), every mode damped by
  // the modal ratio; the tip's shape R Jv φ.
  const RobotPlace& at = robot_places_[static_cast<std::size_t>(place)];
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(
      Eigen::MatrixXd(structure.joint_stiffness.asDiagonal()), at.mass,
      Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
  if (solver.info() != Eigen::Success)
    return false;
  for (Eigen::Index i = 0; i < solver.eigenvalues().size(); ++i) {
    const double omega2 = solver.eigenvalues()(i);
    if (!(omega2 > 0.0))
      return false;
    modes.push_back({std::sqrt(omega2) / (2.0 * std::numbers::pi), structure.robot_damping_ratio,
                     at.tip_jacobian * solver.eigenvectors().col(i)});
  }
  return true;
}

Eigen::VectorXd LearningModel::values_of(const Eigen::VectorXd& w) const {
  const Eigen::VectorXd z = correlation_factor_ ? Eigen::VectorXd(*correlation_factor_ * w) : w;
  Eigen::VectorXd x(z.size());
  for (Eigen::Index j = 0; j < z.size(); ++j) {
    const double u = std::clamp(0.5 * std::erfc(-z(j) / std::numbers::sqrt2), kUnitMin, kUnitMax);
    x(j) = uncertainty::quantile(priors_[static_cast<std::size_t>(j)], u);
  }
  return x;
}

std::optional<cutting::LinearLaw> LearningModel::law_of(const Eigen::VectorXd& x) const {
  Structure structure;
  if (!apply(x, structure))
    return std::nullopt;
  return structure.law;
}

Eigen::VectorXd LearningModel::nominal_values() const {
  Eigen::VectorXd x = Eigen::VectorXd::Ones(dimension());
  for (const Setter& s : setters_) {
    if (!s.scale)
      x(s.variable) = s.nominal;
  }
  return x;
}

bool LearningModel::apply(const Eigen::VectorXd& x, Structure& out) const {
  out = nominal_;
  using F = Setter::Field;
  for (const Setter& s : setters_) {
    const double value = s.scale ? s.nominal * x(s.variable) : x(s.variable);
    if (!std::isfinite(value))
      return false;
    switch (s.field) {
      case F::ktc:
        out.law.Ktc_pa = value;
        break;
      case F::krc:
        out.law.Krc_pa = value;
        break;
      case F::kac:
        out.law.Kac_pa = value;
        break;
      case F::kte:
        out.law.Kte_n_per_m = value;
        break;
      case F::kre:
        out.law.Kre_n_per_m = value;
        break;
      case F::kae:
        out.law.Kae_n_per_m = value;
        break;
      case F::fn:
        out.modes[static_cast<std::size_t>(s.mode)].natural_frequency_hz = value;
        break;
      case F::zeta:
        out.modes[static_cast<std::size_t>(s.mode)].damping_ratio = value;
        break;
      case F::k:
        out.modes[static_cast<std::size_t>(s.mode)].stiffness_n_per_m = value;
        break;
      case F::joint_stiffness:
        out.joint_stiffness(s.mode) = value;
        break;
      case F::robot_damping:
        out.robot_damping_ratio = value;
        break;
    }
  }
  const cutting::LinearLaw& l = out.law;
  if (l.Ktc_pa < 0.0 || l.Krc_pa < 0.0 || l.Kac_pa < 0.0 || l.Kte_n_per_m < 0.0 ||
      l.Kre_n_per_m < 0.0 || l.Kae_n_per_m < 0.0)
    return false;
  if (!robot_places_.empty() &&
      (!(out.joint_stiffness.minCoeff() > 0.0) || !(out.robot_damping_ratio > 0.0) ||
       !(out.robot_damping_ratio < 1.0)))
    return false;
  return std::all_of(out.modes.begin(), out.modes.end(), [](const job::ModeSpec& m) {
    return m.natural_frequency_hz > 0.0 && m.damping_ratio > 0.0 && m.damping_ratio < 1.0 &&
           m.stiffness_n_per_m > 0.0;
  });
}

bool LearningModel::limits(const Eigen::VectorXd& x, int place, int cut,
                           std::span<const double> speeds_rad_s,
                           std::span<stability::ZeroOrderLimit> out) const {
  Structure structure;
  if (!apply(x, structure))
    return false;
  std::vector<dynamics::Mode> modes;
  if (!modes_at(structure, place, modes))
    return false;
  const Cut& cut_of_test = cuts_[static_cast<std::size_t>(cut)];
  if (method_ != job::StabilitySettings::Method::zoa) {
    // A time-domain limit (stability/lobes.hpp), on this thread: the
    // sampler runs the samples in parallel.
    stability::LobeOptions options;
    options.method = floquet_method(method_);
    options.steps = steps_;
    options.depth_max_m = search_depth_m_;
    options.threads = 1;
    const stability::RegenerativeModel regenerative(*tool_, cutting::CuttingLaw(structure.law),
                                                    cut_of_test.process,
                                                    dynamics::ModalModel(std::move(modes)));
    const std::vector<double> speeds(speeds_rad_s.begin(), speeds_rad_s.end());
    const std::vector<stability::LobePoint> points =
        stability::stability_boundary(regenerative, speeds, options);
    for (std::size_t s = 0; s < points.size(); ++s) {
      out[s] = stability::ZeroOrderLimit{};
      out[s].spindle_rad_s = points[s].spindle_rad_s;
      out[s].depth_limit_m = points[s].depth_limit_m;
      out[s].limited = points[s].limited;
      out[s].chatter_frequency_hz = points[s].chatter_frequency_hz;
    }
    return true;
  }
  // The grid only has to find each crossing (the limit is refined on the
  // exact eigenvalues): 40 points per peak and 100 elsewhere give the full
  // grid's limits (150 and 1500 points) to 1e-11 at all but 1 of 60 000
  // (300 prior draws of the anchor case × 200 speeds; with 30 per peak, 15
  // crossings are missed), at a third of the cost (docs/learning.md §2).
  stability::ZeroOrderOptions options;
  options.global_points = 100;
  options.points_per_peak = 40;
  options.depth_max_m = search_depth_m_;
  const stability::ZeroOrderSolver solver(cut_of_test.basis(structure.law), teeth_,
                                          dynamics::ModalModel(std::move(modes)), options);
  for (std::size_t s = 0; s < speeds_rad_s.size(); ++s)
    out[s] = solver.limit(speeds_rad_s[s]);
  return true;
}

void LearningModel::check_against_the_job(const job::Job& job) const {
  // Two prior draws, one either side of the median in every variable.
  JobDraws draws{names_, Eigen::MatrixXd(2, dimension()), "learn check"};
  for (int j = 0; j < dimension(); ++j) {
    const auto& prior = priors_[static_cast<std::size_t>(j)];
    draws.values(0, j) = uncertainty::quantile(prior, 0.31 + 0.01 * j);
    draws.values(1, j) = uncertainty::quantile(prior, 0.73 - 0.01 * j);
  }
  for (std::size_t i = 0; i < 2; ++i) {
    const job::Job drawn = job_of_draw(job, draws, i);
    Structure mine;
    if (!apply(draws.values.row(static_cast<Eigen::Index>(i)).transpose(), mine))
      continue;  // the re-read job refuses it too (job_of_draw threw otherwise)
    const auto close = [](double a, double b) {
      return std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b)) + 1e-300;
    };
    const auto& law = std::get<cutting::LinearLaw>(*drawn.cutting);
    bool same = close(law.Ktc_pa, mine.law.Ktc_pa) && close(law.Krc_pa, mine.law.Krc_pa) &&
                close(law.Kac_pa, mine.law.Kac_pa) && drawn.modes.size() == mine.modes.size();
    for (std::size_t m = 0; same && m < mine.modes.size(); ++m) {
      same = close(drawn.modes[m].natural_frequency_hz, mine.modes[m].natural_frequency_hz) &&
             close(drawn.modes[m].damping_ratio, mine.modes[m].damping_ratio) &&
             close(drawn.modes[m].stiffness_n_per_m, mine.modes[m].stiffness_n_per_m);
    }
    if (same && !robot_places_.empty()) {
      // The robot's modes at robot.posture, as every analysis builds them.
      const dynamics::ModalModel reread = structure_modes(drawn);
      const std::vector<dynamics::Mode>& theirs = reread.modes();
      std::vector<dynamics::Mode> modes;
      same = modes_at(mine, 0, modes) && modes.size() == theirs.size();
      const auto near = [](double a, double b) {
        return std::abs(a - b) <= 1e-6 * std::max(std::abs(a), std::abs(b)) + 1e-12;
      };
      for (std::size_t m = 0; same && m < modes.size(); ++m) {
        same = near(modes[m].natural_frequency_hz, theirs[m].natural_frequency_hz) &&
               near(modes[m].damping_ratio, theirs[m].damping_ratio) &&
               near(modes[m].shape.norm(), theirs[m].shape.norm()) &&
               near(std::abs(modes[m].shape.dot(theirs[m].shape)), modes[m].shape.squaredNorm());
      }
    }
    if (!same)
      throw InputError("uncertainty", job.uncertainty->line,
                       "learn sets the variables' fields directly, and for this job that does "
                       "not give what re-reading the job does (a mode given by its mass m or "
                       "its shape, whose k follows fn): give the modes learned with fn, zeta "
                       "and k");
  }
}

}  // namespace robomill::analysis
