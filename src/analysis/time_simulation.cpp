#include "robomill/analysis/time_simulation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "robomill/analysis/process_damping.hpp"
#include "robomill/analysis/structure.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"
#include "robomill/cutting/engagement.hpp"
#include "robomill/robot/joint_dynamics.hpp"
#include "robomill/robot/kinematics.hpp"
#include "robomill/robot/reduced_model.hpp"

namespace robomill::analysis {
namespace {

/// 002 Eq 23 through its modal decomposition: the reduced model's (3-D,
/// translational, for robots with fewer than six joints)
/// mass-normalized modes (Mr, Kr, Dr at robot.posture), their translational
/// part rotated into the tool frame, ζ from the robot's joint damping or
/// simulation.damping_ratio where the robot has none.
dynamics::ModalModel reduced_modes(const job::Job& job, const job::SimulationSettings& s) {
  if (job.robot->posture_rad.empty())
    throw InputError("robot.posture", 0, "required with simulation.model: reduced6d");
  try {
    const robot::RobotModel model(job.robot->description);
    const Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(
        job.robot->posture_rad.data(), static_cast<Eigen::Index>(job.robot->posture_rad.size()));
    // 6-D where six joints make the tip compliance invertible, else the
    // translational 3-D reduction (as `robomill robot` reports it).
    const Eigen::MatrixXd jacobian = model.dof() >= 6
                                         ? Eigen::MatrixXd(robot::tool_jacobian(model, q))
                                         : robot::linear_jacobian(robot::tool_jacobian(model, q));
    Eigen::MatrixXd joint_damping;
    try {
      joint_damping = robot::joint_damping_matrix(model, q);
    } catch (const std::invalid_argument&) {
      joint_damping.resize(0, 0);
    }
    const robot::ReducedModel reduced = robot::reduce_model(
        jacobian, model.joint_stiffness(), robot::mass_matrix(model, q), joint_damping);
    const Eigen::Matrix3d to_tool = robot::tool_pose(model, q).linear().transpose();
    std::vector<dynamics::Mode> modes;
    double largest = 0.0;
    for (Eigen::Index i = 0; i < reduced.mode_shapes.cols(); ++i)
      largest = std::max(largest, reduced.mode_shapes.col(i).head<3>().norm());
    for (Eigen::Index i = 0; i < reduced.mode_shapes.cols(); ++i) {
      const Eigen::Vector3d shape = to_tool * reduced.mode_shapes.col(i).head<3>();
      if (!(shape.norm() > 1e-9 * largest))
        continue;  // a pure rotation of the tip: the force does not drive it
      double zeta = reduced.damping_ratios.size() > i ? reduced.damping_ratios(i) : 0.0;
      if (!(zeta > 0.0 && zeta < 1.0)) {
        if (!(s.damping_ratio > 0.0))
          throw InputError("simulation.damping_ratio", s.line,
                           "required with model reduced6d: the robot has no joint damping, so "
                           "give the modal damping ratio of the reduced modes (e.g. 0.05)");
        zeta = s.damping_ratio;
      }
      modes.push_back({reduced.natural_frequencies_hz(i), zeta, shape});
    }
    return dynamics::ModalModel(std::move(modes));
  } catch (const std::invalid_argument& error) {
    throw InputError("robot", 0, error.what());
  }
}

simulation::LinearStructure structure_of(const job::Job& job, const job::SimulationSettings& s) {
  switch (s.model) {
    case job::SimulationSettings::Model::rigid:
      return simulation::rigid_structure();
    case job::SimulationSettings::Model::fixation:
      return simulation::fixation_structure(s.mass_kg, s.damping_n_s_per_m, s.stiffness_n_per_m);
    case job::SimulationSettings::Model::reduced6d: {
      simulation::LinearStructure structure = simulation::modal_structure(reduced_modes(job, s));
      structure.description = "reduced robot model (002 Eq 23), " + structure.description;
      return structure;
    }
    case job::SimulationSettings::Model::modes:
      break;
  }
  return simulation::modal_structure(analysis::structure_modes(job));
}

std::string field_of(const std::string& key) {
  return "simulation." + key;
}

/// The checks that need the structure (and its natural frequencies): a step
/// fine enough for the highest mode and the engaged arc, a part the cutter
/// reaches, a run long enough for the metrics. Each names the field and the
/// value that would work. Returns the steps per tooth period to use: the
/// job's, or, when the job does not set them, the default raised to what the
/// structure and the cut need.
int check_settings(const job::Job& job, const job::SimulationSettings& s,
                   const simulation::LinearStructure& structure, const Eigen::VectorXd& frequencies,
                   const tool::Tool& cutter) {
  const cutting::MillingProcess& process = *job.process;
  const int teeth = cutter.teeth();
  const double tooth_period_s = kTwoPi / (process.spindle_rad_s * teeth);
  // At least 8 steps per period of the highest mode: the force is linearly
  // interpolated over a step, and the mode must see it resolved.
  int needed = 8;
  std::string why = "8 steps per tooth period";
  if (frequencies.size() > 0) {
    const double highest_hz = frequencies.maxCoeff();
    const int for_mode = static_cast<int>(std::ceil(8.0 * highest_hz * tooth_period_s));
    if (for_mode > needed) {
      needed = for_mode;
      why = fmt::format("8 steps per period of the highest mode ({:.4g} Hz)", highest_hz);
    }
  }
  // Enough steps across the engaged arc (the chip's entry and exit).
  const simulation::ArcResolution arc =
      simulation::engaged_arc_resolution(cutter, process, simulation::Workpiece{});
  if (arc.steps_per_tooth > needed) {
    needed = arc.steps_per_tooth;
    why = fmt::format("{} steps across the engaged arc of {:.1f} deg",
                      simulation::kStepsAcrossEngagedArc, arc.arc_rad * 180.0 / std::numbers::pi);
  }
  // Process damping is applied explicitly: its rate on the lightest direction
  // bounds the step (simulation::process_damping_step_limit_s).
  if (const std::optional<stability::LinearProcessDamping> damping = process_damping(s)) {
    const double limit_s =
        simulation::process_damping_step_limit_s(cutter, process, structure, *damping);
    const double for_damping = std::ceil(tooth_period_s / limit_s * (1.0 + 1e-12));
    if (for_damping > needed) {
      if (for_damping > 1e5)
        throw InputError(field_of("process_damping"), s.line,
                         fmt::format("the process damping is so strong for this structure that "
                                     "the step would need to be below {:.3g} s",
                                     limit_s));
      needed = static_cast<int>(for_damping);
      why = fmt::format("the process damping (rate {:.3g} 1/s on the lightest direction)",
                        1.0 / limit_s);
    }
  }
  const bool automatic = !s.steps_per_tooth_given;
  const int steps_per_tooth = automatic ? std::max(s.steps_per_tooth, needed) : s.steps_per_tooth;
  if (automatic && s.duration_s / tooth_period_s * steps_per_tooth / s.record_every > 2e7)
    throw InputError(field_of("record_every"), s.line,
                     fmt::format("{} steps per tooth period ({}) record more than 2e7 rows; raise "
                                 "record_every or shorten the run",
                                 steps_per_tooth, why));
  if (steps_per_tooth < needed)
    throw InputError(
        field_of("steps_per_tooth"), s.steps_line ? s.steps_line : s.line,
        fmt::format("{} steps per tooth period (step {:.3g} s) is too coarse: {} "
                    "needs steps_per_tooth: {} or more",
                    s.steps_per_tooth, tooth_period_s / s.steps_per_tooth, why, needed));

  const double feed_speed = process.feed_per_tooth_m / tooth_period_s;
  const double travel = feed_speed * s.duration_s;
  double engaged_s = 0.0;
  if (s.border_gap_m) {
    if (*s.border_gap_m >= travel)
      throw InputError(
          "simulation." + s.workpiece_key + ".border", s.border_line,
          fmt::format("the cutter never reaches the part: it travels {:.4g} mm in {:.4g} s at "
                      "{:.4g} mm/min, less than the {:.4g} mm gap; use a border below {:.4g} mm "
                      "or a duration above {:.4g} s",
                      travel * 1e3, s.duration_s, feed_speed * 6e4, *s.border_gap_m * 1e3,
                      travel * 1e3, *s.border_gap_m / feed_speed));
    engaged_s = (*s.border_gap_m + cutter.radius_m()) / feed_speed;
  }
  // The metrics: the steady window after full engagement, and at least three
  // periods of the lowest mode after it for the first frequency.
  double needed_s = engaged_s + s.steady_window_s;
  std::string what = fmt::format("full engagement at {:.4g} s plus the steady window of {:.4g} s",
                                 engaged_s, s.steady_window_s);
  if (frequencies.size() > 0 && frequencies.minCoeff() > 0.0) {
    const double for_frequency = engaged_s + 3.0 / frequencies.minCoeff();
    if (for_frequency > needed_s) {
      needed_s = for_frequency;
      what = fmt::format(
          "full engagement at {:.4g} s plus three periods of the lowest mode "
          "({:.4g} Hz)",
          engaged_s, frequencies.minCoeff());
    }
  }
  if (s.duration_s < needed_s * (1.0 - 1e-9))
    throw InputError(
        field_of(s.duration_key), s.duration_line ? s.duration_line : s.line,
        fmt::format("a run of {:.4g} s is too short for the metrics ({}): needs "
                    "duration: {:.4g} s ({} revolutions) or more",
                    s.duration_s, what, needed_s,
                    static_cast<long long>(std::ceil(needed_s * process.spindle_rad_s / kTwoPi))));
  return steps_per_tooth;
}

/// The spectrum (amplitudes, Hann window) of one recorded channel over the
/// steady window, from record `from`: the force's component `axis` (N), or
/// with `displacement` the displacement's, sampled in mm.
simulation::AmplitudeSpectrum steady_spectrum(const simulation::SimulationResult& result,
                                              std::size_t from, bool displacement, int axis) {
  std::vector<double> samples;
  for (std::size_t i = from; i + 1 < result.size(); ++i)
    samples.push_back(displacement ? result.displacement_m[i][axis] * 1e3
                                   : result.force_n[i][axis]);
  return simulation::amplitude_spectrum(samples, result.record_interval_s);
}

}  // namespace

TimeSimulation time_simulation(const job::Job& job) {
  job::require(job, {job::Section::tool, job::Section::cutting, job::Section::process});
  if (!job.simulation)
    throw InputError("simulation", 0,
                     "required: the simulation: section (duration or revolutions, steps_per_tooth, "
                     "model)");
  const job::SimulationSettings& s = *job.simulation;
  const auto start = std::chrono::steady_clock::now();
  const tool::Tool cutter(*job.tool);
  TimeSimulation simulated;
  simulated.structure = structure_of(job, s);
  const simulation::LinearStructure& structure = simulated.structure;
  simulated.natural_frequencies_hz = simulation::natural_frequencies_hz(structure);
  simulated.steps_per_tooth =
      check_settings(job, s, structure, simulated.natural_frequencies_hz, cutter);

  simulation::SimulationOptions run;
  run.duration_s = s.duration_s;
  run.steps_per_tooth = simulated.steps_per_tooth;
  run.axial_elements = s.axial_elements > 0
                           ? s.axial_elements
                           : cutting::default_axial_elements(cutter, job.process->axial_depth_m);
  run.start_angle_rad = s.start_angle_rad;
  run.record_every = s.record_every;
  run.process_damping = process_damping(s);
  simulated.axial_elements = run.axial_elements;
  simulation::Workpiece part;
  if (s.border_gap_m)
    part.border_x_m = cutter.radius_m() + *s.border_gap_m;
  simulated.result = simulation::simulate(cutter, *job.cutting, *job.process, structure, part, run);
  const simulation::SimulationResult& result = simulated.result;

  simulation::ResponseOptions& response = simulated.response_options;
  response.spindle_rad_s = job.process->spindle_rad_s;
  response.teeth = cutter.teeth();
  response.runout = cutter.runout().offset_m > 0.0;
  response.steady_window_s = s.steady_window_s;
  response.feed_per_tooth_m = job.process->feed_per_tooth_m;
  simulated.metrics = simulation::analyze_response(result, response);
  simulated.elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // Spectrum of the steady window.
  const std::size_t from = static_cast<std::size_t>(
      std::llround(simulated.metrics.steady_from_s / result.record_interval_s));
  for (int axis = 0; axis < 3; ++axis)
    simulated.force_spectra_n[axis] = steady_spectrum(result, from, false, axis);
  for (int axis = 0; axis < 3; ++axis)
    simulated.displacement_spectra_mm[axis] = steady_spectrum(result, from, true, axis);
  for (int n : result.teeth_cutting)
    simulated.max_teeth_cutting = std::max(simulated.max_teeth_cutting, n);
  return simulated;
}

}  // namespace robomill::analysis
