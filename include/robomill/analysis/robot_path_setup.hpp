#pragma once
// From a job to the robot along its program (robot_path/robot_along_path.hpp):
// the robot model, the structure at each posture (the job's dynamics source),
// the stability settings of its `stability:` section, where the part sits
// (`workpiece`, 004 Eq 7) and the `robot_path:` tuning.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "robomill/analysis/job_draws.hpp"
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

/// The draws of the job's uncertain inputs (its uncertainty: section) on the
/// robot along its program (issue 33): each drawn job's setup and cutting
/// law, at the nominal postures.
struct RobotPathDraws {
  JobDraws draws;
  std::vector<RobotPathSetup> setups;  ///< per draw (its structure refers to its model)
  std::vector<cutting::CuttingLaw> laws;
  /// What RobotAlongPath::set_draws takes (refers to `setups`' models).
  std::vector<robot_path::PathDraw> path_draws() const;
};

/// Throws InputError naming the variable whose path would move the postures
/// or the cut (require_draws_keep_the_postures), or a draw the job refuses.
RobotPathDraws robot_path_draws(const job::Job& job, int threads);

}  // namespace robomill::analysis
