#pragma once
// The robot along the program (issue 19, docs/toolpath.md "The robot along
// the program"): every sample of a program analysis (program_analysis.hpp)
// placed in the robot cell, the robot's posture there by inverse kinematics
// with the redundancy angle ψ about the tool axis (001 §2.1.4), the structure
// at that posture (the robot's joint-space model, 004 Eq 1-2; modal tables
// measured at several postures, 001 Eq 16-18; or one fixed table), and from
// them per sample:
//
//  - the stable axial depth at the sample's engagement and spindle speed by
//    the zero-order method (Altintas & Budak; 003 §3.2, process damping of
//    000 Eq 18-19 / 003 §3.1 when the job asks), against the actual depth: a
//    stability margin a_lim / ap and a chatter flag with the chatter
//    frequency;
//  - the static tool-tip deflection under the sample's mean force (the
//    robot's compliance at the posture, 000 Eq 3 / 004 Eq 2 at ω = 0, plus
//    the tool as a cantilever loaded at the middle of the engaged depth, 000
//    Eq 1), projected on the normal of the wall the sample finishes (the
//    surface location error) and on the tool axis (the floor);
//  - on request, 004's steady-state tool-tip offset (§3.1 Eq 1-2): the
//    robot's joint-space model at the posture under the periodic force of
//    the sample's own engagement, as `robomill optimize` takes it at each
//    point of its path (planning/steady_state_offset.hpp).
//
// The shortcut. The posture changes slowly along a path but the zero-order
// limit costs a solver per sample. Along every run of samples that share the
// tool and the spindle speed, the limit is computed exactly at the run's ends
// and at midpoints by bisection: an interval is filled by linear
// interpolation only when its midpoint's exact limit lies within `tolerance`
// of the interpolated one, and is split otherwise, down to neighbouring
// samples (which are then exact). Every `check_every`-th interpolated sample
// is also computed exactly and its error reported, so the shortcut's error is
// measured, not assumed.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "robomill/cutting/cutting_law.hpp"
#include "robomill/dynamics/modal_model.hpp"
#include "robomill/planning/force_harmonics.hpp"
#include "robomill/planning/steady_state_offset.hpp"
#include "robomill/robot/posture_interpolation.hpp"
#include "robomill/robot/robot_model.hpp"
#include "robomill/stability/process_damping.hpp"
#include "robomill/stability/zero_order.hpp"
#include "robomill/toolpath/program_analysis.hpp"

