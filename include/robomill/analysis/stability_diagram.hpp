#pragma once
// The stability lobe diagram of a job (`robomill stability`, DESIGN.md §3):
// the limiting axial depth over the job's spindle speeds by the zero-order
// approximation (ZOA, 003 §3) or the semi-/full-discretization methods
// (SDM, FDM, FDM2), for all modes coupled and/or 003 §3.2's envelope of the
// one-mode diagrams, with process damping (000 Eq 18-19, 003 §3.1), 000's
// multipoint model (the modes' shapes along the tool, 000 Eq 35) and its
// deformation-corrected engagement (000 Figures 12-13), the spectral-radius
// map, and the job's cutting tests against the prediction.
//
// Everything is in SI units; the command line (apps/robomill) turns the
// result into sld.csv and summary.json.

#include <optional>
#include <string>
#include <vector>

#include "robomill/dynamics/modal_model.hpp"
#include "robomill/job/job.hpp"
#include "robomill/stability/lobes.hpp"
#include "robomill/stability/zero_order.hpp"

namespace robomill::analysis {

/// How the boundary was crossed at a limit (the critical Floquet multiplier:
/// stability/floquet.hpp); the zero-order method knows only Hopf.
enum class Bifurcation {
  none,  ///< not limited: stable up to the search range
  hopf,  ///< a complex pair leaves the unit circle (regenerative chatter)
  flip,  ///< a real multiplier at −1 (period doubling)
  fold,  ///< a real multiplier at +1
};

/// "none", "hopf", "flip" or "fold" (sld.csv's bifurcation column).
const char* to_string(Bifurcation bifurcation) noexcept;

/// One speed of a diagram, whatever method produced it.
struct StabilityLimit {
  double spindle_rad_s = 0.0;
  /// Smallest unstable axial depth, or the search range's top
  /// (stability.depth_max) when the cut is stable up to it (`limited` false).
  double depth_limit_m = 0.0;
  bool limited = false;
  double chatter_frequency_hz = 0.0;  ///< 0 when not limited
  Bifurcation bifurcation = Bifurcation::none;
  int mode = -1;  ///< governing mode of an envelope (0-based), −1 for a coupled diagram
};

/// The key figures of one diagram.
struct DiagramFigures {
  double min_limit_m = 0.0;  ///< +inf for an empty diagram
  double min_limit_spindle_rad_s = 0.0;
  double max_limit_m = 0.0;
  int speeds_stable_to_depth_max = 0;  ///< speeds not limited in the search range
  int speeds_period_doubling = 0;      ///< speeds limited by a flip bifurcation
};

DiagramFigures diagram_figures(const std::vector<StabilityLimit>& limits);

/// The limit at any speed inside the diagram's range, linear between the
/// computed speeds (sorted by speed); nullopt outside the range or for an
/// empty diagram. A one-speed diagram answers only at its speed.
std::optional<double> interpolated_limit_m(const std::vector<StabilityLimit>& limits,
                                           double spindle_rad_s);

/// One cutting test (`experiments:`) against a diagram.
struct ExperimentCheck {
  job::Experiment experiment;
  /// The diagram's limit at the test's speed (interpolated_limit_m); nullopt
  /// when the speed is outside the computed range (then nothing else is set).
  std::optional<double> limit_m;
  bool predicted_chatter = false;  ///< depth ≥ limit
  bool agrees = false;             ///< predicted_chatter == the observed verdict
  /// The computed speed nearest to the test's: its chatter frequency (when
  /// limited) and, in an envelope, the governing mode and its natural
  /// frequency say which structure the prediction blames.
  std::optional<double> chatter_frequency_hz;
  int governing_mode = -1;  ///< 0-based; −1 for a coupled diagram
  std::optional<double> governing_mode_fn_hz;
};

struct ExperimentComparison {
  std::vector<ExperimentCheck> tests;  ///< one per experiment, in the job's order
  int agree = 0;                       ///< tests whose prediction matches the verdict
  int compared = 0;                    ///< tests inside the computed speed range
};

/// The time-domain method of a job's method name (sdm, fdm, fdm2); fdm for
/// zoa, which callers handle before asking.
stability::FloquetMethod floquet_method(job::StabilitySettings::Method method);

/// Every test against `limits`; `modes` (optional) gives the natural
/// frequency of an envelope's governing mode.
ExperimentComparison compare_experiments(const std::vector<job::Experiment>& experiments,
                                         const std::vector<StabilityLimit>& limits,
                                         const dynamics::ModalModel* modes);

/// 000 Figures 12-13: one of the diagrams without and with process damping
/// and with and without the deformation-corrected engagement, all on the
/// multipoint model (the modes' shapes along the tool).
struct DeformationVariant {
  /// "traditional" (neither), "process_damping", "deformation" or "both".
  std::string name;
  bool process_damping = false;
  bool deformation = false;
  std::vector<StabilityLimit> limits;
  /// The largest expansion over the traditional diagram, speed by speed:
  /// a_lim / a_lim,traditional − 1 (0 for the traditional diagram itself).
  double max_expansion = 0.0;
  double max_expansion_spindle_rad_s = 0.0;
  ExperimentComparison experiments;
};

/// How far 000's deformed engagement moved the cut (deflection/
/// deformed_engagement.hpp): the entry angle at the tip and at the top of
/// the flute for the deepest tabulated depth.
struct DeformedEngagementFigures {
  bool robot_included = false;          ///< the robot's joint springs (000 Eq 3)
  bool mode_shapes_along_tool = false;  ///< the modal table gives shapes (000 Eq 35)
  int table_depths = 0;                 ///< depths the engagement is tabulated over
  double nominal_entry_rad = 0.0;
  double entry_at_depth_max_tip_rad = 0.0;
  double entry_at_depth_max_top_rad = 0.0;
};

/// The time-domain methods' time step against the structure's highest mode
/// at the lowest speed (the longest tooth period). The parser asks for two
/// steps per period of the highest mode (no aliasing); the boundary converges
/// at about eight (docs/assumptions.md, measured on the 1-DOF benchmark at
/// 1500 rpm: 2.2 steps per period put the limit 2.4x too high).
struct DiscretizationCheck {
  static constexpr double converged_steps_per_period = 8.0;
  int discretization = 0;  ///< steps per tooth period (stability.discretization)
  double highest_mode_hz = 0.0;
  double lowest_spindle_rad_s = 0.0;
  double steps_per_period = 0.0;  ///< of the highest mode at the lowest speed
  /// The discretization that gives converged_steps_per_period.
  double discretization_for_convergence = 0.0;
  bool converged() const noexcept { return steps_per_period >= converged_steps_per_period; }
};

struct StabilityDiagram {
  job::StabilitySettings::Method method = job::StabilitySettings::Method::fdm;
  /// Which diagrams were asked for (stability.modes).
  job::StabilitySettings::Modes diagrams = job::StabilitySettings::Modes::coupled;
  std::vector<double> speeds_rad_s;  ///< the computed spindle speeds, ascending
  /// The structure's modes (table, fit, robot or posture library); nullopt
  /// when the measured FRFs are used directly (dynamics.use: frf).
  std::optional<dynamics::ModalModel> modes;

