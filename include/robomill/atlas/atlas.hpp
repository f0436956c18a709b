#pragma once
// Workspace atlas (issue 11): a sweep of tool-tip positions × redundancy
// angles, and per item the analyses a job asks for — lowest natural frequency,
// compliance along feed / normal / tool axis, and the minimum and maximum
// stable depth over a spindle range (a zero-order diagram at the item's
// posture). Every item is computed on its own from the same seed posture, so
// its result depends on nothing but its inputs: any order, thread count or
// MPI rank layout gives bitwise-identical results.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "robomill/cutting/cutting_law.hpp"
#include "robomill/cutting/process.hpp"
#include "robomill/robot/robot_model.hpp"
#include "robomill/tool/tool.hpp"

namespace robomill::atlas {

/// What the job's `atlas:` section describes (SI units).
struct AtlasSpec {
  Eigen::Vector3d from_m = Eigen::Vector3d::Zero(), to_m = Eigen::Vector3d::Zero();
  std::array<int, 3> counts{1, 1, 1};
  Eigen::Vector3d tool_axis = Eigen::Vector3d::UnitZ();  ///< tool z, tip → spindle (unit)
  Eigen::Vector3d feed = Eigen::Vector3d::UnitX();       ///< unit, ⊥ tool_axis
  std::vector<double> redundancy_rad{0.0};               ///< angles about the tool axis
  bool compliance = true, frequency = true, stability = false;
  double speed_from_rad_s = 0.0, speed_to_rad_s = 0.0;  ///< `speeds` (stability)
  int speed_count = 0;
  double depth_max_m = 0.0;     ///< `depth_max`: limits above it are reported as it
  std::filesystem::path store;  ///< resolved against the job file's folder
  int batch = 0;                ///< items per commit; 0: automatic
};

/// One work item: a grid point and a redundancy angle.
struct AtlasItem {
  std::int64_t id = 0;  ///< 0-based: ((iz * ny + iy) * nx + ix) * nψ + iψ
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  double redundancy_rad = 0.0;
};

std::int64_t item_count(const AtlasSpec& spec);
/// The item with this id (0 ≤ id < item_count).
AtlasItem item(const AtlasSpec& spec, std::int64_t id);

/// The results of one item. Values not requested or not reachable are 0.
struct AtlasResult {
  bool reachable = false;
  double lowest_frequency_hz = 0.0;
  double compliance_feed_m_per_n = 0.0, compliance_normal_m_per_n = 0.0;
  double compliance_axial_m_per_n = 0.0;
  double condition_number = 0.0;
  double depth_min_m = 0.0, speed_at_min_rad_s = 0.0;  ///< smallest stable limit over the speeds
  double depth_max_m = 0.0, speed_at_max_rad_s = 0.0;  ///< largest
  Eigen::VectorXd q;  ///< the posture (rad); empty when not reachable
};

/// Number of doubles in a packed result of a robot with `dof` joints.
int packed_size(int dof);
/// Flat form (for messages between MPI ranks): fixed fields then q (dof).
void pack(const AtlasResult& result, int dof, double* out);
AtlasResult unpack(const double* in, int dof);

/// Everything items share, built once per job: the robot, the seed posture,
/// and for stability the cut's mean cutting stiffness A0 (tool frame).
class AtlasContext {
 public:
  /// Throws std::invalid_argument when stability is requested without a cut
  /// (tool, law, process) or the seed has the wrong size.
  AtlasContext(const AtlasSpec& spec, const robot::RobotModel& model, Eigen::VectorXd seed,
               const std::optional<tool::Tool>& tool = {},
               const std::optional<cutting::CuttingLaw>& law = {},
               const std::optional<cutting::MillingProcess>& process = {});

  /// The item's results (thread-safe: reads only shared state).
  AtlasResult evaluate(const AtlasItem& item) const;

  const AtlasSpec& spec() const noexcept { return spec_; }
  const robot::RobotModel& model() const noexcept { return model_; }

 private:
  AtlasSpec spec_;
  const robot::RobotModel& model_;
  Eigen::VectorXd seed_;
  Eigen::Matrix3d a0_ = Eigen::Matrix3d::Zero();
  int teeth_ = 1;
  std::vector<double> speeds_rad_s_;
};

}  // namespace robomill::atlas