namespace robomill::robot_path {

/// The structure at the tool tip at posture q, expressed in the sample's
/// milling frame (rows of `cell_to_milling`: the lateral feed, the normal
/// axis × feed, the tool axis; cell frame).
using PostureStructure = std::function<dynamics::ModalModel(
    const Eigen::VectorXd& q, const Eigen::Matrix3d& cell_to_milling)>;

/// The robot's own modes at each posture (004 Eq 1-2: Jv (K − ω²M + iωC)⁻¹ Jvᵀ).
PostureStructure robot_structure(const robot::RobotModel& model);

/// Modal tables measured at several postures (tool frame), interpolated at
/// each posture by inverse-distance weighting (001 Eq 16-18) and turned from
/// the tool frame into the milling frame. Throws std::invalid_argument for an
/// empty or inconsistent library.
PostureStructure measured_postures_structure(
    const robot::RobotModel& model, std::vector<Eigen::VectorXd> postures_rad,
    std::vector<std::vector<robot::DirectionalModeParameters>> tables,
    robot::IdwOptions options = {});

/// One modal table (tool frame) that holds at every posture; the tool frame
/// turns with the robot, so its modes turn into each sample's milling frame.
PostureStructure fixed_structure(const robot::RobotModel& model,
                                 dynamics::ModalModel tool_frame_modes);

/// How the stable depth is computed at each sample.
struct PathStabilitySettings {
  bool enabled = true;       ///< false: no limits (a law the regenerative model cannot take)
  double depth_max_m = 0.0;  ///< limits above it read as "not limited" (0: the tool overhang)
  std::optional<stability::ProcessDamping> process_damping;
  bool envelope = false;  ///< 003 §3.2's lowest envelope of the single-mode diagrams
  /// Speeds the advice searches for a better spindle speed at the worst
  /// samples (rad/s, ascending); empty: 0.5 … 1.5 × the sample's speed.
  std::vector<double> advice_speeds_rad_s;
};

struct RobotPathSettings {
  /// Workpiece frame → cell frame (004 Eq 7: p_c + p_w + R_w(θp) p).
  Eigen::Isometry3d workpiece_to_cell = Eigen::Isometry3d::Identity();
  /// ψ about the tool axis (001 §2.1.4) at every sample the program leaves
  /// it to the cell; an oriented sample (a KRL frame) takes the program's.
  double redundancy_rad = 0.0;
  /// A schedule ψ(s) instead (program_optimization.hpp): ψ at the start and
  /// the end of every move, linear along it; empty: redundancy_rad.
  std::vector<std::pair<double, double>> redundancy_by_move;
  /// A turn of the program's own ψ at every oriented sample (its frames
  /// turned about the tool axis: `--optimize` on a KRL program, written back
  /// with io::turn_krl_frames).
  double frame_turn_rad = 0.0;
  /// The IK's first seed (rad, one per joint); each later sample starts from
  /// the posture before it, so the robot follows one configuration.
  Eigen::VectorXd seed_rad;
  double tolerance = 0.02;   ///< relative error allowed to an interpolated limit
  int max_span = 64;         ///< at most this many samples between two exact limits
  int check_every = 25;      ///< every n-th interpolated sample is also exact (0: none)
  double risk_margin = 1.0;  ///< at risk when a_lim < risk_margin × ap
  /// A joint this close to a limit (rad) counts as a joint-limit hit.
  double joint_limit_margin_rad = 0.5 * 3.14159265358979323846 / 180.0;
  /// Tool bending (000 Eq 1): Young's modulus × the equivalent section's
  /// second moment come from each tool; the equivalent diameter is this
  /// fraction of the diameter (000's 0.8, docs/assumptions.md).
  double equivalent_diameter_fraction = 0.8;
  /// 000's contact boundary (§4, Eq 20-31) where a sample finishes a wall in
  /// down milling with the linear law and a flat end mill: the node
  /// deflections of `robomill deflection` at the sample's posture, feed,
  /// radial and axial depth, in its milling frame, instead of the static
  /// tip deflection (which every other sample keeps).
  struct ContactDeflection {
    bool enabled = false;
    int elements = 10;            ///< m axial elements (000: dz = ap/m)
    bool chip_correction = true;  ///< 000 Eq 21/28's static-chip correction
  } contact;
  /// 004's steady-state offset (§3.1 Eq 1-2, §3.3) at every reachable
  /// sample in the cut: M(q), C, K and Jv of the robot's joint-space model
  /// at the sample's posture, the force of the sample's engaged arc, depth,
  /// feed and speed as a Fourier series (004 §4.2) in its milling frame
  /// (x the feed, z the tool axis: 004's R_ni). The robot needs its links'
  /// masses. d_m (004 Eq 6) is then the mean over those samples.
  struct SteadyOffset {
    bool enabled = false;
    planning::OffsetMeasure measure = planning::OffsetMeasure::peak;
    int harmonics = 60;      ///< force harmonics kept
    int samples = 256;       ///< instants per period (≥ 2 harmonics + 1)
    int axial_elements = 0;  ///< of the force model (0: the default for the depth)
  } offset;
  int threads = 0;  ///< 0: all cores
  std::size_t worst_lines = 10;
  /// With draws (RobotAlongPath::set_draws): a program line is listed when
  /// P(chatter) over the draws exceeds this at one of its samples.
  double max_chatter_probability = 0.05;
};

/// One draw of a job's uncertain inputs (issue 33, docs/uncertainty.md)
/// along the program: the structure at every posture, the cutting law and
/// the stability settings of the drawn job (analysis::robot_path_setup of
/// it). The draws keep the nominal postures: what they draw is structure and
/// coefficients, not kinematics or the cut.
struct PathDraw {
  PostureStructure structure;
  cutting::CuttingLaw law;
  PathStabilitySettings stability;
};

/// What the robot does at one sample.
struct RobotSample {
  using Joints = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 8, 1>;  ///< no allocation
  bool reachable = false;
  Joints q_rad;  ///< the posture (the IK's best attempt when unreachable)
  double redundancy_rad = 0.0;
  double joint_margin_rad = 0.0;  ///< smallest distance of a joint to its limit
  bool joint_limit = false;       ///< joint_margin_rad below the settings' margin
  double singularity = 0.0;       ///< σ_min / σ_max of the tool Jacobian (1 m per rad)
  // Stability (analysed, reachable samples in the cut).
  bool stability = false;  ///< a limit was computed for this sample
  bool exact = false;      ///< computed directly (else interpolated by the shortcut)
  double depth_limit_m = 0.0;
  bool limited = false;  ///< a lobe lies below depth_max at this speed
  double margin = 0.0;   ///< depth_limit / ap (> 1: stable)
  bool chatter = false;  ///< ap ≥ depth_limit
  bool at_risk = false;  ///< ap × risk_margin ≥ depth_limit
  double chatter_frequency_hz = 0.0;
  // Deflection (analysed, reachable samples).
  Eigen::Vector3d deflection_m = Eigen::Vector3d::Zero();  ///< tool tip, workpiece frame
  double form_error_m = 0.0;   ///< on the finished wall's normal; + = material left
  double floor_error_m = 0.0;  ///< along the tool axis; + = material left
  bool wall = false;           ///< the sample finishes a wall (an arc ends at φ = 0 or π)
  /// Unit, workpiece frame: from the tool towards the wall it finishes (the
  /// milling frame's −y in down milling and slots, +y in up milling); zero
  /// where no wall.
  Eigen::Vector3d wall_direction = Eigen::Vector3d::Zero();
  /// The lateral deflection and the form error are 000's contact boundary
  /// (RobotPathSettings::contact): the tip node's deflection, and the wall's
  /// largest surface location error over the nodes that generate it.
  bool contact = false;
  /// 004's steady-state offset d_i (RobotPathSettings::offset's measure), m.
  double steady_offset_m = 0.0;
  bool has_offset = false;  ///< steady_offset_m was computed at this sample
  // Over the draws of the uncertain inputs (RobotAlongPath::set_draws), at
  // this sample's posture and engagement: each draw's limit by the same
  // shortcut as the nominal one.
  bool drawn = false;         ///< the draws' limits were computed here
  double p_chatter = 0.0;     ///< the fraction of draws whose limit is ≤ ap
  double p_chatter_se = 0.0;  ///< its binomial standard error √(p(1 − p)/n)
  /// The draws' 5 % and 95 % quantiles of the limit (depth_max where a draw
  /// is not limited, as depth_limit_m).
  double depth_limit_q05_m = 0.0, depth_limit_q95_m = 0.0;
  /// The draws' limit at the bound (RobotPathSettings::max_chatter_probability
  /// p over n draws): their (⌊p n⌋ + 1)-th smallest, so that P(chatter) ≤ p
  /// exactly where ap < it. `--optimize` keeps ap below it (docs/uncertainty.md).
  double depth_limit_at_bound_m = 0.0;
  /// ap × risk_margin ≥ depth_limit_at_bound_m: with risk_margin 1, P(chatter)
  /// over the bound.
  bool at_risk_drawn = false;

