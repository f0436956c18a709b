// The robot along the program (include/robomill/robot_path/robot_along_path.hpp).

#include "robomill/robot_path/robot_along_path.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>
#include <tuple>
#include <variant>

#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"
#include "robomill/core/parallel.hpp"
#include "robomill/cutting/milling_forces.hpp"
#include "robomill/deflection/contact_boundary.hpp"
#include "robomill/deflection/deformed_engagement.hpp"
#include "robomill/deflection/node_compliance.hpp"
#include "robomill/robot/joint_dynamics.hpp"
#include "robomill/robot/kinematics.hpp"
#include "robomill/robot/stiffness.hpp"
#include "robomill/stability/regenerative_model.hpp"
#include "robomill/stability/zero_order.hpp"
#include "robomill/uncertainty/sample_statistics.hpp"

namespace robomill::robot_path {
namespace {

// An arc end within this of φ = 0 or π is a band edge: the dexel engagement
// resolves angles to a fraction of a degree.
constexpr double kBandEdgeRad = 2.0 * kPi / 180.0;

dynamics::ModalModel rotated(const dynamics::ModalModel& modes, const Eigen::Matrix3d& rotation) {
  std::vector<dynamics::Mode> out = modes.modes();
  for (dynamics::Mode& mode : out)
    mode.shape = rotation * mode.shape;
  return dynamics::ModalModel(std::move(out));
}

// The sample's milling frame in the workpiece frame: x the feed's part normal
// to the axis (any normal direction for a plunge), y = z × x, z the axis.
Eigen::Matrix3d milling_frame(const toolpath::PathSample& sample) {
  const Eigen::Vector3d axis = sample.axis.normalized();
  Eigen::Vector3d x = sample.feed_direction - sample.feed_direction.dot(axis) * axis;
  x = x.norm() < 1e-6 ? axis.unitOrthogonal() : x.normalized();
  Eigen::Matrix3d frame;
  frame.col(0) = x;
  frame.col(1) = axis.cross(x);
  frame.col(2) = axis;
  return frame;
}

const tool::Tool* find_tool(const toolpath::Tooling& tooling, int number) {
  auto it = tooling.find(number);
  if (it == tooling.end())
    it = tooling.find(0);
  return it == tooling.end() ? nullptr : &it->second;
}

// Runs of samples with the same tool, spindle speed and kind of engagement
// are interpolated; a change of any starts a new run.
enum class Band { down, up, slot, inside };

// The up-milling band [0, exit] of an arc (A0 of an inner arc is the
// difference of two of them).
cutting::MillingProcess up_band_process(double exit_rad, double radius_m, double spindle_rad_s,
                                        double feed_per_tooth_m) {
  cutting::MillingProcess process;
  process.spindle_rad_s = spindle_rad_s;
  process.feed_per_tooth_m = feed_per_tooth_m;
  process.direction = cutting::MillingDirection::up;
  process.radial_depth_m = std::clamp(radius_m * (1.0 - std::cos(exit_rad)), 1e-9, 2.0 * radius_m);
  return process;
}

Band band_of(const toolpath::PathSample& s) {
  const bool starts = s.entry_rad <= kBandEdgeRad;
  const bool ends = std::abs(s.exit_rad - kPi) <= kBandEdgeRad;
  return starts && ends ? Band::slot : ends ? Band::down : starts ? Band::up : Band::inside;
}

}  // namespace

std::optional<cutting::MillingProcess> band_process(double entry_rad, double exit_rad,
                                                    double tool_radius_m, double spindle_rad_s,
                                                    double feed_per_tooth_m) {
  cutting::MillingProcess process;
  process.spindle_rad_s = spindle_rad_s;
  process.feed_per_tooth_m = feed_per_tooth_m;
  const bool starts = entry_rad <= kBandEdgeRad;
  const bool ends = std::abs(exit_rad - kPi) <= kBandEdgeRad;
  if (starts && ends) {
    process.radial_depth_m = 2.0 * tool_radius_m;
  } else if (ends) {  // down milling: φ from π − acos(1 − ae/R) to π
    process.radial_depth_m = tool_radius_m * (1.0 + std::cos(entry_rad));
    process.direction = cutting::MillingDirection::down;
  } else if (starts) {  // up milling: φ from 0 to acos(1 − ae/R)
    process.radial_depth_m = tool_radius_m * (1.0 - std::cos(exit_rad));
    process.direction = cutting::MillingDirection::up;
  } else {
    return std::nullopt;
  }
  process.radial_depth_m = std::clamp(process.radial_depth_m, 1e-9, 2.0 * tool_radius_m);
  return process;
}

namespace {

// A0, or its basis in the coefficients, of a sample's engaged arc by
// `average(process)`: the arc's band as its straight cut, or an arc inside
// (0, π) as the up-milling band [0, b] less [0, a] (the period-averaged W is
// additive over the arc).
template <class Average>
auto arc_average(const toolpath::PathSample& sample, double radius_m, const Average& average) {
  const double spindle = std::abs(sample.spindle_rad_s);
  if (const auto band = band_process(sample.entry_rad, sample.exit_rad, radius_m, spindle,
                                     sample.feed_per_tooth_m))
    return average(*band);
  auto arc = average(up_band_process(sample.exit_rad, radius_m, spindle, sample.feed_per_tooth_m));
  arc -= average(up_band_process(sample.entry_rad, radius_m, spindle, sample.feed_per_tooth_m));
  return arc;
}

}  // namespace

PostureStructure robot_structure(const robot::RobotModel& model) {
  return [&model](const Eigen::VectorXd& q, const Eigen::Matrix3d& cell_to_milling) {
    return robot::tool_tip_modal_model(model, q, cell_to_milling);
  };
}

PostureStructure measured_postures_structure(
    const robot::RobotModel& model, std::vector<Eigen::VectorXd> postures_rad,
    std::vector<std::vector<robot::DirectionalModeParameters>> tables, robot::IdwOptions options) {
  if (postures_rad.empty() || postures_rad.size() != tables.size())
    throw std::invalid_argument("measured postures: one modal table per posture");
  return [&model, postures = std::move(postures_rad), tables = std::move(tables),
          options = std::move(options)](const Eigen::VectorXd& q,
                                        const Eigen::Matrix3d& cell_to_milling) {
    // 001 Eq 16-18 at q, then each directional mode (tool frame) as a
    // mass-normalized shape e ωn/√k turned into the milling frame.
    const auto table = robot::interpolate_modal_tables(postures, tables, q, options);
    const Eigen::Matrix3d tool_to_milling = cell_to_milling * robot::tool_pose(model, q).linear();
    std::vector<dynamics::Mode> modes;
    modes.reserve(table.size());
    for (const auto& m : table) {
      dynamics::Mode mode;
      mode.natural_frequency_hz = m.natural_frequency_hz;
      mode.damping_ratio = m.damping_ratio;
      mode.shape = tool_to_milling.col(m.axis) *
                   (2.0 * kPi * m.natural_frequency_hz / std::sqrt(m.stiffness_n_per_m));
      modes.push_back(mode);
    }
    return dynamics::ModalModel(std::move(modes));
  };
}

PostureStructure fixed_structure(const robot::RobotModel& model,
                                 dynamics::ModalModel tool_frame_modes) {
  return [&model, modes = std::move(tool_frame_modes)](const Eigen::VectorXd& q,
                                                       const Eigen::Matrix3d& cell_to_milling) {
    return rotated(modes, cell_to_milling * robot::tool_pose(model, q).linear());
  };
}

RobotAlongPath::RobotAlongPath(const robot::RobotModel& model, PostureStructure structure,
                               const toolpath::Tooling& tooling, const cutting::CuttingLaw& law,
                               PathStabilitySettings stability, RobotPathSettings settings)
    : model_(model),
      structure_(std::move(structure)),
      tooling_(tooling),
      law_(law),
      stability_(std::move(stability)),
      settings_(std::move(settings)) {
  if (settings_.seed_rad.size() != model_.dof())
    throw std::invalid_argument("robot along the path: the seed posture needs one angle per joint");
  if (model_.dof() > RobotSample::Joints::MaxRowsAtCompileTime)
    throw std::invalid_argument("robot along the path: at most 8 joints");
  if (!(settings_.tolerance > 0.0) || settings_.max_span < 1 || settings_.check_every < 0 ||
      !(settings_.risk_margin >= 1.0) || !structure_ ||
      !(settings_.max_chatter_probability > 0.0 && settings_.max_chatter_probability < 1.0) ||
      (settings_.offset.enabled && (settings_.offset.harmonics < 1 ||
                                    settings_.offset.samples < 2 * settings_.offset.harmonics + 1 ||
                                    settings_.offset.axial_elements < 0)))
    throw std::invalid_argument("robot along the path: inconsistent settings");
  seed_ = settings_.seed_rad;
  summary_.min_margin = std::numeric_limits<double>::infinity();
}

RobotSample RobotAlongPath::posture_at(const toolpath::PathSample& sample, double redundancy_rad,
                                       const Eigen::VectorXd& seed_rad) const {
  RobotSample out;
  const Eigen::Vector3d tip = settings_.workpiece_to_cell * sample.tip_m;
  const Eigen::Vector3d axis = (settings_.workpiece_to_cell.linear() * sample.axis).normalized();
  robot::IkOptions ik;
  ik.position_only = model_.dof() < 6;
  ik.position_tolerance_m = 1e-9;
  ik.orientation_tolerance_rad = 1e-9;
  ik.restarts = 0;  // follow the configuration of the sample before
  // A program that fixes the tool's rotation about its axis (a KRL frame)
  // sets ψ itself: the angle from ψ = 0's x (the cell's x normal to the
  // axis, robot::tool_orientation_about_axis) to the program's x.
  if (sample.oriented) {
    const Eigen::Vector3d x0 = robot::tool_orientation_about_axis(axis, 0.0).col(0);
    const Eigen::Vector3d x = settings_.workpiece_to_cell.linear() * sample.tool_x;
    redundancy_rad += std::atan2(x0.cross(x).dot(axis), x0.dot(x));
  }
  robot::IkResult solution =
      robot::inverse_kinematics_about_axis(model_, tip, axis, redundancy_rad, seed_rad, ik);
  if (!solution.converged) {
    ik.restarts = 8;
    solution =
        robot::inverse_kinematics_about_axis(model_, tip, axis, redundancy_rad, seed_rad, ik);
  }
  out.reachable = solution.converged;
  out.q_rad = solution.q;
  out.redundancy_rad = redundancy_rad;
  double margin = std::numeric_limits<double>::infinity();
  for (int j = 0; j < model_.dof(); ++j) {
    const auto& joint = model_.joints()[static_cast<std::size_t>(j)];
    margin = std::min({margin, solution.q[j] - joint.lower_rad, joint.upper_rad - solution.q[j]});
  }
  out.joint_margin_rad = margin;
  out.joint_limit = margin < settings_.joint_limit_margin_rad;
  // σ_min/σ_max of the Jacobian with angular rows in m per rad (1 m): 0 at a
  // singularity. A robot with fewer than 6 joints is judged on its linear rows.
  const Eigen::Matrix<double, 6, Eigen::Dynamic> jacobian =
      robot::tool_jacobian(model_, solution.q);
  const Eigen::MatrixXd used =
      model_.dof() < 6 ? Eigen::MatrixXd(jacobian.topRows<3>()) : Eigen::MatrixXd(jacobian);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(used);
  const Eigen::VectorXd sigma = svd.singularValues();
  out.singularity = sigma(0) > 0.0 ? sigma(sigma.size() - 1) / sigma(0) : 0.0;
  return out;
}

void RobotAlongPath::posture(const toolpath::PathSample& sample, RobotSample& out) {
  double psi = sample.oriented ? settings_.frame_turn_rad : settings_.redundancy_rad;
  if (sample.move < settings_.redundancy_by_move.size()) {
    // The schedule's angle; for a sample whose frame sets ψ, a turn of it.
    const auto [from, to] = settings_.redundancy_by_move[sample.move];
    psi = (sample.oriented ? settings_.frame_turn_rad : 0.0) + from +
          (to - from) * sample.move_fraction;
  }
  out = posture_at(sample, psi, seed_);
  if (out.reachable)
    seed_ = out.q_rad;
}

void RobotAlongPath::deflect(const toolpath::PathSample& sample, RobotSample& out) const {
  const tool::Tool* tool = find_tool(tooling_, sample.tool);
  if (!sample.analysed || !out.reachable || !tool || sample.kind == toolpath::MotionKind::rapid)
    return;
  const Eigen::Matrix3d to_cell = settings_.workpiece_to_cell.linear();
  const Eigen::Vector3d force_cell = to_cell * sample.force_mean_n;  // on the tool
  // The robot: its translational compliance at the tip (000 Eq 3 with Jc = Je).
  Eigen::Vector3d deflection_cell =
      robot::translational_compliance(model_, Eigen::VectorXd(out.q_rad)) * force_cell;
  // The tool: a cantilever clamped at the overhang, the mean force at the
  // middle of the engaged depth, the deflection read at the tip (000 Eq 1).
  const double length = tool->overhang_m();
  const double rigidity = deflection::flexural_rigidity_n_m2(
      tool->youngs_modulus_pa(), settings_.equivalent_diameter_fraction * tool->diameter_m());
  const double load_height = std::clamp(0.5 * sample.axial_depth_m, 0.0, length);
  const double tool_compliance =
      deflection::cantilever_influence_m_per_n(length, rigidity, 0.0, load_height);
  const Eigen::Vector3d axis_cell = (to_cell * sample.axis).normalized();
  const Eigen::Vector3d lateral = force_cell - force_cell.dot(axis_cell) * axis_cell;
  deflection_cell += tool_compliance * lateral;
  out.deflection_m = to_cell.transpose() * deflection_cell;

  // The finished surfaces. In robomill's angles (clockwise from +y of the
  // milling frame) an arc ending at φ = π leaves the wall at −y (down
  // milling), one starting at φ = 0 the wall at +y (up milling): the tool
  // moving away from that wall leaves material.
  const Eigen::Matrix3d frame = milling_frame(sample);
  const double lateral_y = out.deflection_m.dot(frame.col(1));
  const Band band = band_of(sample);
  out.wall = band != Band::inside && !sample.plunge;
  if (out.wall)
    out.wall_direction =
        band == Band::up ? Eigen::Vector3d(frame.col(1)) : Eigen::Vector3d(-frame.col(1));
  if (band == Band::down)
    out.form_error_m = lateral_y;
  else if (band == Band::up)
    out.form_error_m = -lateral_y;
  else if (band == Band::slot)
    out.form_error_m = lateral_y;  // one wall leaves what the other takes
  out.floor_error_m = out.deflection_m.dot(frame.col(2));
  if (settings_.contact.enabled && band == Band::down && !sample.plunge)
    contact_deflect(sample, *tool, frame, out);
}

// 000 §4's contact boundary at a down-milling wall: the setup of `robomill
// deflection` (analysis/deformation.cpp) with the sample's feed, radial depth and
// posture, the robot's compliance in the sample's milling frame. Node k
// generates the wall at height z_k (position K = k); ae,k = ae − ΔY,k (Eq
// 26), so ΔY > 0 leaves material, as the static form error's sign does.
void RobotAlongPath::contact_deflect(const toolpath::PathSample& sample, const tool::Tool& tool,
                                     const Eigen::Matrix3d& frame, RobotSample& out) const {
  const auto* linear = std::get_if<cutting::LinearLaw>(&law_);
  const double radius = 0.5 * tool.diameter_m();
  if (!linear || tool.type() != tool::ToolType::flat || !(sample.radial_width_m > 0.0) ||
      !(sample.radial_width_m < 2.0 * radius) || !(sample.axial_depth_m > 0.0) ||
      !(sample.feed_per_tooth_m > 0.0))
    return;
  deflection::DeflectionSetup setup;
  setup.tool_radius_m = radius;
  setup.helix_rad = tool.helix_rad();
  setup.overhang_m = tool.overhang_m();
  setup.flexural_rigidity_n_m2 = deflection::flexural_rigidity_n_m2(
      tool.youngs_modulus_pa(), settings_.equivalent_diameter_fraction * tool.diameter_m());
  setup.feed_per_tooth_m = sample.feed_per_tooth_m;
  setup.radial_depth_m = sample.radial_width_m;
  setup.law = *linear;
  setup.elements = settings_.contact.elements;
  setup.options.chip_correction = settings_.contact.chip_correction;
  setup.robot = std::shared_ptr<const robot::RobotModel>(std::shared_ptr<void>(), &model_);
  setup.posture_rad = out.q_rad;
  setup.cut_frame = settings_.workpiece_to_cell.linear() * frame;
  deflection::ContactBoundary boundary;
  try {
    boundary = deflection::solve_contact_boundary(
        deflection::contact_problem(setup, std::min(sample.axial_depth_m, tool.overhang_m())),
        setup.options);
  } catch (const NumericalError&) {
    return;  // no fixed point even relaxed: the static deflection stands
  }
  const Eigen::Vector2d tip = boundary.generating(1).deflection_m;
  double worst = 0.0;
  for (int k = 1; k <= static_cast<int>(boundary.positions.size()); ++k) {
    const double dy = boundary.generating(k).deflection_m.y();
    if (std::abs(dy) > std::abs(worst))
      worst = dy;
  }
  out.deflection_m = frame * Eigen::Vector3d(tip.x(), tip.y(), out.floor_error_m);
  out.form_error_m = worst;
  out.contact = true;
}

// The periodic force of a sample's engagement as 004 §4.2's Fourier series,
// once per cutter, arc, depth, feed and speed: a straight cut's samples
// share it. An arc that starts at φ = 0 or ends at π is the straight band of
// the cutting/process.hpp constructor (what `robomill optimize` builds from
// the job's process); any other arc is the general engagement over the
// depth.
std::shared_ptr<const planning::ForceHarmonics> RobotAlongPath::force_series(
    const tool::Tool& tool, const toolpath::PathSample& sample) const {
  const double depth = std::min(sample.axial_depth_m, tool.overhang_m());
  const double spindle = std::abs(sample.spindle_rad_s);
  const auto key = std::make_tuple(&tool, sample.entry_rad, sample.exit_rad, depth,
                                   sample.feed_per_tooth_m, spindle);
  {
    const std::lock_guard lock(force_mutex_);
    if (const auto it = force_cache_.find(key); it != force_cache_.end())
      return it->second;
  }
  const int elements = settings_.offset.axial_elements > 0
                           ? settings_.offset.axial_elements
                           : cutting::default_axial_elements(tool, depth);
  constexpr double kExact = 1e-9;  // the band's edge as the engagement gives it
  const double radius = 0.5 * tool.diameter_m();
  std::optional<cutting::MillingForceModel> model;
  const bool starts = sample.entry_rad <= kExact, ends = std::abs(sample.exit_rad - kPi) <= kExact;
  const bool band = (starts || ends) && starts == (sample.entry_rad <= kBandEdgeRad) &&
                    ends == (std::abs(sample.exit_rad - kPi) <= kBandEdgeRad);
  if (band) {
    cutting::MillingProcess process = *band_process(
        std::max(0.0, sample.entry_rad), sample.exit_rad, radius, spindle, sample.feed_per_tooth_m);
    process.axial_depth_m = depth;
    model.emplace(tool, law_, process, elements);
  } else {
    cutting::GeneralEngagement general;
    general.spindle_rad_s = spindle;
    general.feed_per_tooth_m = sample.feed_per_tooth_m;
    general.axial_depth_m = depth;
    general.slice_top_m = {depth};
    general.arcs = {{{sample.entry_rad, sample.exit_rad}}};
    model.emplace(tool, law_, general, elements);
  }
  auto series = std::make_shared<const planning::ForceHarmonics>(
      planning::force_harmonics(*model, settings_.offset.samples, settings_.offset.harmonics));
  const std::lock_guard lock(force_mutex_);
  constexpr std::size_t kMaxCached = 4096;  // a ramp's depths do not repeat
  if (force_cache_.size() < kMaxCached)
    force_cache_.emplace(key, series);
  return series;
}

// 004 Eq 1-2 at the sample's posture: the harmonic steady state of the
// robot's joint-space model under the force series turned from the
// sample's milling frame (004's R_ni: x the feed, z the tool axis) into the
// cell.
void RobotAlongPath::steady_offset(const toolpath::PathSample& sample, RobotSample& out) const {
  const tool::Tool* tool = find_tool(tooling_, sample.tool);
  if (!settings_.offset.enabled || !sample.analysed || !out.reachable || !tool ||
      sample.kind == toolpath::MotionKind::rapid || sample.plunge ||
      !(sample.axial_depth_m > 0.0) || !(sample.feed_per_tooth_m > 0.0) ||
      !(sample.exit_rad > sample.entry_rad))
    return;
  const std::shared_ptr<const planning::ForceHarmonics> series = force_series(*tool, sample);
  thread_local planning::OffsetWorkspace workspace;
  const planning::PostureDynamics dynamics =
      planning::posture_dynamics(model_, Eigen::VectorXd(out.q_rad));
  const Eigen::Matrix3d tool_to_cell = settings_.workpiece_to_cell.linear() * milling_frame(sample);
  const planning::OffsetMeasure measure = settings_.offset.measure;
  const planning::OffsetResponse response = planning::steady_state_offset(
      dynamics, tool_to_cell, *series, workspace, measure == planning::OffsetMeasure::startup);
  out.steady_offset_m = response.measure(measure);
  out.has_offset = true;
}

Eigen::Matrix3d RobotAlongPath::mean_stiffness(const tool::Tool& tool,
                                               const toolpath::PathSample& sample) const {
  // A0 depends on the cutter, the law, the engaged arc and (size-dependent
  // laws) the feed per tooth, never on the posture or the speed: the dexel
  // engagement gives few distinct arcs, so each is averaged once.
  const auto key =
      std::make_tuple(&tool, sample.entry_rad, sample.exit_rad, sample.feed_per_tooth_m);
  {
    const std::lock_guard lock(a0_mutex_);
    if (const auto it = a0_cache_.find(key); it != a0_cache_.end())
      return it->second;
  }
  const Eigen::Matrix3d a0 =
      arc_average(sample, 0.5 * tool.diameter_m(), [&](const cutting::MillingProcess& process) {
        return stability::mean_cutting_stiffness_per_depth(tool, law_, process);
      });
  const std::lock_guard lock(a0_mutex_);
  a0_cache_.emplace(key, a0);
  return a0;
}

Eigen::Matrix3d RobotAlongPath::draw_mean_stiffness(std::size_t draw, const tool::Tool& tool,
                                                    const toolpath::PathSample& sample) const {
  const auto key =
      std::make_tuple(&tool, sample.entry_rad, sample.exit_rad, sample.feed_per_tooth_m);
  const cutting::CuttingLaw& law = draws_[draw].law;
  const auto* linear = std::get_if<cutting::LinearLaw>(&law);
  {
    const std::lock_guard lock(a0_mutex_);
    if (linear) {
      if (const auto it = basis_cache_.find(key); it != basis_cache_.end())
        return it->second(*linear);
    } else if (const auto it = draw_a0_cache_[draw].find(key); it != draw_a0_cache_[draw].end()) {
      return it->second;
    }
  }
  const double radius = 0.5 * tool.diameter_m();
  if (linear) {
    // A0 is linear in (Ktc, Krc, Kac) (000 Eq 14): one basis per arc serves
    // every draw's coefficients.
    const stability::MeanCuttingStiffnessBasis basis =
        arc_average(sample, radius, [&](const cutting::MillingProcess& process) {
          return stability::mean_cutting_stiffness_basis(tool, law, process);
        });
    const std::lock_guard lock(a0_mutex_);
    return basis_cache_.emplace(key, basis).first->second(*linear);
  }
  const Eigen::Matrix3d a0 = arc_average(sample, radius, [&](const cutting::MillingProcess& p) {
    return stability::mean_cutting_stiffness_per_depth(tool, law, p);
  });
  const std::lock_guard lock(a0_mutex_);
  draw_a0_cache_[draw].emplace(key, a0);
  return a0;
}

std::vector<stability::ZeroOrderLimit> RobotAlongPath::limits_at(
    const toolpath::PathSample& sample, const Eigen::VectorXd& q_rad,
    const std::vector<double>& speeds_rad_s) const {
  return limits_with(sample, q_rad, speeds_rad_s, structure_, law_, stability_,
                     [&](const tool::Tool& tool) { return mean_stiffness(tool, sample); });
}

stability::ZeroOrderLimit RobotAlongPath::draw_limit(std::size_t draw,
                                                     const toolpath::PathSample& sample,
                                                     const Eigen::VectorXd& q_rad) const {
  if (draw >= draws_.size())
    throw std::invalid_argument("robot along the path: no such draw");
  const PathDraw& d = draws_[draw];
  return limits_with(
             sample, q_rad, {std::abs(sample.spindle_rad_s)}, d.structure, d.law, d.stability,
             [&](const tool::Tool& tool) { return draw_mean_stiffness(draw, tool, sample); })
      .front();
}

std::vector<stability::ZeroOrderLimit> RobotAlongPath::limits_with(
    const toolpath::PathSample& sample, const Eigen::VectorXd& q_rad,
    const std::vector<double>& speeds_rad_s, const PostureStructure& structure,
    const cutting::CuttingLaw& law, const PathStabilitySettings& settings,
    const std::function<Eigen::Matrix3d(const tool::Tool&)>& a0_of) const {
  const tool::Tool* tool = find_tool(tooling_, sample.tool);
  if (!tool)
    throw std::invalid_argument("robot along the path: no cutter for the sample's tool");
  const Eigen::Matrix3d cell_to_milling =
      (settings_.workpiece_to_cell.linear() * milling_frame(sample)).transpose();
  const dynamics::ModalModel modes = structure(q_rad, cell_to_milling);
  stability::ProcessDampedOptions options;
  options.zero_order.depth_max_m =
      settings.depth_max_m > 0.0 ? settings.depth_max_m : tool->overhang_m();
  options.method = settings.envelope ? stability::MultiModeMethod::envelope
                                     : stability::MultiModeMethod::coupled;
  options.threads = 1;
  const double radius = 0.5 * tool->diameter_m();
  const auto process = band_process(sample.entry_rad, sample.exit_rad, radius,
                                    std::abs(sample.spindle_rad_s), sample.feed_per_tooth_m);
  if (process && settings.process_damping) {
    // The straight cut of `robomill stability` with process damping (its
    // zero-order diagram): the damping needs the regenerative model itself.
    const stability::RegenerativeModel model(*tool, law, *process, modes);
    return stability::process_damped_limits(model, settings.process_damping, speeds_rad_s, options);
  }
  // Without process damping the zero-order limit needs only A0 and the modes
  // (process_damped_limits reduces to the same solver).
  const Eigen::Matrix3d a0 = a0_of(*tool);
  if (settings.envelope)
    return stability::envelope_limits(a0, tool->teeth(), modes, speeds_rad_s, options.zero_order);
  const stability::ZeroOrderSolver solver(a0, tool->teeth(), modes, options.zero_order);
  return solver.limits(speeds_rad_s);
}

stability::ZeroOrderLimit RobotAlongPath::direct_limit(const toolpath::PathSample& sample,
                                                       const Eigen::VectorXd& q_rad) const {
  return limits_at(sample, q_rad, {std::abs(sample.spindle_rad_s)}).front();
}

ShortcutChecks RobotAlongPath::limits(std::span<const toolpath::PathSample> samples,
                                      std::span<RobotSample> out) const {
  ShortcutChecks checks = shortcut_limits(
      samples, out,
      [this](const toolpath::PathSample& s, const Eigen::VectorXd& q) {
        return direct_limit(s, q);
      },
      settings_.threads);
  if (!draws_.empty())
    draw_limits(samples, out, checks);
  return checks;
}

ShortcutChecks RobotAlongPath::shortcut_limits(std::span<const toolpath::PathSample> samples,
                                               std::span<RobotSample> out, const LimitAt& limit_at,
                                               int threads) const {
  // The samples that get a limit, and the runs they form.
  ShortcutChecks totals;
  std::vector<std::size_t> index;
  if (!stability_.enabled)
    return totals;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const toolpath::PathSample& s = samples[i];
    if (s.analysed && out[i].reachable && !s.plunge && s.kind != toolpath::MotionKind::rapid &&
        s.axial_depth_m > 0.0 && s.spindle_rad_s != 0.0 && s.engaged_rad > 0.0 &&
        find_tool(tooling_, s.tool))
      index.push_back(i);
  }
  if (index.empty())
    return totals;
  std::vector<std::pair<std::size_t, std::size_t>> chunks;  // into `index`, inclusive
  const auto same_run = [&](std::size_t a, std::size_t b) {
    const toolpath::PathSample& x = samples[index[a]];
    const toolpath::PathSample& y = samples[index[b]];
    return index[b] == index[a] + 1 && x.tool == y.tool && x.spindle_rad_s == y.spindle_rad_s &&
           x.entry_rad == y.entry_rad && x.exit_rad == y.exit_rad && x.arcs == y.arcs &&
           x.feed_per_tooth_m == y.feed_per_tooth_m;
  };
  for (std::size_t start = 0; start < index.size();) {
    std::size_t end = start;
    while (end + 1 < index.size() && same_run(end, end + 1) &&
           end + 1 - start <= static_cast<std::size_t>(settings_.max_span))
      ++end;
    chunks.emplace_back(start, end);
    start = end + 1;
  }

