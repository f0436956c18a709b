#pragma once
// Process damping for the zero-order stability analysis (003 §3.1-3.2,
// 000 Eq 18-19) and 003's two multi-mode diagrams.
//
// Indentation model (Wu 1989; Budak & Tunc 2010; 003 Eq 1): the flank wear
// land of width w behind the edge indents the wavy surface the edge has just
// cut; the indented volume U(t) produces F_r^d = K_d U(t) normal to the cut
// (pushing the tool away from the part) and F_t^d = μ F_r^d along the cutting
// force. For an edge vibrating along its chip normal as y(t) = A sin ω_c t at
// cutting speed v, the surface at a distance x behind the edge was cut at
// t − x/v, so with clearance angle γ the indentation depth there is
//   p(x, t) = A sin ω_c t − A sin(ω_c t − k x) − x tan γ,   k = ω_c / v = 2π/λ,
// λ = 2π v / ω_c = 2π R Ω_s / ω_c the wavelength, and U = db ∫_0^w [p]₊ dx.
// Energy balance (003 §3.1, Fig. 2c): the equivalent viscous coefficient c
// dissipates per vibration cycle what F_r^d does,
//   c · π ω_c A² = ∮ F_r^d ẏ dt.
// With γ = 0 the double integral has a closed form: ∫_0^{2π} [sin θ −
// sin(θ − ξ)]₊ cos θ dθ = (π/2) sin ξ for every ξ, hence
//   c = K_d db v (1 − cos β) / (2 ω_c²) = K_d db w² / (4 v) · [sin(β/2)/(β/2)]²,
//   β = k w = 2π w / λ,                                                    (EB)
// independent of A. For w ≪ λ (β → 0) this is Ahmadi's linear-equivalent
// damper, 000 Eq 19: C_eq = K_sp w² dz / (4 v). With γ > 0 the land only
// indents while ẏ/v > tan γ and c depends on A (numerical quadrature).
//
// Per edge element the damping force on the tool is (000 Eq 18 in robomill's
// frame; n the chip normal, t the tangential-force direction):
//   F_c = −c_e (n − μ t) nᵀ q̇,
// and its average over a tooth period (the zero-order approximation, as for
// A0) is the 3x3 matrix
//   C_p = Σ_elements c_e (N / 2π) ∫_{φst}^{φex} (n − μ t) nᵀ dφ,
// evaluated in closed form. The modes see it as extra modal damping
// (003 Eq 2: c^t = c^s + c^p): ζ_q ← ζ_q + φ_qᵀ C_p φ_q / (2 ω_q), which for a
// mode of modal mass m along a unit direction u is c^p/(2 m ω_q) with
// c^p = uᵀ C_p u. Cross-modal terms φ_pᵀ C_p φ_q (p ≠ q) are dropped (003
// treats modes as uncoupled).
//
// Fixed-point iteration (Budak & Tunc 2010): C_p grows with the depth (the
// contact length) and, for the energy balance, depends on the chatter
// frequency, which itself depends on the damping. At each speed:
//   a_0 = 0 → (a_1, f_1) = ZOA limit without process damping;
//   (a_{i+1}, f_{i+1}) = ZOA limit with C_p(Ω, a_i, f_i).
// The limit L(a) rises with the damping, so from a_0 = 0 the iterates rise
// monotonically to the smallest fixed point a = L(a): the depth where the cut,
// damped as it would be at that depth, turns unstable. When L'(a) is close to
// one this converges slowly, so an Aitken extrapolation is tried after every
// two plain steps; if it overshoots (L(a_x) < a_x) the fixed point is
// bracketed and found by Illinois regula falsi. The iteration stops at a
// relative change below `tolerance` in depth and frequency, or after
// `max_evaluations` ZOA limits (then `converged` is false and the last
// iterate is returned). If an iterate exceeds depth_max, process damping
// stabilizes every depth up to depth_max (`limited` false).

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "robomill/dynamics/modal_model.hpp"
#include "robomill/stability/regenerative_model.hpp"
#include "robomill/stability/zero_order.hpp"

