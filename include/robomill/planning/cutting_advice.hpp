#pragma once
// Cutting-parameter advice (issue 9 item 4): the spindle speed Ω and axial
// depth ap that maximize the material removal rate
//
//   MRR = ap · ae · v_f,   v_f = f_z · N · Ω / 2π                  (feed speed)
//
// at fixed radial depth ae, feed per tooth f_z and N teeth, subject to
//
//   ap ≤ s · a_lim(Ω)                 (inside the stability diagram, safety factor s ≤ 1)
//   d(Ω, ap) ≤ d_max                  (expected steady tool-tip offset, 004 Eq 1-2)
//
// a_lim(Ω) is the existing stability engine's limit (zero-order, Altintas &
// Budak 1995, or the semi-/full-discretization boundary, stability/lobes.hpp)
// and d the harmonic steady state of steady_state_offset.hpp under the
// periodic milling force at (Ω, ap). With several stations (the postures
// along a path) both constraints must hold at every one: a_lim is the lowest
// station's limit and d the largest station's offset.
//
// At a fixed speed MRR grows with ap, so the best depth there is the largest
// feasible one. Depths are multiples of the resolution Δ (what a machinist
// can set); the largest multiple under s · a_lim is found directly, the
// offset limit by bisection over the multiples below it. The bisection
// assumes the offset grows with the depth at a fixed speed (the mean force,
// and so the static part of the offset, is proportional to ap for a flat end
// mill; the tests check the advice against an exhaustive grid). The speed is
// scanned on the job's grid, then rescanned finely between the neighbours of
// the best scanned speed. With a Floquet method (sdm/fdm/fdm2) the advised
// point is re-checked by a direct Floquet solve at every station and stepped
// down while unstable, so the advice never leaves the computed diagram; with
// the zero-order method the same solve (FDM) is reported as an independent
// check.

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "robomill/cutting/cutting_law.hpp"
#include "robomill/cutting/process.hpp"
#include "robomill/dynamics/modal_model.hpp"
#include "robomill/planning/steady_state_offset.hpp"
#include "robomill/stability/lobes.hpp"
#include "robomill/tool/tool.hpp"