  std::vector<char> exact(index.size(), 0);
  auto compute = [&](std::size_t k) {
    const std::size_t i = index[k];
    const stability::ZeroOrderLimit limit = limit_at(samples[i], Eigen::VectorXd(out[i].q_rad));
    out[i].depth_limit_m = limit.depth_limit_m;
    out[i].limited = limit.limited;
    out[i].chatter_frequency_hz = limit.chatter_frequency_hz;
    out[i].exact = true;
    exact[k] = 1;
  };
  auto interpolate = [&](std::size_t a, std::size_t b, std::size_t k) {
    const double t = static_cast<double>(k - a) / static_cast<double>(b - a);
    const RobotSample& x = out[index[a]];
    const RobotSample& y = out[index[b]];
    RobotSample& r = out[index[k]];
    r.depth_limit_m = x.depth_limit_m + t * (y.depth_limit_m - x.depth_limit_m);
    r.limited = x.limited || y.limited;
    r.chatter_frequency_hz = t < 0.5 ? x.chatter_frequency_hz : y.chatter_frequency_hz;
    if (x.limited && y.limited)
      r.chatter_frequency_hz =
          x.chatter_frequency_hz + t * (y.chatter_frequency_hz - x.chatter_frequency_hz);
    r.exact = false;
  };
  // Bisection: an interval is interpolated when its midpoint's exact limit
  // agrees with the interpolation to the tolerance, else split.
  std::function<void(std::size_t, std::size_t)> refine = [&](std::size_t a, std::size_t b) {
    if (b <= a + 1)
      return;
    const std::size_t m = (a + b) / 2;
    compute(m);
    const double exact_depth = out[index[m]].depth_limit_m;
    const double t = static_cast<double>(m - a) / static_cast<double>(b - a);
    const double guess = out[index[a]].depth_limit_m +
                         t * (out[index[b]].depth_limit_m - out[index[a]].depth_limit_m);
    if (std::abs(guess - exact_depth) <= settings_.tolerance * exact_depth) {
      for (std::size_t k = a + 1; k < b; ++k)
        if (k != m)
          interpolate(k < m ? a : m, k < m ? m : b, k);
      return;
    }
    refine(a, m);
    refine(m, b);
  };
  core::parallel_for(chunks.size(), threads, [&](std::size_t c) {
    const auto [a, b] = chunks[c];
    compute(a);
    if (b != a)
      compute(b);
    refine(a, b);
  });

