#pragma once
// `robomill advise` of a job (issue 9 item 4): the spindle speed and axial
// depth that maximize the material removal rate inside the stability diagram
// (with the job's safety factor) and under the job's tool-offset limit
// (planning/cutting_advice.hpp), at the job's structure or at every point of
// its path (the robot's tool-tip modes there, 004 Eq 1-2 and Eq 7); and, with
// advise.redundancy, the rotation of a 6-joint robot about the tool axis
// that maximizes the minimum stable depth along the path
// (planning/redundancy_study.hpp). SI units.

#include <optional>
#include <vector>

#include "robomill/dynamics/modal_model.hpp"
#include "robomill/job/job.hpp"
#include "robomill/planning/cutting_advice.hpp"
#include "robomill/planning/redundancy_study.hpp"
#include "robomill/robot/robot_model.hpp"

namespace robomill::analysis {

struct CuttingParameterAdvice {
  /// The structures the advice holds for, tool frame: the job's (dynamics:)
  /// with advise.along: posture, else one per path point (the robot turned
  /// by advise.redundancy_angle about the tool axis).
  std::vector<dynamics::ModalModel> stations;
  planning::CuttingAdvice advice;
  /// The robot, when the advice needs it (along the path, redundancy).
  std::optional<robot::RobotModel> robot;
  /// advise.redundancy: per path point (or the robot's posture without a
  /// placed path) and candidate angle, the minimum stable depth.
  std::optional<planning::RedundancyStudy> redundancy;
  double elapsed_s = 0.0;  ///< the whole advice (structures, scan, redundancy)
};

/// The advice on up to `threads` threads (0: all cores). Needs the advise:
/// section (and what it names: tool, cutting, process, dynamics or a robot
/// with a placed path). Throws InputError naming the field: a path point the
/// robot does not reach within its joint limits, a discretization too coarse
/// for the structure's highest mode, settings the planner rejects.
CuttingParameterAdvice cutting_parameter_advice(const job::Job& job, int threads = 0);

/// The robot the advice needs (advise.along: path or advise.redundancy),
/// built from the job's robot: section; none otherwise. Throws InputError
/// naming `robot` when the description is refused. Needs the advise: section.
std::optional<robot::RobotModel> advice_robot(const job::Job& job);

/// The structures the advice holds for (CuttingParameterAdvice::stations):
/// the job's structure, or the robot's tool-tip modes at every path point.
/// Throws InputError naming the field (an unreachable point, a Floquet
/// discretization too coarse for the highest mode). Needs the advise:
/// section, and `robot` with advise.along: path.
std::vector<dynamics::ModalModel> advice_stations(const job::Job& job,
                                                  const std::optional<robot::RobotModel>& robot);

}  // namespace robomill::analysis