namespace robomill::planning {

/// Which stability engine gives a_lim(Ω).
enum class LimitMethod { zoa, sdm, fdm, fdm2 };

std::string_view to_string(LimitMethod method) noexcept;

/// How the stability limit is computed.
struct LimitSettings {
  LimitMethod method = LimitMethod::zoa;
  int discretization = 40;        ///< steps per tooth period (sdm/fdm/fdm2)
  double depth_max_m = 0.0;       ///< search range (0, depth_max]; ≤ the tool overhang
  double depth_tolerance = 1e-3;  ///< relative precision of a Floquet boundary
};

/// a_lim at every speed for one structure, in speed order (stability engine:
/// ZeroOrderSolver or stability_boundary). Zero-order limits carry
/// bifurcation "hopf" when limited.
std::vector<stability::LobePoint> limit_curve(const stability::RegenerativeModel& model,
                                              const std::vector<double>& spindle_rad_s,
                                              const LimitSettings& settings, int threads);

/// The harmonic steady-state problem of a modal model (tool frame): Eq 1 in
/// modal coordinates, M = I, K = diag(ωn²), C = diag(2ζωn), Jv = the shapes,
/// so that Jv (K − ω²M + iωC)⁻¹ Jvᵀ is the modal receptance.
PostureDynamics modal_dynamics(const dynamics::ModalModel& modes);

/// The job's limits and resolution.
struct AdviceLimits {
  double speed_min_rad_s = 0.0, speed_max_rad_s = 0.0;
  int speed_count = 0;                 ///< speeds of the scan (≥ 1)
  int refine_count = 20;               ///< speeds of the fine rescan around the best (0: none)
  double depth_step_m = 0.0;           ///< Δ: advised depths are multiples of it
  double stability_margin = 1.0;       ///< s ∈ (0, 1]: ap ≤ s · a_lim
  std::optional<double> max_offset_m;  ///< d_max (none: no offset limit)
  OffsetMeasure measure = OffsetMeasure::peak;
  int harmonics = 60;  ///< force harmonics for the offset
  int samples = 256;   ///< force samples per period (≥ 2 harmonics + 1)
};

struct AdviceOptions {
  LimitSettings limit;
  int peaks = 5;  ///< runner-ups reported (local MRR maxima of the scan, one per lobe pocket)
  /// Steps per tooth period of the independent FDM check of a zero-order
  /// advice; raised to two steps per period of the highest mode, and the
  /// check is skipped (reported as not done) beyond `max_check_steps`.
  int check_steps = 40;
  int max_check_steps = 400;
  int threads = 0;  ///< 0: all cores
  /// The limit the scan keeps under, when not the stations' own diagrams:
  /// called with the scan's speeds, then with the fine rescan's, it returns
  /// one LobePoint per speed (its depth_limit_m is what the margin
  /// multiplies; `limited` and the chatter frequency are reported as the
  /// stations' are). The robust advice of an uncertain job
  /// (analysis/robust_advice.hpp) gives the depth whose chance of chatter
  /// over the draws is the bound. The Floquet check of the advised point is
  /// then made on the stations and reported, without stepping the depth down.
  std::function<std::vector<stability::LobePoint>(const std::vector<double>& spindle_rad_s)>
      limit_source;
};

/// One speed of the scan: advice_map.csv's row.
struct SpeedAdvice {
  double spindle_rad_s = 0.0;
  double limit_depth_m = 0.0;  ///< a_lim: the lowest station's limit (depth_max if unlimited)
  bool limited = false;        ///< some station has a limit below depth_max
  int station = 0;             ///< the station whose limit governs
  double chatter_frequency_hz = 0.0;
  double stable_depth_m = 0.0;  ///< largest multiple of Δ ≤ s · a_lim
  double depth_m = 0.0;         ///< advised depth: also within the offset limit (0: none)
  double offset_m = 0.0;        ///< expected offset at depth_m (largest over stations)
  bool offset_limited = false;  ///< the offset limit, not stability, set depth_m
  double mrr_m3_per_s = 0.0;    ///< ap · ae · f_z N Ω/2π at depth_m
  int stage = 0;                ///< 0 the scan, 1 the fine rescan
};

/// A direct Floquet solve at one (Ω, ap): the largest spectral radius over stations.
struct FloquetCheck {
  bool done = false;
  std::string method;  ///< "sdm", "fdm" or "fdm2"
  int steps = 0;
  double spectral_radius = 0.0;       ///< at the advised depth (< 1: stable)
  bool next_done = false;             ///< false when depth + Δ exceeds depth_max
  double next_spectral_radius = 0.0;  ///< at the advised depth + Δ
};

struct CuttingAdvice {
  bool feasible = false;  ///< some scanned speed admits a depth ≥ Δ
  SpeedAdvice best;
  double margin_to_chatter = 0.0;   ///< a_lim / ap at the advice (≥ 1 / s)
  double feed_speed_m_per_s = 0.0;  ///< v_f at the advised speed
  FloquetCheck check;
  std::vector<SpeedAdvice> scan;   ///< the scanned speeds, then the fine rescan
  std::vector<SpeedAdvice> peaks;  ///< local MRR maxima of the scan, best first
  int stepped_down = 0;            ///< depth steps removed by the Floquet re-check
  double elapsed_s = 0.0;
};

/// MRR of a cut (m³/s): ap · ae · f_z · N · Ω / 2π.
double material_removal_rate(double spindle_rad_s, double axial_depth_m,
                             const cutting::MillingProcess& process, int teeth);

/// The advice for `process`'s ae, f_z and direction (its spindle speed and ap
/// are the unknowns and are ignored) at every station's structure (tool
/// frame). Throws std::invalid_argument for no station, a bad range or
/// resolution (depth_max over the overhang, Δ > depth_max, more than 100 000
/// depth steps), a margin outside (0, 1] or a non-positive offset limit.
CuttingAdvice advise_cutting(const tool::Tool& tool, const cutting::CuttingLaw& law,
                             const cutting::MillingProcess& process,
                             const std::vector<dynamics::ModalModel>& stations,
                             const AdviceLimits& limits, const AdviceOptions& options);

/// The spectral radius of one station at (Ω, ap) by a direct Floquet solve
/// (for checks; stability/floquet.hpp).
double spectral_radius_at(const stability::RegenerativeModel& model, double spindle_rad_s,
                          double axial_depth_m, stability::FloquetMethod method, int steps);

}  // namespace robomill::planning
