// Atlas items and their analyses (include/robomill/atlas/atlas.hpp).

#include "robomill/atlas/atlas.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <limits>
#include <stdexcept>

#include "robomill/robot/joint_dynamics.hpp"
#include "robomill/robot/kinematics.hpp"
#include "robomill/robot/stiffness.hpp"
#include "robomill/stability/zero_order.hpp"

namespace robomill::atlas {
namespace {

double coordinate(double from, double to, int count, int i) {
  return count == 1 ? from : from + (to - from) * i / (count - 1);
}

constexpr int kFixedFields = 10;

}  // namespace

std::int64_t item_count(const AtlasSpec& spec) {
  return static_cast<std::int64_t>(spec.counts[0]) * spec.counts[1] * spec.counts[2] *
         static_cast<std::int64_t>(spec.redundancy_rad.size());
}

AtlasItem item(const AtlasSpec& spec, std::int64_t id) {
  if (id < 0 || id >= item_count(spec))
    throw std::out_of_range("atlas item id out of range");
  const std::int64_t angles = static_cast<std::int64_t>(spec.redundancy_rad.size());
  const int ipsi = static_cast<int>(id % angles);
  std::int64_t point = id / angles;
  const int ix = static_cast<int>(point % spec.counts[0]);
  point /= spec.counts[0];
  const int iy = static_cast<int>(point % spec.counts[1]);
  const int iz = static_cast<int>(point / spec.counts[1]);
  AtlasItem result;
  result.id = id;
  result.position_m = {coordinate(spec.from_m.x(), spec.to_m.x(), spec.counts[0], ix),
                       coordinate(spec.from_m.y(), spec.to_m.y(), spec.counts[1], iy),
                       coordinate(spec.from_m.z(), spec.to_m.z(), spec.counts[2], iz)};
  result.redundancy_rad = spec.redundancy_rad[static_cast<std::size_t>(ipsi)];
  return result;
}

int packed_size(int dof) {
  return kFixedFields + dof;
}

void pack(const AtlasResult& r, int dof, double* out) {
  const double fixed[kFixedFields] = {r.reachable ? 1.0 : 0.0,
                                      r.lowest_frequency_hz,
                                      r.compliance_feed_m_per_n,
                                      r.compliance_normal_m_per_n,
                                      r.compliance_axial_m_per_n,
                                      r.condition_number,
                                      r.depth_min_m,
                                      r.speed_at_min_rad_s,
                                      r.depth_max_m,
                                      r.speed_at_max_rad_s};
  std::copy(fixed, fixed + kFixedFields, out);
  for (int j = 0; j < dof; ++j)
    out[kFixedFields + j] = r.q.size() == dof ? r.q[j] : 0.0;
}

AtlasResult unpack(const double* in, int dof) {
  AtlasResult r;
  r.reachable = in[0] != 0.0;
  r.lowest_frequency_hz = in[1];
  r.compliance_feed_m_per_n = in[2];
  r.compliance_normal_m_per_n = in[3];
  r.compliance_axial_m_per_n = in[4];
  r.condition_number = in[5];
  r.depth_min_m = in[6];
  r.speed_at_min_rad_s = in[7];
  r.depth_max_m = in[8];
  r.speed_at_max_rad_s = in[9];
  if (r.reachable)
    r.q = Eigen::Map<const Eigen::VectorXd>(in + kFixedFields, dof);
  return r;
}

AtlasContext::AtlasContext(const AtlasSpec& spec, const robot::RobotModel& model,
                           Eigen::VectorXd seed, const std::optional<tool::Tool>& tool,
                           const std::optional<cutting::CuttingLaw>& law,
                           const std::optional<cutting::MillingProcess>& process)
    : spec_(spec), model_(model), seed_(std::move(seed)) {
  if (seed_.size() != model.dof())
    throw std::invalid_argument("atlas: the seed posture needs one angle per joint");
  if (spec_.redundancy_rad.empty())
    throw std::invalid_argument("atlas: at least one redundancy angle");
  if (spec_.stability) {
    if (!tool || !law || !process)
      throw std::invalid_argument("atlas: stability needs the tool, cutting law and process");
    if (!(spec_.depth_max_m > 0.0) || spec_.speed_count < 1 || !(spec_.speed_from_rad_s > 0.0))
      throw std::invalid_argument("atlas: stability needs speeds and depth_max");
    a0_ = stability::mean_cutting_stiffness_per_depth(*tool, *law, *process);
    teeth_ = tool->teeth();
    for (int i = 0; i < spec_.speed_count; ++i) {
      speeds_rad_s_.push_back(spec_.speed_count == 1
                                  ? spec_.speed_from_rad_s
                                  : spec_.speed_from_rad_s +
                                        (spec_.speed_to_rad_s - spec_.speed_from_rad_s) * i /
                                            (spec_.speed_count - 1));
    }
  }
}

AtlasResult AtlasContext::evaluate(const AtlasItem& item) const {
  AtlasResult r;
  robot::IkOptions ik;
  ik.position_only = model_.dof() < 6;
  ik.position_tolerance_m = 1e-9;
  ik.orientation_tolerance_rad = 1e-9;
  const robot::IkResult solution = robot::inverse_kinematics_about_axis(
      model_, item.position_m, spec_.tool_axis, item.redundancy_rad, seed_, ik);
  if (!solution.converged)
    return r;
  r.reachable = true;
  r.q = solution.q;
  const Eigen::Vector3d normal = spec_.tool_axis.cross(spec_.feed);
  if (spec_.compliance) {
    const Eigen::Matrix3d c = robot::translational_compliance(model_, r.q);
    r.compliance_feed_m_per_n = spec_.feed.dot(c * spec_.feed);
    r.compliance_normal_m_per_n = normal.dot(c * normal);
    r.compliance_axial_m_per_n = spec_.tool_axis.dot(c * spec_.tool_axis);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(c);
    const double smallest = eigen.eigenvalues().minCoeff();
    r.condition_number = smallest > 0.0 ? eigen.eigenvalues().maxCoeff() / smallest : 0.0;
  }
  if (spec_.frequency)
    r.lowest_frequency_hz = robot::robot_modes(model_, r.q).natural_frequencies_hz.minCoeff();
  if (spec_.stability) {
    // The milling frame of the cut: x the feed, z the tool axis, fixed in the
    // cell whatever the redundancy angle turns the flange.
    Eigen::Matrix3d cell_to_tool;
    cell_to_tool.row(0) = spec_.feed.transpose();
    cell_to_tool.row(1) = normal.transpose();
    cell_to_tool.row(2) = spec_.tool_axis.transpose();
    const dynamics::ModalModel modes = robot::tool_tip_modal_model(model_, r.q, cell_to_tool);
    stability::ZeroOrderOptions options;
    options.depth_max_m = spec_.depth_max_m;
    const stability::ZeroOrderSolver solver(a0_, teeth_, modes, options);
    // Speeds in order; ties keep the first (lowest) speed.
    r.depth_min_m = std::numeric_limits<double>::infinity();
    r.depth_max_m = -1.0;
    for (const double speed : speeds_rad_s_) {
      const double depth = std::min(solver.limit(speed).depth_limit_m, spec_.depth_max_m);
      if (depth < r.depth_min_m) {
        r.depth_min_m = depth;
        r.speed_at_min_rad_s = speed;
      }
      if (depth > r.depth_max_m) {
        r.depth_max_m = depth;
        r.speed_at_max_rad_s = speed;
      }
    }
  }
  return r;
}

}  // namespace robomill::atlas
