#include "robomill/planning/redundancy_study.hpp"

#include <chrono>
#include <stdexcept>
#include <string>

#include "robomill/core/parallel.hpp"
#include "robomill/robot/joint_dynamics.hpp"
#include "robomill/robot/kinematics.hpp"
#include "robomill/stability/regenerative_model.hpp"

namespace robomill::planning {

RedundancyStudy redundancy_study(const robot::RobotModel& robot,
                                 const std::vector<PlacedPoint>& points,
                                 const Eigen::VectorXd& seed_posture_rad, const tool::Tool& tool,
                                 const cutting::CuttingLaw& law,
                                 const cutting::MillingProcess& process,
                                 const RedundancyOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (robot.dof() < 6)
    throw std::invalid_argument(
        "the robot has " + std::to_string(robot.dof()) +
        " joints: no rotation about the tool axis is free (a redundancy angle needs 6)");
  if (points.empty() || options.angles_rad.empty() || options.spindle_rad_s.empty())
    throw std::invalid_argument("redundancy_study: needs points, angles and speeds");

  const std::size_t angles = options.angles_rad.size();
  RedundancyStudy study;
  study.points.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    study.points[i].placed = points[i];
    study.points[i].samples.resize(angles);
  }
  robot::IkOptions ik;
  ik.position_tolerance_m = 0.1 * options.position_tolerance_m;
  ik.orientation_tolerance_rad = 0.1 * options.orientation_tolerance_rad;

  core::parallel_for(points.size() * angles, options.threads, [&](std::size_t item) {
    const std::size_t i = item / angles, a = item % angles;
    const PlacedPoint& point = points[i];
    RedundancySample& sample = study.points[i].samples[a];
    sample.angle_rad = options.angles_rad[a];
    Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
    target.translation() = point.position_m;
    target.linear() =
        point.tool_to_cell * Eigen::AngleAxisd(sample.angle_rad, Eigen::Vector3d::UnitZ()).matrix();
    const robot::IkResult result = robot::inverse_kinematics(robot, target, seed_posture_rad, ik);
    sample.q = result.q;
    sample.reachable = result.position_residual_m <= options.position_tolerance_m &&
                       result.orientation_residual_rad <= options.orientation_tolerance_rad &&
                       robot.within_limits(result.q);
    if (!sample.reachable)
      return;
    // The robot's modes in the cutting frame of the point (x feed, z axis).
    const dynamics::ModalModel modes =
        robot::tool_tip_modal_model(robot, result.q, point.tool_to_cell.transpose());
    sample.lowest_fn_hz = modes.highest_frequency_hz();
    for (const dynamics::Mode& mode : modes.modes())
      sample.lowest_fn_hz = std::min(sample.lowest_fn_hz, mode.natural_frequency_hz);
    const stability::RegenerativeModel model(tool, law, process, modes);
    const auto curve = limit_curve(model, options.spindle_rad_s, options.limit, 1);
    sample.min_limit_m = curve.front().depth_limit_m;
    sample.at_spindle_rad_s = curve.front().spindle_rad_s;
    for (const stability::LobePoint& p : curve) {
      if (p.depth_limit_m < sample.min_limit_m) {
        sample.min_limit_m = p.depth_limit_m;
        sample.at_spindle_rad_s = p.spindle_rad_s;
      }
    }
  });

  for (PointRedundancy& point : study.points) {
    for (std::size_t a = 0; a < angles; ++a) {
      const RedundancySample& s = point.samples[a];
      if (s.reachable &&
          (point.best < 0 || s.min_limit_m > point.samples[std::size_t(point.best)].min_limit_m))
        point.best = static_cast<int>(a);
    }
  }
  for (std::size_t a = 0; a < angles; ++a) {
    double weakest = INFINITY;
    int weakest_point = -1;
    for (std::size_t i = 0; i < study.points.size(); ++i) {
      const RedundancySample& s = study.points[i].samples[a];
      if (!s.reachable) {
        weakest_point = -1;
        break;
      }
      if (s.min_limit_m < weakest) {
        weakest = s.min_limit_m;
        weakest_point = static_cast<int>(i);
      }
    }
    if (weakest_point >= 0 && (study.best_constant < 0 || weakest > study.constant_min_limit_m)) {
      study.best_constant = static_cast<int>(a);
      study.constant_min_limit_m = weakest;
      study.constant_weakest_point = weakest_point;
    }
  }
  study.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return study;
}

}  // namespace robomill::planning