namespace robomill::stability {

enum class ProcessDampingModel {
  linear_equivalent,  ///< 000 Eq 18-19 (Ahmadi's linear damper)
  energy_balance      ///< 003 §3.1: the energy-balance average coefficient (EB)
};

struct ProcessDamping {
  ProcessDampingModel model = ProcessDampingModel::linear_equivalent;
  double indentation_n_per_m3 = 1.5e14;  ///< K_sp (000 Eq 19) = K_d (003 Eq 1), N/m³
  double wear_land_m = 40e-6;            ///< flank wear land (contact length) w
  double friction = 0.3;                 ///< μ, F_t^d = μ F_r^d (003 Eq 1, 000 Eq 18)
  double clearance_rad = 0.0;            ///< energy balance only: flank clearance γ
  double amplitude_m = 0.0;              ///< energy balance with γ > 0: vibration amplitude A
};

/// 000 Eq 19: C_eq = K_sp w² dz / (4 v), N·s/m, for an engaged edge length dz
/// at cutting speed v = R Ω_s.
double equivalent_damping_n_s_per_m(double indentation_n_per_m3, double wear_land_m,
                                    double engaged_width_m, double cutting_speed_m_s);

/// Energy-balance coefficient (EB) for vibration at `chatter_frequency_hz`:
/// closed form for γ = 0, quadrature for γ > 0 (needs amplitude_m > 0).
double energy_balance_damping_n_s_per_m(double indentation_n_per_m3, double wear_land_m,
                                        double engaged_width_m, double cutting_speed_m_s,
                                        double chatter_frequency_hz, double clearance_rad = 0.0,
                                        double amplitude_m = 0.0);

/// The coefficient of one edge element under `params`' model.
double edge_damping_n_s_per_m(const ProcessDamping& params, double engaged_width_m,
                              double cutting_speed_m_s, double chatter_frequency_hz);

/// C_p (N·s/m, tool frame): the tooth-period average of the process-damping
/// forces of every engaged element at depth ap (≤ the tool overhang).
Eigen::Matrix3d process_damping_matrix(const RegenerativeModel& model, const ProcessDamping& params,
                                       double spindle_rad_s, double axial_depth_m,
                                       double chatter_frequency_hz);

/// 003's average process-damping coefficient c^p of a mode: uᵀ C_p u along
/// the mode's unit shape direction u, N·s/m.
double mode_process_damping_n_s_per_m(const Eigen::Matrix3d& damping, const dynamics::Mode& mode);

/// The modes with ζ_q + φ_qᵀ C φ_q / (2 ω_q) (c^t = c^s + c^p, 003 Eq 2),
/// clamped to [1e-6, 0.999] so the model stays valid.
dynamics::ModalModel with_added_damping(const dynamics::ModalModel& modes,
                                        const Eigen::Matrix3d& damping);

/// model.modes() damped by C_p at (spindle speed, depth, chatter frequency).
dynamics::ModalModel process_damped_modes(const RegenerativeModel& model,
                                          const ProcessDamping& params, double spindle_rad_s,
                                          double axial_depth_m, double chatter_frequency_hz);

/// 003 §3.2: all modes in one diagram, or the lowest envelope of the diagrams
/// of each mode alone (ModalModel::subset), each with its own process damping
/// at its own chatter frequency.
enum class MultiModeMethod { coupled, envelope };

struct ProcessDampedOptions {
  ZeroOrderOptions zero_order;  ///< grid, depth_max, A0 averaging
  MultiModeMethod method = MultiModeMethod::coupled;
  int max_evaluations = 40;  ///< ZOA limits per speed (and per mode for the envelope)
  double tolerance = 1e-4;   ///< relative change of depth and chatter frequency
  int threads = 1;           ///< speeds run in parallel; 0: all cores
  /// A0 when the caller already has it (MeanCuttingStiffnessBasis applied to
  /// the model's law, for many draws of one cut); nullopt computes it from
  /// the model (mean_cutting_stiffness_per_depth with zero_order's options).
  std::optional<Eigen::Matrix3d> mean_stiffness_per_depth;
};

/// Zero-order limits with optional process damping (nullopt: none) at each
/// speed. For the envelope, `mode` names the governing mode (index into
/// model.modes()); for the coupled diagram it is −1. `iterations` counts the
/// ZOA limits evaluated (summed over modes for the envelope).
std::vector<ZeroOrderLimit> process_damped_limits(const RegenerativeModel& model,
                                                  const std::optional<ProcessDamping>& params,
                                                  const std::vector<double>& spindle_rad_s,
                                                  const ProcessDampedOptions& options = {});

/// The envelope (minimum over one-mode diagrams) for a given A0, without
/// process damping; `mode` names the governing mode.
std::vector<ZeroOrderLimit> envelope_limits(const Eigen::Matrix3d& mean_stiffness_per_depth,
                                            int teeth, const dynamics::ModalModel& modes,
                                            const std::vector<double>& spindle_rad_s,
                                            const ZeroOrderOptions& options = {});

}  // namespace robomill::stability