  std::vector<StabilityLimit> coupled;   ///< all modes together (empty for modes: envelope)
  std::vector<StabilityLimit> envelope;  ///< 003 §3.2 (empty unless modes: envelope or both)
  /// With stability.deformation: 000's four (or, without process damping,
  /// two) diagrams, the traditional one first (it is also `coupled`).
  std::vector<DeformationVariant> variants;
  std::optional<DeformedEngagementFigures> deformation;  ///< with stability.deformation
  std::optional<stability::StabilityMap> map;            ///< with stability.mode: map

  ExperimentComparison experiments;  ///< the job's tests against primary()
  /// The tests against the envelope when both diagrams were computed.
  std::optional<ExperimentComparison> envelope_experiments;
  /// Time-domain methods with modes only.
  std::optional<DiscretizationCheck> discretization;
  double elapsed_s = 0.0;  ///< computing the diagrams (structure included)

  /// The diagram the job asked for first: the coupled one, or the envelope
  /// for modes: envelope.
  const std::vector<StabilityLimit>& primary() const noexcept {
    return diagrams == job::StabilitySettings::Modes::envelope ? envelope : coupled;
  }
};

/// The job's diagram(s) on up to `threads` threads (0: all cores). Needs the
/// tool, cutting, process and stability sections and a structure; throws
/// InputError naming the field for combinations the methods do not support
/// (energy-balance damping with a time-domain method, a map by ZOA, 000's
/// deformation variants with an envelope or a map, fitted modes too fast for
/// the discretization).
///
/// `cut_basis`, when given, is the A0 basis (zero_order.hpp) of the job's
/// tool, process and reference depth, computed once by a caller that runs
/// many jobs differing only in coefficients and structure (the stability
/// band's draws): the zero-order diagram on modes then takes A0 from it
/// instead of averaging W again. The other methods ignore it.
StabilityDiagram stability_diagram(const job::Job& job, int threads = 0,
                                   const stability::MeanCuttingStiffnessBasis* cut_basis = nullptr);

}  // namespace robomill::analysis