  /// The risk `--optimize` keeps away from: with draws here, P(chatter) over
  /// the bound (at_risk_drawn); else the nominal limit's (at_risk).
  bool at_risk_to_optimize() const { return drawn ? at_risk_drawn : at_risk; }
};

/// A program line whose P(chatter) over the draws exceeds the bound, at its
/// sample of highest probability.
struct RiskyLine {
  int line = 0;
  double t_s = 0.0;
  double p_chatter = 0.0, p_chatter_se = 0.0;
  double axial_depth_m = 0.0, depth_limit_m = 0.0, depth_limit_q05_m = 0.0;
};

/// One program line among the worst, with the advice for it.
struct WorstLine {
  int line = 0;
  double t_s = 0.0;
  double margin = 0.0, axial_depth_m = 0.0, depth_limit_m = 0.0;
  double spindle_rad_s = 0.0, chatter_frequency_hz = 0.0, form_error_m = 0.0;
  /// The speed in the advice range with the largest stable depth at this
  /// sample's posture and engagement, and that depth.
  double better_spindle_rad_s = 0.0, better_depth_limit_m = 0.0;
  Eigen::VectorXd q_rad;
};

/// Totals over the program.
struct RobotPathSummary {
  std::size_t samples = 0, analysed = 0, stability_samples = 0;
  std::size_t unreachable = 0, joint_limit = 0, chatter = 0, at_risk = 0;
  int first_unreachable_line = 0, first_joint_limit_line = 0;
  std::vector<int> unreachable_lines;  ///< distinct program lines, at most 50
  double min_margin = 0.0;
  int min_margin_line = 0;
  double max_form_error_m = 0.0, max_deflection_m = 0.0, max_floor_error_m = 0.0;
  int max_form_error_line = 0;
  std::size_t contact_samples = 0;  ///< deflections by 000's contact boundary
  /// Samples whose ψ the program's frames set (PathSample::oriented), and
  /// the range of ψ over the reachable samples.
  std::size_t oriented_samples = 0;
  double min_redundancy_rad = 0.0, max_redundancy_rad = 0.0;
  /// 004's steady-state offset: samples with one, their mean (004 Eq 6's
  /// d_m over the program's samples) and the largest.
  std::size_t offset_samples = 0;
  double mean_offset_m = 0.0, max_offset_m = 0.0;
  int max_offset_line = 0;
  std::size_t exact_limits = 0;     ///< zero-order solves (the shortcut's cost)
  std::size_t checked = 0;          ///< interpolated samples also computed exactly
  double shortcut_max_error = 0.0;  ///< largest relative error among them
  double min_singularity = 1.0;
  int min_singularity_line = 0;
  std::vector<WorstLine> worst_lines;  ///< by margin, then form error; one per line
  std::vector<std::string> notes;
  // With draws (RobotAlongPath::set_draws):
  std::size_t draws = 0;
  /// Per draw, its samples that chatter (ap ≥ the draw's limit).
  std::vector<double> draw_chatter_samples;
  /// The expected number of chattering samples (the mean of
  /// draw_chatter_samples, Σ p_chatter) and its standard error (the draws'
  /// spread of the count / √n: the samples of one draw are not independent).
  double expected_chatter_samples = 0.0, expected_chatter_samples_se = 0.0;
  double max_p_chatter = 0.0, max_p_chatter_se = 0.0;
  int max_p_chatter_line = 0;
  /// The lines over RobotPathSettings::max_chatter_probability, in program
  /// order.
  std::vector<RiskyLine> risky_lines;
  std::size_t draw_exact_limits = 0;     ///< the draws' zero-order solves
  double draw_shortcut_max_error = 0.0;  ///< the largest checked error over the draws
};

/// The shortcut's cost and check over a block of samples: limits solved
/// exactly, interpolated samples also solved to check, and the largest
/// relative error among those.
struct ShortcutChecks {
  std::size_t exact = 0, checked = 0;
  double max_error = 0.0;
  /// With draws: the same over all draws, and per draw the block's
  /// chattering samples.
  std::size_t draw_exact = 0;
  double draw_max_error = 0.0;
  std::vector<double> draw_chatter_samples;
};

/// A RobotSample as `packed_size(dof)` doubles, to send between processes
/// (analysis::BlockSharing); unpack gives it back bit for bit.
std::size_t packed_size(int dof);
void pack(const RobotSample& sample, int dof, double* out);
RobotSample unpack(const double* in, int dof);

/// The analysis, fed block by block in program order. Holds the IK seed
/// between blocks; not thread-safe itself (it runs its blocks in parallel).
class RobotAlongPath {
 public:
  /// Throws std::invalid_argument for a seed of the wrong size or
  /// inconsistent settings. `model`, `tooling`, `law` must outlive it.
  RobotAlongPath(const robot::RobotModel& model, PostureStructure structure,
                 const toolpath::Tooling& tooling, const cutting::CuttingLaw& law,
                 PathStabilitySettings stability, RobotPathSettings settings);

