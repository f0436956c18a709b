#pragma once
// `robomill identify-stiffness` of a job: the joint stiffness Kq of the job's
// robot from static loading tests (000 §6.1, model 000 Eq 3), and — with
// --synthesize — the displacements such tests would measure on the job's
// robot, to plan a test (which postures and loads make Kq observable) or to
// check the method on data with known answers.
//
// Everything is in SI units; commands::compute_identify_stiffness reads the
// tests (DATA.csv) against loading_test_robot and turns the results into
// fit.csv, joint_stiffness.yaml and summary.json, or loading_tests.csv.

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "robomill/job/job.hpp"
#include "robomill/robot/robot_model.hpp"
#include "robomill/robot/stiffness.hpp"
#include "robomill/robot/stiffness_identification.hpp"

namespace robomill::analysis {

/// One static loading test (cell frame, loaded − unloaded).
struct LoadingTest {
  int test = 0;           ///< 1-based data row: "test N" in messages, fit.csv's test column
  Eigen::VectorXd q_rad;  ///< the posture
  /// The applied force (N), then the moment about the loaded point (N·m).
  robot::Vector6d wrench = robot::Vector6d::Zero();
  bool has_moment = false;  ///< a moment was given: the fit loads the joints with the wrench
  Eigen::Vector3d displacement_m = Eigen::Vector3d::Zero();  ///< measured, of the target
  /// The measured point (target ball) from the tool tip in the tool frame:
  /// Jc of 000 Eq 3.
  Eigen::Vector3d target_offset_tool_m = Eigen::Vector3d::Zero();
  /// Where the load acts, from the tool tip in the tool frame: Je of 000 Eq 3.
  Eigen::Vector3d load_offset_tool_m = Eigen::Vector3d::Zero();
};

/// The job's robot, whose joints the tests' postures and Kq refer to. Throws
/// InputError naming `robot` when the job has none, and RobotModel's
/// std::invalid_argument for an invalid description.
robot::RobotModel loading_test_robot(const job::Job& job);

/// Kq identified from loading tests.
struct JointStiffnessIdentification {
  /// Kq, its standard errors, the residuals and the problem's condition
  /// (robot/stiffness_identification.hpp).
  robot::StiffnessIdentification fit;
  Eigen::VectorXd job_stiffness_nm_per_rad;  ///< the job's Kq, N·m/rad, to compare with
  /// Per test (same order): the displacement the identified Kq predicts,
  /// Jc diag(c) Jeᵀ w (000 Eq 3), m.
  std::vector<Eigen::Vector3d> model_displacement_m;
};

/// Kq of `robot` from the tests by 000 Eq 3 (positions only; the moment
/// loads the joints when a test has one), refused above
/// `max_condition_number`. Throws InputError naming `data_file` when the tests
/// cannot identify Kq (robot::identify_joint_stiffness's reasons).
JointStiffnessIdentification joint_stiffness_from_tests(const robot::RobotModel& robot,
                                                        const std::vector<LoadingTest>& tests,
                                                        double max_condition_number,
                                                        const std::filesystem::path& data_file);

/// The displacement each test would measure (same order), m: 000 Eq 3 forward
/// with the job's Kq, plus Gaussian noise of `noise_relative` (in [0, 1])
/// times the test's displacement magnitude on every component (the "1 %
/// displacement noise" of a laser tracker); three deviates per test, in the
/// tests' order, from core::StandardNormal(seed).
std::vector<Eigen::Vector3d> synthesized_displacements_m(const robot::RobotModel& robot,
                                                         const std::vector<LoadingTest>& tests,
                                                         double noise_relative, std::uint32_t seed);

}  // namespace robomill::analysis
