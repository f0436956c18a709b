#include "robomill/analysis/cutting_parameter_advice.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "robomill/analysis/structure.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"
#include "robomill/robot/joint_dynamics.hpp"
#include "robomill/robot/kinematics.hpp"
#include "robomill/stability/lobes.hpp"

namespace robomill::analysis {
namespace {

Eigen::VectorXd seed_posture(const job::Job& job, const robot::RobotModel& robot) {
  if (job.robot->posture_rad.empty())
    return Eigen::VectorXd::Zero(robot.dof());
  return Eigen::Map<const Eigen::VectorXd>(job.robot->posture_rad.data(), robot.dof());
}

/// The job's path placed at workpiece.pose (004 Eq 7).
std::vector<planning::PlacedPoint> placed_path(const job::Job& job) {
  std::vector<planning::PlacedPoint> points;
  for (const planning::PathPoint& p : job.path)
    points.push_back(planning::place(job.workpiece->cell, *job.workpiece->pose, p));
  return points;
}

/// The robot's tool-tip modes (cutting frame) at every path point, the robot
/// turned by ψ about the tool axis; an unreachable point is an input error.
std::vector<dynamics::ModalModel> path_stations(const job::Job& job,
                                                const robot::RobotModel& robot) {
  const std::vector<planning::PlacedPoint> points = placed_path(job);
  const double psi = job.advise->redundancy_angle_rad;
  std::vector<dynamics::ModalModel> stations;
  for (std::size_t i = 0; i < points.size(); ++i) {
    Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
    target.translation() = points[i].position_m;
    target.linear() =
        points[i].tool_to_cell * Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()).matrix();
    const robot::IkResult ik = robot::inverse_kinematics(robot, target, seed_posture(job, robot));
    if (ik.position_residual_m > 1e-7 || ik.orientation_residual_rad > 1e-6 ||
        !robot.within_limits(ik.q)) {
      const Eigen::Vector3d x = points[i].position_m * 1e3;
      throw InputError(
          "path", 0,
          fmt::format("point {} of {} at [{:.1f}, {:.1f}, {:.1f}] mm (cell frame) is "
                      "not reachable at redundancy angle {:g} deg within the joint "
                      "limits (IK leaves {:.3g} mm, {:.3g} deg)",
                      i + 1, points.size(), x.x(), x.y(), x.z(), psi * kDegPerRad,
                      ik.position_residual_m * 1e3, ik.orientation_residual_rad * kDegPerRad));
    }
    stations.push_back(
        robot::tool_tip_modal_model(robot, ik.q, points[i].tool_to_cell.transpose()));
  }
  return stations;
}

/// Floquet methods step in time: two steps per period of the highest mode.
void check_advise_discretization(const job::Job& job,
                                 const std::vector<dynamics::ModalModel>& stations) {
  const job::AdviseSettings& s = *job.advise;
  if (s.limit.method == planning::LimitMethod::zoa)
    return;
  double highest_hz = 0.0;
  for (const auto& station : stations)
    highest_hz = std::max(highest_hz, station.highest_frequency_hz());
  const double tau = 2.0 * std::numbers::pi / (job.tool->teeth * s.limits.speed_min_rad_s);
  const double needed = std::ceil(2.0 * highest_hz * tau * (1.0 - 1e-12));
  if (s.limit.discretization < needed)
    throw InputError("advise.discretization", 0,
                     fmt::format("{} steps per tooth period are too coarse for the {:g} Hz mode "
                                 "of the structure: at least {:.0f} needed (or method: zoa)",
                                 s.limit.discretization, highest_hz, needed));
}

}  // namespace

std::optional<robot::RobotModel> advice_robot(const job::Job& job) {
  const job::AdviseSettings& settings = *job.advise;
  if (!job.robot || !(settings.along_path || settings.redundancy))
    return std::nullopt;
  try {
    return robot::RobotModel(job.robot->description);
  } catch (const std::invalid_argument& error) {
    throw InputError("robot", 0, error.what());
  }
}

std::vector<dynamics::ModalModel> advice_stations(const job::Job& job,
                                                  const std::optional<robot::RobotModel>& robot) {
  const job::AdviseSettings& settings = *job.advise;
  std::vector<dynamics::ModalModel> stations;
  try {
    if (settings.along_path)
      stations = path_stations(job, *robot);
    else
      stations.push_back(analysis::structure_modes(job));
  } catch (const std::invalid_argument& error) {
    throw InputError(settings.along_path ? "advise.along" : "dynamics", 0, error.what());
  }
  check_advise_discretization(job, stations);
  return stations;
}

CuttingParameterAdvice cutting_parameter_advice(const job::Job& job, int threads) {
  if (!job.advise)
    throw InputError("advise", 0,
                     "required: the advise: section (spindle range, depth step, margin, offset "
                     "limit)");
  const job::AdviseSettings& settings = *job.advise;
  const auto start = std::chrono::steady_clock::now();
  CuttingParameterAdvice result;

  std::optional<robot::RobotModel>& robot = result.robot;
  robot = advice_robot(job);
  std::vector<dynamics::ModalModel>& stations = result.stations;
  stations = advice_stations(job, robot);

  const tool::Tool cutter(*job.tool);
  planning::AdviceOptions advice_options;
  advice_options.limit = settings.limit;
  advice_options.peaks = settings.peaks;
  advice_options.threads = threads;
  result.advice = planning::advise_cutting(cutter, *job.cutting, *job.process, stations,
                                           settings.limits, advice_options);

  if (settings.redundancy) {
    std::vector<planning::PlacedPoint> points;
    if (!job.path.empty() && job.workpiece && job.workpiece->pose) {
      points = placed_path(job);
    } else {
      const Eigen::Isometry3d pose = robot::tool_pose(*robot, seed_posture(job, *robot));
      points.push_back({pose.translation(), pose.linear()});
    }
    planning::RedundancyOptions study_options;
    study_options.angles_rad = settings.redundancy->angles_rad;
    study_options.spindle_rad_s =
        settings.redundancy->at_spindle
            ? std::vector<double>{job.process->spindle_rad_s}
            : stability::linear_range(settings.limits.speed_min_rad_s,
                                      settings.limits.speed_max_rad_s, settings.limits.speed_count);
    study_options.limit = settings.limit;
    study_options.threads = threads;
    result.redundancy =
        planning::redundancy_study(*robot, points, seed_posture(job, *robot), cutter, *job.cutting,
                                   *job.process, study_options);
  }
  result.elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace robomill::analysis
