#include "robomill/analysis/robot_path_setup.hpp"

#include <fmt/format.h>

#include <optional>
#include <stdexcept>
#include <utility>

#include "robomill/analysis/process_damping.hpp"
#include "robomill/analysis/structure.hpp"
#include "robomill/core/error.hpp"
#include "robomill/planning/workpiece_placement.hpp"
#include "robomill/stability/regenerative_model.hpp"

namespace robomill::analysis {

namespace {

// The structure at every posture, by the job's dynamics source.
void set_structure(const job::Job& job, const robot::RobotModel& model, RobotPathSetup& setup) {
  switch (job.dynamics_source) {
    case job::Job::DynamicsSource::robot:
      setup.structure = robot_path::robot_structure(model);
      setup.structure_source = "robot";
      break;
    case job::Job::DynamicsSource::postures: {
      const job::PostureLibrary& library = *job.posture_library;
      std::vector<std::vector<robot::DirectionalModeParameters>> tables;
      for (const auto& table : library.tables) {
        std::vector<robot::DirectionalModeParameters> t;
        for (const job::ModeSpec& m : table)
          t.push_back(
              {m.direction - 'x', m.natural_frequency_hz, m.damping_ratio, m.stiffness_n_per_m});
        tables.push_back(std::move(t));
      }
      setup.structure = robot_path::measured_postures_structure(model, library.postures_rad,
                                                                std::move(tables), library.idw);
      setup.structure_source = "postures";
      setup.notes.emplace_back(
          "the measured modal tables are interpolated at every sample's posture (001 Eq 16-18)");
      break;
    }
    case job::Job::DynamicsSource::table:
      if (job.modes.empty()) {
        setup.structure = robot_path::robot_structure(model);
        setup.structure_source = "robot";
        setup.notes.emplace_back(
            "no dynamics: section: the robot model's own modes at each posture");
        break;
      }
      [[fallthrough]];
    case job::Job::DynamicsSource::fit:
      setup.structure = robot_path::fixed_structure(model, structure_modes(job));
      setup.structure_source =
          job.dynamics_source == job::Job::DynamicsSource::fit ? "fit" : "table";
      setup.notes.emplace_back(
          "one modal table (tool frame) at every posture: the dynamics do not follow the robot");
      break;
    case job::Job::DynamicsSource::frf:
      throw InputError("dynamics.use", 0,
                       "is 'frf': the program analysis needs modes at each posture (use: fit, a "
                       "modal table, dynamics.postures or from_robot)");
  }
}

// Stability: the zero-order method at every sample, with the job's depth
// range, process damping and multi-mode method; off where the law is not
// linear.
void set_stability(const job::Job& job, RobotPathSetup& setup) {
  if (job.stability) {
    const job::StabilitySettings& s = *job.stability;
    setup.stability.depth_max_m = s.depth_max_m;
    setup.stability.envelope = s.modes == job::StabilitySettings::Modes::envelope;
    setup.stability.process_damping = process_damping(s);
    if (s.method != job::StabilitySettings::Method::zoa)
      setup.notes.emplace_back(
          "stability.method is for single cuts; along the program every sample's limit is the "
          "zero-order one (the semi-/full-discretization would take minutes per sample)");
    for (int i = 0; i < s.speed_count; ++i)
      setup.stability.advice_speeds_rad_s.push_back(
          s.speed_count == 1 ? s.speed_from_rad_s
                             : s.speed_from_rad_s + (s.speed_to_rad_s - s.speed_from_rad_s) * i /
                                                        (s.speed_count - 1));
  }
  // The regenerative model reduces the law to a linear one; other laws keep
  // the deflection but not the margin.
  try {
    cutting::MillingProcess probe;
    probe.spindle_rad_s = 1000.0;
    probe.feed_per_tooth_m = 1e-4;
    const tool::Tool tool =
        job.tool ? tool::Tool(*job.tool) : tool::Tool(job.toolpath->tools.begin()->second);
    probe.radial_depth_m = 0.25 * tool.diameter_m();
    (void)stability::RegenerativeModel(
        tool, *job.cutting, probe,
        dynamics::ModalModel({dynamics::Mode{100.0, 0.05, Eigen::Vector3d::UnitX()}}));
  } catch (const std::invalid_argument&) {
    setup.stability.enabled = false;
    setup.notes.emplace_back(
        "the cutting law is not linear: no chatter margin along the program (the regenerative "
        "model needs Ktc, Krc, Kac); the deflection is computed");
  }
}

}  // namespace

std::optional<RobotPathSetup> robot_path_setup(const job::Job& job, int threads) {
  const int line = job.robot_path ? job.robot_path->line : 0;
  if (!job.robot) {
    if (job.robot_path)
      throw InputError("robot_path", line,
                       "needs a robot: section (the robot that runs the program)");
    return std::nullopt;
  }
  if (!job.workpiece || !job.workpiece->pose) {
    if (job.robot_path)
      throw InputError("workpiece.pose", line,
                       "required with robot_path: where the part sits in the cell ([x, y, theta] "
                       "on the table of workpiece:)");
    return std::nullopt;
  }
  RobotPathSetup setup;
  try {
    setup.model = std::make_unique<robot::RobotModel>(job.robot->description);
  } catch (const std::invalid_argument& error) {
    throw InputError("robot", 0, error.what());
  }
  const robot::RobotModel& model = *setup.model;
  if (job.robot->posture_rad.empty())
    throw InputError("robot.posture", 0,
                     "required for the program: the posture the robot starts from (each sample's "
                     "inverse kinematics starts at the posture before it)");

  set_structure(job, model, setup);
  set_stability(job, setup);

  robot_path::RobotPathSettings& settings = setup.settings;
  settings.workpiece_to_cell = planning::workpiece_to_cell(
      job.workpiece->cell, job.workpiece->pose.value_or(planning::WorkpiecePose{}));
  settings.seed_rad = Eigen::Map<const Eigen::VectorXd>(
      job.robot->posture_rad.data(), static_cast<Eigen::Index>(job.robot->posture_rad.size()));
  settings.threads = threads;
  if (job.deflection && job.deflection->equivalent_diameter_m > 0.0) {
    setup.notes.emplace_back(
        "deflection.equivalent_diameter is for the job's tool; along the program each cutter's "
        "bending section is 0.8 × its diameter");
  }
  if (job.robot_path) {
    const job::RobotPathJobSettings& r = *job.robot_path;
    settings.redundancy_rad = r.redundancy_rad;
    settings.tolerance = r.tolerance;
    settings.max_span = r.max_span;
    settings.check_every = r.check_every;
    settings.risk_margin = r.risk_margin;
    settings.worst_lines = static_cast<std::size_t>(r.worst_lines);
    settings.max_chatter_probability = r.max_chatter_probability;
    // 000's contact boundary with the settings `robomill deflection` takes
    // from the job's deflection: section, so that a straight down-milling
    // cut reduces to that command at the sample's posture (the bending
    // section stays 0.8 × each cutter's diameter, as the note above says).
    settings.contact.enabled = r.contact_deflection;
    if (r.offset) {
      // The offset of `robomill optimize` (004 Eq 1-2): its measure and
      // series unless the section sets its own, and the job's force model.
      if (job.robot->description.dh && job.robot->description.dh->links.empty())
        throw InputError("robot_path.offset", r.offset->line,
                         "needs the robot's joint-space model: robot.links (masses, centres of "
                         "gravity, inertias) with joint_stiffness and damping_ratio");
      robot_path::RobotPathSettings::SteadyOffset& offset = settings.offset;
      offset.enabled = true;
      if (job.optimize) {
        offset.measure = job.optimize->measure;
        offset.harmonics = job.optimize->harmonics;
        offset.samples = job.optimize->samples;
      }
      offset.measure = r.offset->measure.value_or(offset.measure);
      offset.harmonics = r.offset->harmonics.value_or(offset.harmonics);
      offset.samples = r.offset->samples.value_or(offset.samples);
      if (offset.samples < 2 * offset.harmonics + 1)
        throw InputError("robot_path.offset.samples", r.offset->line,
                         fmt::format("must be at least 2 harmonics + 1 = {} (Nyquist), got {}",
                                     2 * offset.harmonics + 1, offset.samples));
      offset.axial_elements = job.forces.axial_elements;
    }
    if (job.deflection) {
      settings.contact.elements = job.deflection->elements;
      settings.contact.chip_correction = job.deflection->chip_correction;
    }
  }
  return setup;
}

std::vector<robot_path::PathDraw> RobotPathDraws::path_draws() const {
  std::vector<robot_path::PathDraw> out;
  out.reserve(setups.size());
  for (std::size_t i = 0; i < setups.size(); ++i)
    out.push_back({setups[i].structure, laws[i], setups[i].stability});
  return out;
}

RobotPathDraws robot_path_draws(const job::Job& job, int threads) {
  require_draws_keep_the_postures(job, "toolpath");
  job::require(job, {job::Section::cutting});
  RobotPathDraws out{draw_job_inputs(job), {}, {}};
  const auto n = static_cast<std::size_t>(out.draws.values.rows());
  std::vector<std::optional<RobotPathSetup>> setups(n);
  std::vector<std::optional<cutting::CuttingLaw>> laws(n);
  for_each_draw(out.draws, threads, [&](std::size_t i) {
    const job::Job drawn = job_of_draw(job, out.draws, i);
    setups[i] = robot_path_setup(drawn, 1);
    laws[i] = *drawn.cutting;
  });
  out.setups.reserve(n);
  out.laws.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!setups[i])
      throw std::invalid_argument("robot_path_draws: a job without a robot on its program");
    out.setups.push_back(std::move(*setups[i]));
    out.laws.push_back(std::move(*laws[i]));
  }
  return out;
}

}  // namespace robomill::analysis
