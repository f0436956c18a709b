#include "robomill/deflection/deformed_engagement.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "robomill/core/error.hpp"
#include "robomill/core/parallel.hpp"
#include "robomill/deflection/node_compliance.hpp"

namespace robomill::deflection {

ContactProblem contact_problem(const DeflectionSetup& setup, double axial_depth_m) {
  ContactProblem problem;
  problem.tool_radius_m = setup.tool_radius_m;
  problem.helix_rad = setup.helix_rad;
  problem.feed_per_tooth_m = setup.feed_per_tooth_m;
  problem.radial_depth_m = setup.radial_depth_m;
  problem.axial_depth_m = axial_depth_m;
  problem.elements = setup.elements;
  problem.law = setup.law;
  const std::vector<double> heights = node_heights_m(axial_depth_m, setup.elements);
  const auto size = static_cast<Eigen::Index>(2 * heights.size());
  problem.compliance = Eigen::MatrixXd::Zero(size, size);
  if (std::isfinite(setup.flexural_rigidity_n_m2)) {
    if (axial_depth_m > setup.overhang_m * (1.0 + 1e-12)) {
      throw std::invalid_argument("the axial depth exceeds the tool overhang");
    }
    problem.compliance +=
        tool_node_compliance(heights, setup.overhang_m, setup.flexural_rigidity_n_m2);
  }
  if (setup.robot)
    problem.compliance +=
        setup.cut_frame
            ? robot_node_compliance(*setup.robot, setup.posture_rad, heights, *setup.cut_frame)
            : robot_node_compliance(*setup.robot, setup.posture_rad, heights);
  return problem;
}

DeformedEngagement::DeformedEngagement(const DeflectionSetup& setup, double depth_max_m, int count,
                                       int threads)
    : nominal_entry_rad_(deflection::entry_angle_rad(setup.tool_radius_m, setup.radial_depth_m)) {
  if (!(depth_max_m > 0.0) || count < 1)
    throw std::invalid_argument("deformed engagement: depth_max > 0 and count ≥ 1 needed");
  depths_m_.resize(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i)
    depths_m_[static_cast<std::size_t>(i)] = depth_max_m * (i + 1) / count;
  boundaries_.resize(depths_m_.size());
  core::parallel_for(depths_m_.size(), threads, [&](std::size_t i) {
    boundaries_[i] = solve_contact_boundary(contact_problem(setup, depths_m_[i]), setup.options);
  });
}

double DeformedEngagement::entry_at_grid(std::size_t index, double height_m) const {
  const ContactBoundary& b = boundaries_[index];
  const int nodes = static_cast<int>(b.positions.size());
  const double depth = depths_m_[index];
  const double step = depth / (nodes - 1);
  const double position = std::clamp(height_m / step, 0.0, static_cast<double>(nodes - 1));
  const int lower = std::min(static_cast<int>(position), nodes - 2);
  const double t = position - lower;
  return (1.0 - t) * b.generating(lower + 1).entry_rad + t * b.generating(lower + 2).entry_rad;
}

double DeformedEngagement::entry_angle_rad(double axial_depth_m, double height_m) const {
  if (!(axial_depth_m > 0.0))
    return nominal_entry_rad_;
  const auto upper = std::lower_bound(depths_m_.begin(), depths_m_.end(), axial_depth_m);
  if (upper == depths_m_.end())
    return entry_at_grid(depths_m_.size() - 1, height_m);
  const auto i = static_cast<std::size_t>(upper - depths_m_.begin());
  const double high = entry_at_grid(i, height_m);
  const double previous_depth = i == 0 ? 0.0 : depths_m_[i - 1];
  const double low = i == 0 ? nominal_entry_rad_ : entry_at_grid(i - 1, height_m);
  const double t = (axial_depth_m - previous_depth) / (depths_m_[i] - previous_depth);
  return low + t * (high - low);
}

}  // namespace robomill::deflection