  // The check: every n-th interpolated sample computed exactly as well.
  std::vector<std::size_t> checks;
  if (settings_.check_every > 0) {
    std::size_t interpolated = 0;
    for (std::size_t k = 0; k < index.size(); ++k)
      if (!exact[k] && interpolated++ % static_cast<std::size_t>(settings_.check_every) == 0)
        checks.push_back(k);
  }
  std::vector<double> errors(checks.size(), 0.0);
  core::parallel_for(checks.size(), threads, [&](std::size_t c) {
    const std::size_t i = index[checks[c]];
    const double shortcut = out[i].depth_limit_m;
    compute(checks[c]);
    errors[c] = std::abs(shortcut - out[i].depth_limit_m) / out[i].depth_limit_m;
  });
  totals.checked = checks.size();
  for (const double e : errors)
    totals.max_error = std::max(totals.max_error, e);
  for (std::size_t k = 0; k < index.size(); ++k) {
    RobotSample& r = out[index[k]];
    const toolpath::PathSample& s = samples[index[k]];
    r.stability = true;
    r.margin = r.depth_limit_m / s.axial_depth_m;
    r.chatter = s.axial_depth_m >= r.depth_limit_m;
    r.at_risk = s.axial_depth_m * settings_.risk_margin >= r.depth_limit_m;
    if (!r.chatter && !r.limited)
      r.chatter_frequency_hz = 0.0;
    totals.exact += exact[k] ? 1 : 0;
  }
  return totals;
}

