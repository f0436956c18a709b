#pragma once
// The paper-004 case as the example job states it
// (examples/004_kr300_pose_optimization.yaml): the KR300-class 3-joint
// robot, the cutter, its force model and the workpiece-placement problem.
// Shared by the planning tests, the 004 validation and the planning
// benchmark, so that all three measure the same case.

#include <Eigen/Core>
#include <optional>
#include <string>

#include "robomill/cutting/milling_forces.hpp"
#include "robomill/job/job.hpp"
#include "robomill/planning/path_performance.hpp"
#include "robomill/robot/robot_model.hpp"
#include "robomill/tool/tool.hpp"

namespace robomill::test {

struct Case004 {
  job::Job job = job::load_job(std::string(ROBOMILL_SOURCE_DIR) +
                               "/examples/004_kr300_pose_optimization.yaml");
  robot::RobotModel robot{job.robot->description};
  tool::Tool cutter{*job.tool};
  cutting::MillingForceModel force{cutter, *job.cutting, *job.process,
                                   cutting::default_axial_elements(cutter, 2e-3)};

  /// The placement problem: the force's harmonics as the job's optimize:
  /// section samples them, the robot's posture as the IK seed, and the
  /// offset measure given (default: the job's).
  planning::PlacementProblem problem(
      std::optional<planning::OffsetMeasure> measure = std::nullopt) const {
    planning::PlacementProblem p;
    p.cell = job.workpiece->cell;
    p.path = job.path;
    p.force = planning::force_harmonics(force, job.optimize->samples, job.optimize->harmonics);
    p.seed_posture_rad = Eigen::Map<const Eigen::VectorXd>(job.robot->posture_rad.data(), 3);
    p.measure = measure.value_or(job.optimize->measure);
    return p;
  }
};

}  // namespace robomill::test