  /// The robot at every sample of a block (out.size() == samples.size()):
  /// postures, compute and record in turn.
  void evaluate(std::span<const toolpath::PathSample> samples, std::span<RobotSample> out);

  /// evaluate()'s steps, for a block whose results are computed elsewhere
  /// (analysis::BlockSharing). The postures, in order (each inverse
  /// kinematics starts from the posture before; every block must pass here,
  /// in program order).
  void postures(std::span<const toolpath::PathSample> samples, std::span<RobotSample> out);
  /// At those postures: deflection, 004's offset, the stable depths (in
  /// parallel; the shortcut within the block).
  ShortcutChecks compute(std::span<const toolpath::PathSample> samples,
                         std::span<RobotSample> out) const;
  /// Adds a block's results to the totals, in program order.
  void record(std::span<const toolpath::PathSample> samples, std::span<const RobotSample> out,
              const ShortcutChecks& checks);

  /// The totals so far, with the worst lines' advice computed.
  RobotPathSummary finish();

  /// Draws of the uncertain inputs (before the first block): compute() then
  /// also gives every sample with a limit its P(chatter) over them and the
  /// band of its limit (RobotSample::drawn …), and record() the expected
  /// number of chattering samples and the lines over the bound. The draws run
  /// in parallel, each through the same shortcut as the nominal limits.
  void set_draws(std::vector<PathDraw> draws);
  std::size_t draw_count() const noexcept { return draws_.size(); }
  const std::vector<PathDraw>& draws() const noexcept { return draws_; }

