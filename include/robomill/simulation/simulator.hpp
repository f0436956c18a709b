#pragma once
// Nonlinear, regenerative time-domain simulation of milling on a compliant
// structure (002 §3.2-3.4, 001 §2.2, 000 §3): the structure (structure.hpp)
// is driven by the cutting forces of the teeth, whose chip thickness comes
// from the actual geometry — the surface the earlier teeth left and the raw
// part — so that tool entry, partial engagement, loss of contact, runout and
// multiple regeneration all follow without special cases.
//
// Chip thickness: a swept-surface memory, the equivalent of 002 §3.3's
// workpiece mesh without its quantization. Angles are discretized with the
// step (Δφ = Ω Δt = 2π / (N · steps_per_tooth)), so at every step each edge
// element k of tooth j sits exactly on one cell b of its element's angular
// grid. Each cell keeps the largest projection s_b = max (c · n + ρ) ever
// reached there, with c the cutter centre (nominal feed path + vibration u),
// n = (sin κ sin φ, sin κ cos φ, −cos κ) the chip normal and ρ the edge
// point's own projection (its radius with runout, 001 Eq 4). The chip of the
// element is
//   h = min( c·n + ρ − s_b ,  d_stock ),                                (H)
// the thickness between the edge and the deepest earlier cut at that angle
// (the min over all earlier teeth: multiple regeneration and runout, as in
// 001 Eq 14), limited by d_stock, the thickness of raw material behind the
// edge along −n (zero outside the part). The part is the prism
// {x ≥ border} ∩ the radial band of the process (y ≤ ae − R down milling,
// y ≥ R − ae up milling, all y for a slot), so entry into a part with a
// straight border (002 Fig. 5 phases Ia, Ib, II) is geometric. h ≤ 0 gives
// zero force (002 Eq 27); the cell is updated after every committed step
// whether or not the edge cut, so the memory is also valid where the edge
// moves away from the part. Before t = 0 the cutter is taken to have moved
// rigidly along its nominal path, which makes a simulation without a border
// start in the steady cut.
//
// Forces: any cutting law (cutting_law.hpp, 002 Eq 24-28) per element,
// projected by 001 Eq 11 (002 Eq 29 for κ = 90°); optional process damping
// per engaged element, F = −c_e (n − μ t)(n · u̇), c_e = K_sp w² db / (4 V)
// (000 Eq 18-19, Ahmadi's linear equivalent).
//
// Integration: exact discretization of the structure with the force linearly
// interpolated over the step; the force at the end of the step is predicted
// from the state reached with the force held (predictor-corrector, one trial
// evaluation that does not touch the surface memory per step).

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <vector>

#include "robomill/cutting/cutting_law.hpp"
#include "robomill/cutting/process.hpp"
#include "robomill/simulation/structure.hpp"
#include "robomill/stability/lobes.hpp"
#include "robomill/tool/tool.hpp"

namespace robomill::simulation {

/// The part: material at x ≥ border_x_m in the frame where the cutter's
/// centre starts at the origin and feeds along +x at t = 0, within the radial
/// band of the process. −∞: the cutter is in the steady cut from t = 0.
struct Workpiece {
  double border_x_m = -std::numeric_limits<double>::infinity();
  /// false: the radial band (ae) is measured from the tool's radius — a
  /// straight wall beside the pass (slotting, side milling). true: from each
  /// edge element's own radius — a ball-end raster, where the previous pass's
  /// groove leaves a strip ae wide at every height (001 §2.4's path interval),
  /// so every disk of the ball cuts a crescent of radial depth ae.
  bool raster_groove = false;
  bool has_border() const noexcept { return border_x_m > -1e300; }
};

struct SimulationOptions {
  double duration_s = 0.0;
  int steps_per_tooth = 40;  ///< Δt = tooth period / steps_per_tooth
  int axial_elements = 1;
  double start_angle_rad = 0.0;  ///< tooth 0's angle at t = 0 (clockwise from +y)
  int record_every = 1;          ///< keep every k-th step in the result
  std::optional<stability::LinearProcessDamping> process_damping;
};

struct SimulationResult {
  double step_s = 0.0;           ///< integration step
  double record_interval_s = 0;  ///< step_s · record_every
  std::vector<double> time_s;
  std::vector<Eigen::Vector3d> force_n;         ///< on the cutter, tool frame
  std::vector<Eigen::Vector3d> displacement_m;  ///< tool-tip vibration u
  std::vector<int> teeth_cutting;               ///< teeth with a positive chip (n_c)
  long long element_evaluations = 0;  ///< tooth-element force evaluations (trial included)
  /// First step with a positive chip (−1: never), and when the cutter's
  /// centre reaches the border (the end of 002's phase I; 0 without border).
  double first_contact_s = -1.0;
  double full_engagement_s = 0.0;
  std::size_t size() const noexcept { return time_s.size(); }
};

/// How finely a step resolves the cut: the narrowest engaged arc of an edge
/// point (the top of the cut in a raster groove, where the disk is widest;
/// the tool's full radius against a straight wall) and the steps per tooth
/// period that put `steps_across` steps across it. A coarser step misplaces
/// the chip's entry and exit by up to a step; on a narrow arc that error is
/// a large part of the cut, and in a ball-end raster on a soft structure it
/// alone turned a stable cut into a spurious period doubling at 4-8 steps
/// across the arc, converged from 12 (docs/surface.md).
struct ArcResolution {
  double arc_rad = 0.0;
  int steps_per_tooth = 1;
};
inline constexpr int kStepsAcrossEngagedArc = 12;
ArcResolution engaged_arc_resolution(const tool::Tool& tool, const cutting::MillingProcess& process,
                                     const Workpiece& workpiece,
                                     int steps_across = kStepsAcrossEngagedArc);

/// The largest step for which process damping (000 Eq 19) stays stable in
/// the time stepping. The damping force −C u̇ is evaluated from the state
/// (predictor-corrector), i.e. explicitly: like Heun's method on u̇ = −λ u̇ it
/// diverges for λ Δt > 2, λ = C_max · λmax(Lᵀ M⁻¹ L), the damping rate on the
/// lightest direction of the structure. C_max bounds the damping with the
/// whole depth in contact on every tooth that can be inside the engaged arc
/// (widened by the helix lag) at once: n_c K_sp w² ap / (4 R Ω). The limit
/// returned is 1/λ (half the divergence limit, so that the damping is also
/// resolved, not only bounded). Infinity for a rigid structure or no damping.
double process_damping_step_limit_s(const tool::Tool& tool, const cutting::MillingProcess& process,
                                    const LinearStructure& structure,
                                    const stability::LinearProcessDamping& damping);

/// Simulates `options.duration_s` of cutting. Throws std::invalid_argument
/// for a non-physical process or options (the job parser checks them first
/// and names the field).
SimulationResult simulate(const tool::Tool& tool, const cutting::CuttingLaw& law,
                          const cutting::MillingProcess& process, const LinearStructure& structure,
                          const Workpiece& workpiece, const SimulationOptions& options);

}  // namespace robomill::simulation