void RobotAlongPath::evaluate(std::span<const toolpath::PathSample> samples,
                              std::span<RobotSample> out) {
  postures(samples, out);
  const ShortcutChecks checks = compute(samples, out);
  record(samples, out, checks);
}

void RobotAlongPath::postures(std::span<const toolpath::PathSample> samples,
                              std::span<RobotSample> out) {
  if (out.size() != samples.size())
    throw std::invalid_argument("robot along the path: one result per sample");
  // In order: each IK starts from the posture before.
  for (std::size_t i = 0; i < samples.size(); ++i) {
    out[i] = RobotSample{};
    posture(samples[i], out[i]);
  }
}

ShortcutChecks RobotAlongPath::compute(std::span<const toolpath::PathSample> samples,
                                       std::span<RobotSample> out) const {
  if (out.size() != samples.size())
    throw std::invalid_argument("robot along the path: one result per sample");
  core::parallel_for(samples.size(), settings_.threads, [&](std::size_t i) {
    deflect(samples[i], out[i]);
    steady_offset(samples[i], out[i]);
  });
  return limits(samples, out);
}

void RobotAlongPath::record(std::span<const toolpath::PathSample> samples,
                            std::span<const RobotSample> out, const ShortcutChecks& checks) {
  if (out.size() != samples.size())
    throw std::invalid_argument("robot along the path: one result per sample");
  summary_.exact_limits += checks.exact;
  summary_.checked += checks.checked;
  summary_.shortcut_max_error = std::max(summary_.shortcut_max_error, checks.max_error);
  if (!draws_.empty()) {
    if (checks.draw_chatter_samples.size() != draws_.size())
      throw std::invalid_argument("robot along the path: a block without its draws' counts");
    summary_.draw_exact_limits += checks.draw_exact;
    summary_.draw_shortcut_max_error =
        std::max(summary_.draw_shortcut_max_error, checks.draw_max_error);
    for (std::size_t d = 0; d < draws_.size(); ++d)
      summary_.draw_chatter_samples[d] += checks.draw_chatter_samples[d];
  }
  for (std::size_t i = 0; i < samples.size(); ++i)
    tally(samples[i], out[i]);
}