  /// The robot at a sample with redundancy angle ψ = `redundancy_rad`, or,
  /// where the sample is oriented (PathSample::tool_x, a KRL frame), the
  /// program's own ψ turned by `redundancy_rad`; the inverse kinematics
  /// starting from `seed_rad` (the posture only: no limit, no deflection).
  RobotSample posture_at(const toolpath::PathSample& sample, double redundancy_rad,
                         const Eigen::VectorXd& seed_rad) const;

  /// The limit at one sample's posture and engagement computed directly (no
  /// shortcut), for checks: depth, chatter frequency, limited.
  stability::ZeroOrderLimit direct_limit(const toolpath::PathSample& sample,
                                         const Eigen::VectorXd& q_rad) const;

  /// The same at several spindle speeds (the sample's own is ignored).
  std::vector<stability::ZeroOrderLimit> limits_at(const toolpath::PathSample& sample,
                                                   const Eigen::VectorXd& q_rad,
                                                   const std::vector<double>& speeds_rad_s) const;

  /// direct_limit for draw `draw` (set_draws) at the nominal posture q.
  stability::ZeroOrderLimit draw_limit(std::size_t draw, const toolpath::PathSample& sample,
                                       const Eigen::VectorXd& q_rad) const;

  /// Cell-frame origins of the robot's joint frames, base to tool tip, at q.
  std::vector<Eigen::Vector3d> joint_origins(const Eigen::VectorXd& q_rad) const;

  /// The totals so far (without the worst lines' advice: finish()).
  const RobotPathSummary& summary() const noexcept { return summary_; }
  const robot::RobotModel& model() const noexcept { return model_; }
  const RobotPathSettings& settings() const noexcept { return settings_; }

