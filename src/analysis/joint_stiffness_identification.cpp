#include "robomill/analysis/joint_stiffness_identification.hpp"

#include <stdexcept>

#include "robomill/core/error.hpp"
#include "robomill/core/random.hpp"
#include "robomill/robot/kinematics.hpp"

namespace robomill::analysis {

robot::RobotModel loading_test_robot(const job::Job& job) {
  job::require(job, {job::Section::robot});
  return robot::RobotModel(job.robot->description);
}

JointStiffnessIdentification joint_stiffness_from_tests(const robot::RobotModel& robot,
                                                        const std::vector<LoadingTest>& tests,
                                                        double max_condition_number,
                                                        const std::filesystem::path& data_file) {
  // 000 Eq 3 per test: Jc the measured point's Jacobian (the tool tip),
  // Je the loaded point's; displacements are positions only.
  std::vector<robot::StiffnessSample> samples;
  samples.reserve(tests.size());
  for (const LoadingTest& t : tests) {
    robot::StiffnessSample s;
    s.jacobian = robot::point_jacobian(robot, t.q_rad, t.target_offset_tool_m);
    if (t.load_offset_tool_m != t.target_offset_tool_m)
      s.force_jacobian = robot::point_jacobian(robot, t.q_rad, t.load_offset_tool_m);
    s.load = t.has_moment ? Eigen::VectorXd(t.wrench) : Eigen::VectorXd(t.wrench.head<3>());
    s.displacement_m = t.displacement_m;
    samples.push_back(std::move(s));
  }
  robot::StiffnessIdentificationOptions identification_options;
  identification_options.max_condition_number = max_condition_number;
  JointStiffnessIdentification result;
  try {
    result.fit = robot::identify_joint_stiffness(samples, identification_options);
  } catch (const std::invalid_argument& error) {
    // An ill-posed data set is a property of the input file.
    throw InputError(data_file.string(), 0, error.what());
  }
  result.job_stiffness_nm_per_rad = robot.joint_stiffness();

  result.model_displacement_m.reserve(samples.size());
  for (const robot::StiffnessSample& sample : samples) {
    // Model displacement with the identified Kq: Jc diag(c) Jeᵀ w.
    const Eigen::MatrixXd& je =
        sample.force_jacobian.size() ? sample.force_jacobian : sample.jacobian;
    const Eigen::VectorXd tau = je.topRows(sample.load.size()).transpose() * sample.load;
    const Eigen::Vector3d model_m =
        sample.jacobian.topRows<3>() * result.fit.compliance_rad_per_nm.cwiseProduct(tau);
    result.model_displacement_m.push_back(model_m);
  }
  return result;
}

std::vector<Eigen::Vector3d> synthesized_displacements_m(const robot::RobotModel& robot,
                                                         const std::vector<LoadingTest>& tests,
                                                         double noise_relative,
                                                         std::uint32_t seed) {
  std::vector<Eigen::Vector3d> displacements;
  displacements.reserve(tests.size());
  core::StandardNormal normal(seed);
  for (const LoadingTest& t : tests) {
    Eigen::Vector3d d = robot::deflection_between(robot, t.q_rad, t.target_offset_tool_m,
                                                  t.load_offset_tool_m, t.wrench)
                            .head<3>();
    const double sigma = noise_relative * d.norm();
    for (int k = 0; k < 3; ++k)
      d[k] += sigma * normal();
    displacements.push_back(d);
  }
  return displacements;
}

}  // namespace robomill::analysis