void RobotAlongPath::tally(const toolpath::PathSample& s, const RobotSample& r) {
  ++summary_.samples;
  summary_.contact_samples += r.contact ? 1 : 0;
  summary_.oriented_samples += s.oriented ? 1 : 0;
  const bool in_material = s.analysed && s.kind != toolpath::MotionKind::rapid;
  if (!r.reachable) {
    ++summary_.unreachable;
    if (summary_.first_unreachable_line == 0)
      summary_.first_unreachable_line = s.line;
    if (summary_.unreachable_lines.size() < 50 &&
        (summary_.unreachable_lines.empty() || summary_.unreachable_lines.back() != s.line))
      summary_.unreachable_lines.push_back(s.line);
    return;
  }
  const bool first = summary_.samples == summary_.unreachable + 1;  // the first reachable
  summary_.min_redundancy_rad =
      first ? r.redundancy_rad : std::min(summary_.min_redundancy_rad, r.redundancy_rad);
  summary_.max_redundancy_rad =
      first ? r.redundancy_rad : std::max(summary_.max_redundancy_rad, r.redundancy_rad);
  if (r.joint_limit) {
    ++summary_.joint_limit;
    if (summary_.first_joint_limit_line == 0)
      summary_.first_joint_limit_line = s.line;
  }
  if (r.singularity < summary_.min_singularity) {
    summary_.min_singularity = r.singularity;
    summary_.min_singularity_line = s.line;
  }
  if (!in_material)
    return;
  ++summary_.analysed;
  const double deflection = r.deflection_m.norm();
  summary_.max_deflection_m = std::max(summary_.max_deflection_m, deflection);
  summary_.max_floor_error_m = std::max(summary_.max_floor_error_m, std::abs(r.floor_error_m));
  if (std::abs(r.form_error_m) > summary_.max_form_error_m) {
    summary_.max_form_error_m = std::abs(r.form_error_m);
    summary_.max_form_error_line = s.line;
  }
  if (r.has_offset) {
    ++summary_.offset_samples;
    offset_sum_m_ += r.steady_offset_m;
    summary_.mean_offset_m = offset_sum_m_ / static_cast<double>(summary_.offset_samples);
    if (r.steady_offset_m > summary_.max_offset_m) {
      summary_.max_offset_m = r.steady_offset_m;
      summary_.max_offset_line = s.line;
    }
  }
  if (!r.stability)
    return;
  if (r.drawn)
    tally_draws(s, r);
  ++summary_.stability_samples;
  summary_.chatter += r.chatter ? 1 : 0;
  summary_.at_risk += r.at_risk ? 1 : 0;
  if (r.margin < summary_.min_margin) {
    summary_.min_margin = r.margin;
    summary_.min_margin_line = s.line;
  }
  // The worst sample of each line, a bounded list.
  const std::size_t keep = std::max<std::size_t>(1, settings_.worst_lines);
  auto same = std::find_if(worst_.begin(), worst_.end(),
                           [&](const Candidate& c) { return c.sample.line == s.line; });
  if (same != worst_.end()) {
    if (r.margin < same->robot.margin)
      *same = {s, r};
  } else if (worst_.size() < 4 * keep || r.margin < worst_.back().robot.margin) {
    worst_.push_back({s, r});
  } else {
    return;
  }
  std::sort(worst_.begin(), worst_.end(),
            [](const Candidate& a, const Candidate& b) { return a.robot.margin < b.robot.margin; });
  if (worst_.size() > 4 * keep)
    worst_.resize(4 * keep);
}

