#pragma once
// From a job to the robot along its program (robot_path/robot_along_path.hpp):
// the robot model, the structure at each posture (the job's dynamics source),
// the stability settings of its `stability:` section, where the part sits
// (`workpiece`, 004 Eq 7) and the `robot_path:` tuning.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "robomill/job/job.hpp"
#include "robomill/robot/robot_model.hpp"
#include "robomill/robot_path/feed_schedule.hpp"
#include "robomill/robot_path/robot_along_path.hpp"

namespace robomill::analysis {

struct RobotPathSetup {
  std::unique_ptr<robot::RobotModel> model;  ///< the structure functions refer to it
  robot_path::PostureStructure structure;
  robot_path::PathStabilitySettings stability;
  robot_path::RobotPathSettings settings;
  std::string structure_source;  ///< "robot", "postures", "table" or "fit"
  std::vector<std::string> notes;
};

/// The setup when the job puts a robot on its program (a `robot:` section and
/// `workpiece.pose`, or a `robot_path:` section); nullopt otherwise. Throws
/// InputError naming the missing or inconsistent field (robot_path without a
/// robot or a workpiece pose, a robot without a posture to start from, a
/// structure that cannot be had at every posture).
std::optional<RobotPathSetup> robot_path_setup(const job::Job& job, int threads);

}  // namespace robomill::analysis
