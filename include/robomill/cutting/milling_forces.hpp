#pragma once
// Instantaneous milling forces of a rigid cutter on a rigid part: the sum over
// teeth j and axial elements k of the element forces of the cutting law,
// projected onto the tool frame (000 Eq 8-15, 001 Eq 11-15, 002 Eq 29,
// 004 Eq A1-A5).

#include <Eigen/Core>
#include <vector>

#include "robomill/cutting/cutting_law.hpp"
#include "robomill/cutting/engagement.hpp"
#include "robomill/cutting/process.hpp"
#include "robomill/tool/tool.hpp"

namespace robomill::cutting {

/// Force and torque the part exerts on the cutter at one instant, tool frame.
struct ToolLoad {
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  double torque_nm = 0.0;  ///< about +z; positive resists the cutting rotation
};

/// Where the edge is in material when the workpiece is not a straight band:
/// the engaged arcs of each axial element (the cutter-workpiece engagement
/// along a program, toolpath/cutter_engagement.hpp), and the feed per tooth
/// split into its part normal to the tool axis (along tool x) and along it.
struct GeneralEngagement {
  double spindle_rad_s = 0.0;
  double feed_per_tooth_m = 0.0;        ///< normal to the axis, along tool x
  double axial_feed_per_tooth_m = 0.0;  ///< along +z (towards the spindle); < 0 plunging
  /// The edge from `edge_from_m` up to this height is discretized (ap,
  /// measured from the tip).
  double axial_depth_m = 0.0;
  /// Below this height the edge is in air (the tip below the material): the
  /// elements start here, so they end where the engaged slices do.
  double edge_from_m = 0.0;
  /// Engaged arcs at height z above the tip: `arcs_at(z)` returns them.
  std::vector<double> slice_top_m;            ///< upper end of each slice, increasing
  std::vector<std::vector<Engagement>> arcs;  ///< per slice, each arc in [0, 2π)
};

/// A cutter, a law and a process, precomputed for fast evaluation at any
/// rotation angle. Immutable after construction; `at()` is thread-safe and
/// allocation-free.
class MillingForceModel {
 public:
  /// Throws std::invalid_argument if the process is not feasible for the tool
  /// (ae > D, ap > overhang, non-positive feed, ...).
  MillingForceModel(const tool::Tool& tool, const CuttingLaw& law, const MillingProcess& process,
                    int axial_elements);

  /// The same mechanism on an arbitrary engagement: each element cuts where
  /// its slice's arcs say, and the chip of 001 Eq 14 gains the axial feed's
  /// share on a ball nose, h = i (fz sin φ sin κ − fz,axial cos κ) (Lazoglu's
  /// ball-end chip for a feed with an axial component). A straight band
  /// given as arcs reproduces the constructor above (tests/toolpath). The
  /// law's mean chip thickness (size-dependent law) is taken over the arcs
  /// of the widest slice. Throws std::invalid_argument for a non-positive
  /// speed or depth, or a negative lateral feed.
  MillingForceModel(const tool::Tool& tool, const CuttingLaw& law,
                    const GeneralEngagement& engagement, int axial_elements);

  /// Load at tool rotation angle ϕ (tooth 0's tip is at φ = ϕ).
  ///   φ_{j,k} = ϕ + φp_j − ψ_k                      (000 Eq 10, 001 Eq 1-3)
  ///   h_{j,k} = sin κ_k · min_{i=1..N} (i fz sin φ + r_j − r_{j−i})
  ///       (001 Eq 14 for the static part; the minimum over earlier teeth is
  ///        the usual runout chip thickness, 0 when the tooth does not cut)
  ///   [Fx Fy Fz] = Σ [−cos φ  −sin κ sin φ  −cos κ sin φ] [Ft]
  ///                  [ sin φ  −sin κ cos φ  −cos κ cos φ] [Fr]   (001 Eq 11)
  ///                  [ 0       cos κ        −sin κ      ] [Fa]
  ToolLoad at(double rotation_rad) const noexcept;

  const tool::Tool& tool() const noexcept { return tool_; }
  const MillingProcess& process() const noexcept { return process_; }
  const ResolvedLaw& law() const noexcept { return law_; }
  /// Engagement of the full-radius edge (what Altintas' averages use).
  const Engagement& nominal_engagement() const noexcept { return nominal_engagement_; }
  /// Mean chip thickness t_c over the nominal engagement (004 Eq A3).
  double mean_chip_m() const noexcept { return mean_chip_m_; }
  const std::vector<tool::EdgeElement>& elements() const noexcept { return elements_; }

  double tooth_period_s() const noexcept;

 private:
  struct ElementTooth {       // one (element, tooth) pair, precomputed
    double angle_offset_rad;  // φp_j − ψ_k
    double lever_m;           // radius for the torque, with runout
    int min_offset_index;     // into radius_steps_: N entries (i = 1..N)
  };

  // Fills elements_' per-element data and the (element, tooth) pairs; the
  // element's arcs are `element_arcs(e)`.
  template <class ArcsOfElement>
  void build(ArcsOfElement&& element_arcs);

  tool::Tool tool_;
  MillingProcess process_;
  ResolvedLaw law_;
  Engagement nominal_engagement_;
  double mean_chip_m_ = 0.0;
  std::vector<tool::EdgeElement> elements_;
  std::vector<ElementTooth> pairs_;     // element-major
  std::vector<double> radius_steps_m_;  // r_j − r_{j−i}
  std::vector<double> element_sin_kappa_, element_cos_kappa_;
  // −fz,axial cot κ per element: the axial feed's share of the chip divided by
  // sin κ (0 on cylindrical edges and without axial feed).
  std::vector<double> element_axial_chip_m_;
  std::vector<Engagement> arcs_;        // every element's arcs, element-major
  std::vector<int> element_arc_begin_;  // element e's arcs: [begin[e], begin[e + 1])
};

/// Axial elements that resolve the helix lag to 0.5° per element (at least 40
/// on a rounded end, ball or bull nose; 1 for a straight flute), at most 2000.
int default_axial_elements(const tool::Tool& tool, double axial_depth_m);

/// How to sample a force history.
struct ForceSampling {
  int revolutions = 1;
  int steps_per_tooth = 90;  ///< samples per tooth period
};

/// Force history over whole revolutions, starting at ϕ = 0.
struct ForceSeries {
  std::vector<double> rotation_rad;
  std::vector<double> time_s;
  std::vector<Eigen::Vector3d> force_n;
  std::vector<double> torque_nm;
  std::size_t size() const noexcept { return time_s.size(); }
};

/// Samples `model` at `sampling`. Samples are independent and computed in
/// parallel on `threads` threads (0 = hardware concurrency).
ForceSeries sample_forces(const MillingForceModel& model, const ForceSampling& sampling,
                          int threads = 0);

/// Mean, extremes and peak-to-peak of each component of a force history.
struct ForceStatistics {
  Eigen::Vector3d mean_n, min_n, max_n, peak_n, peak_to_peak_n;
  double mean_torque_nm = 0.0, peak_torque_nm = 0.0;
  double mean_power_w = 0.0;
};

/// `peak_n` is the sample of largest magnitude, with its sign. The mean is the
/// trapezoid-free sample mean, exact for periodic histories sampled over whole
/// tooth periods.
ForceStatistics summarize(const ForceSeries& series, double spindle_rad_s);

}  // namespace robomill::cutting