RobotPathSummary RobotAlongPath::finish() {
  close_line();
  if (!draws_.empty()) {
    const uncertainty::Estimate expected = uncertainty::sample_mean(summary_.draw_chatter_samples);
    summary_.expected_chatter_samples = expected.value;
    summary_.expected_chatter_samples_se = expected.standard_error;
  }
  RobotPathSummary summary = summary_;
  if (!std::isfinite(summary.min_margin))
    summary.min_margin = 0.0;
  const std::size_t count = std::min(worst_.size(), settings_.worst_lines);
  summary.worst_lines.resize(count);
  core::parallel_for(count, settings_.threads, [&](std::size_t k) {
    const Candidate& c = worst_[k];
    WorstLine& w = summary.worst_lines[k];
    w.line = c.sample.line;
    w.t_s = c.sample.t_s;
    w.margin = c.robot.margin;
    w.axial_depth_m = c.sample.axial_depth_m;
    w.depth_limit_m = c.robot.depth_limit_m;
    w.spindle_rad_s = std::abs(c.sample.spindle_rad_s);
    w.chatter_frequency_hz = c.robot.chatter_frequency_hz;
    w.form_error_m = c.robot.form_error_m;
    w.q_rad = c.robot.q_rad;
    // The advice: the speed of the range with the largest stable depth here.
    std::vector<double> speeds = stability_.advice_speeds_rad_s;
    if (speeds.empty()) {
      for (int i = 0; i <= 60; ++i)
        speeds.push_back(w.spindle_rad_s * (0.5 + i / 60.0));
    }
    w.better_spindle_rad_s = w.spindle_rad_s;
    w.better_depth_limit_m = w.depth_limit_m;
    for (const stability::ZeroOrderLimit& limit : limits_at(c.sample, w.q_rad, speeds)) {
      if (limit.depth_limit_m > w.better_depth_limit_m) {
        w.better_depth_limit_m = limit.depth_limit_m;
        w.better_spindle_rad_s = limit.spindle_rad_s;
      }
    }
  });
  return summary;
}