 private:
  struct Candidate {  // a sample kept for the worst-lines table
    toolpath::PathSample sample;
    RobotSample robot;
  };
  const robot::RobotModel& model_;
  PostureStructure structure_;
  const toolpath::Tooling& tooling_;
  const cutting::CuttingLaw& law_;
  PathStabilitySettings stability_;
  RobotPathSettings settings_;
  Eigen::VectorXd seed_;
  RobotPathSummary summary_;
  std::vector<Candidate> worst_;  // the worst sample of each line so far, bounded
  using ArcKey = std::tuple<const tool::Tool*, double, double, double>;
  mutable std::map<ArcKey, Eigen::Matrix3d> a0_cache_;  // A0 per cutter and engaged arc
  mutable std::mutex a0_mutex_;
  // The draws, and the A0 of their laws: per arc the basis for linear laws
  // (A0 is linear in the coefficients, zero_order.hpp), per draw and arc
  // otherwise.
  std::vector<PathDraw> draws_;
  mutable std::map<ArcKey, stability::MeanCuttingStiffnessBasis> basis_cache_;
  mutable std::vector<std::map<ArcKey, Eigen::Matrix3d>> draw_a0_cache_;
  // Per program line, the sample of highest P(chatter) so far (record()).
  std::optional<std::pair<int, RiskyLine>> open_line_;
  using ForceKey = std::tuple<const tool::Tool*, double, double, double, double, double>;
  mutable std::map<ForceKey, std::shared_ptr<const planning::ForceHarmonics>> force_cache_;
  mutable std::mutex force_mutex_;
  double offset_sum_m_ = 0.0;

  Eigen::Matrix3d mean_stiffness(const tool::Tool& tool, const toolpath::PathSample& sample) const;
  Eigen::Matrix3d draw_mean_stiffness(std::size_t draw, const tool::Tool& tool,
                                      const toolpath::PathSample& sample) const;
  /// The limits with a structure, law and stability settings, A0 from `a0`.
  std::vector<stability::ZeroOrderLimit> limits_with(
      const toolpath::PathSample& sample, const Eigen::VectorXd& q_rad,
      const std::vector<double>& speeds_rad_s, const PostureStructure& structure,
      const cutting::CuttingLaw& law, const PathStabilitySettings& stability,
      const std::function<Eigen::Matrix3d(const tool::Tool&)>& a0) const;

  void posture(const toolpath::PathSample& sample, RobotSample& out);
  void deflect(const toolpath::PathSample& sample, RobotSample& out) const;
  void contact_deflect(const toolpath::PathSample& sample, const tool::Tool& tool,
                       const Eigen::Matrix3d& frame, RobotSample& out) const;
  std::shared_ptr<const planning::ForceHarmonics> force_series(
      const tool::Tool& tool, const toolpath::PathSample& sample) const;
  void steady_offset(const toolpath::PathSample& sample, RobotSample& out) const;
  ShortcutChecks limits(std::span<const toolpath::PathSample> samples,
                        std::span<RobotSample> out) const;
  /// The shortcut with any exact limit, on `threads` threads.
  using LimitAt =
      std::function<stability::ZeroOrderLimit(const toolpath::PathSample&, const Eigen::VectorXd&)>;
  ShortcutChecks shortcut_limits(std::span<const toolpath::PathSample> samples,
                                 std::span<RobotSample> out, const LimitAt& limit_at,
                                 int threads) const;
  void draw_limits(std::span<const toolpath::PathSample> samples, std::span<RobotSample> out,
                   ShortcutChecks& checks) const;
  void tally_draws(const toolpath::PathSample& sample, const RobotSample& out);
  void close_line();
  void tally(const toolpath::PathSample& sample, const RobotSample& out);
};

/// The equivalent straight cut of an engagement arc for the regenerative
/// model (cutting/process.hpp): down milling when the arc ends at φ = π, up
/// milling when it starts at φ = 0, a slot when both (robomill's angles,
/// clockwise from +y, docs/theory.md); nullopt for an arc inside (0, π).
std::optional<cutting::MillingProcess> band_process(double entry_rad, double exit_rad,
                                                    double tool_radius_m, double spindle_rad_s,
                                                    double feed_per_tooth_m);

}  // namespace robomill::robot_path