std::vector<Eigen::Vector3d> RobotAlongPath::joint_origins(const Eigen::VectorXd& q_rad) const {
  std::vector<Eigen::Vector3d> origins;
  const Eigen::Isometry3d base = model_.description().base;
  origins.push_back(base.translation());
  KDL::Frame frame = KDL::Frame::Identity();
  unsigned joint = 0;
  for (const KDL::Segment& segment : model_.chain().segments) {
    const bool moves = segment.getJoint().getType() != KDL::Joint::None;
    frame = frame * segment.pose(moves ? q_rad[joint] : 0.0);
    joint += moves ? 1 : 0;
    const Eigen::Vector3d p(frame.p.x(), frame.p.y(), frame.p.z());
    const Eigen::Vector3d cell = base * p;
    if ((cell - origins.back()).norm() > 1e-9)
      origins.push_back(cell);
  }
  return origins;
}

// The layout: the flags and scalars in RobotSample's order, the vectors'
// components, then q's size and q padded to `dof`.
constexpr std::size_t kPackedHead = 33;
std::size_t packed_size(int dof) {
  return kPackedHead + static_cast<std::size_t>(std::max(dof, 0));
}

void pack(const RobotSample& r, int dof, double* out) {
  const auto flag = [](bool b) { return b ? 1.0 : 0.0; };
  const double head[] = {flag(r.reachable),
                         r.redundancy_rad,
                         r.joint_margin_rad,
                         flag(r.joint_limit),
                         r.singularity,
                         flag(r.stability),
                         flag(r.exact),
                         r.depth_limit_m,
                         flag(r.limited),
                         r.margin,
                         flag(r.chatter),
                         flag(r.at_risk),
                         r.chatter_frequency_hz,
                         r.deflection_m.x(),
                         r.deflection_m.y(),
                         r.deflection_m.z(),
                         r.form_error_m,
                         r.floor_error_m,
                         flag(r.wall),
                         r.wall_direction.x(),
                         r.wall_direction.y(),
                         r.wall_direction.z(),
                         flag(r.contact),
                         r.steady_offset_m,
                         flag(r.has_offset),
                         flag(r.drawn),
                         r.p_chatter,
                         r.p_chatter_se,
                         r.depth_limit_q05_m,
                         r.depth_limit_q95_m,
                         r.depth_limit_at_bound_m,
                         flag(r.at_risk_drawn),
                         static_cast<double>(r.q_rad.size())};
  static_assert(std::size(head) == kPackedHead);
  std::copy(std::begin(head), std::end(head), out);
  for (int j = 0; j < dof; ++j)
    out[kPackedHead + j] = j < r.q_rad.size() ? r.q_rad[j] : 0.0;
}

RobotSample unpack(const double* in, int dof) {
  RobotSample r;
  r.reachable = in[0] != 0.0;
  r.redundancy_rad = in[1];
  r.joint_margin_rad = in[2];
  r.joint_limit = in[3] != 0.0;
  r.singularity = in[4];
  r.stability = in[5] != 0.0;
  r.exact = in[6] != 0.0;
  r.depth_limit_m = in[7];
  r.limited = in[8] != 0.0;
  r.margin = in[9];
  r.chatter = in[10] != 0.0;
  r.at_risk = in[11] != 0.0;
  r.chatter_frequency_hz = in[12];
  r.deflection_m = Eigen::Vector3d(in[13], in[14], in[15]);
  r.form_error_m = in[16];
  r.floor_error_m = in[17];
  r.wall = in[18] != 0.0;
  r.wall_direction = Eigen::Vector3d(in[19], in[20], in[21]);
  r.contact = in[22] != 0.0;
  r.steady_offset_m = in[23];
  r.has_offset = in[24] != 0.0;
  r.drawn = in[25] != 0.0;
  r.p_chatter = in[26];
  r.p_chatter_se = in[27];
  r.depth_limit_q05_m = in[28];
  r.depth_limit_q95_m = in[29];
  r.depth_limit_at_bound_m = in[30];
  r.at_risk_drawn = in[31] != 0.0;
  const int size = std::clamp(static_cast<int>(in[32]), 0, std::min(dof, 8));
  r.q_rad.resize(size);
  for (int j = 0; j < size; ++j)
    r.q_rad[j] = in[kPackedHead + j];
  return r;
}

}  // namespace robomill::robot_path
