#pragma once
// The steady-state tool-tip offset of a flexible-joint robot under a periodic
// milling force (004 §3.1 Eq 1-2, §3.3):
//
//   M(q) Δq̈ + C Δq̇ + K Δq = Jvᵀ F_E(t),    Δd = Jv Δq             (004 Eq 1, 2)
//
// The paper integrates Eq 1 in time (MATLAB lsim) until the response is
// periodic. The system is linear and time-invariant at a posture, so the
// periodic steady state is exact in the frequency domain: for every harmonic
// k of the force (force_harmonics.hpp), in the cell frame F_k = R c_k,
//
//   Δd_k = Jv (K − (kω)² M + i kω C)⁻¹ Jvᵀ F_k,   Δd(t) = Σ_k a_k Re(Δd_k e^{ikωt})
//
// (a_0 = 1, a_k = 2), then the amplitude is read off the reconstructed period.
// `steady_state_offset_time_domain` integrates Eq 1 instead (classical RK4
// with the force evaluated exactly at every stage), to check the above.
//
// What "the amplitude d_i" of 004 §3.3 is, is not written in the paper; the
// measures below are the candidate readings (docs/planning.md): the offset
// includes the static deflection under the mean force, which dominates when
// the tooth frequency lies above the robot's modes.

#include <Eigen/Core>
#include <Eigen/LU>
#include <complex>
#include <string_view>
#include <vector>

#include "robomill/cutting/milling_forces.hpp"
#include "robomill/planning/force_harmonics.hpp"
#include "robomill/robot/robot_model.hpp"

namespace robomill::planning {

/// Which number of the steady state is "the amplitude of the offset".
enum class OffsetMeasure {
  peak,       ///< max over the period of |Δd(t)| (the offset, static part included)
  vibration,  ///< max over the period of |Δd(t) − mean Δd| (the oscillation alone)
  rms,        ///< √(mean over the period of |Δd(t)|²)
  mean,       ///< |mean Δd|, the static deflection under the mean force
  /// max over t ≥ 0 of |Δd(t)| when the cut starts at t = 0 on a robot at
  /// rest: the steady state plus the free transient that the start excites
  /// (what a time integration from rest, 004's lsim, shows as its largest
  /// offset; see docs/planning.md for why this reading matches 004 Table 2).
  startup,
};

std::string_view to_string(OffsetMeasure measure) noexcept;

/// The steady state over one period, all measures (m), cell frame.
struct OffsetResponse {
  double peak_m = 0.0;
  double vibration_m = 0.0;
  double rms_m = 0.0;
  double mean_m = 0.0;
  double startup_m = 0.0;       ///< only when requested (0 otherwise)
  double startup_time_s = 0.0;  ///< when the start-up maximum occurs
  Eigen::Vector3d mean_offset_m = Eigen::Vector3d::Zero();
  double measure(OffsetMeasure which) const noexcept;
};

/// Scratch space for steady_state_offset: sized on first use for a robot
/// and a series, then reused without allocating (one per thread).
class OffsetWorkspace {
 public:
  void resize(int dof, const ForceHarmonics& harmonics);

  Eigen::MatrixXcd dynamic_stiffness;        // K − ω² M + iω C
  Eigen::PartialPivLU<Eigen::MatrixXcd> lu;  // of the above
  Eigen::VectorXcd generalized_force, joint_response;
  std::vector<Eigen::Vector3cd> tip_harmonics;  // Δd_k
  Eigen::MatrixXcd joint_harmonics;             // ΔQ_k as columns
  std::vector<std::complex<double>> twiddle;    // e^{2πi j / M}
  std::vector<Eigen::Vector3d> trajectory;      // Δd(t_m)
};

/// The robot's structural matrices at one posture (004 Eq 1): what the
/// harmonic loop needs, computed once per path point.
struct PostureDynamics {
  Eigen::MatrixXd mass;                               ///< M(q)
  Eigen::MatrixXd damping;                            ///< C
  Eigen::MatrixXd stiffness;                          ///< K
  Eigen::Matrix<double, 3, Eigen::Dynamic> jacobian;  ///< Jv (cell frame)
};
PostureDynamics posture_dynamics(const robot::RobotModel& model, const Eigen::VectorXd& q);

/// The harmonic steady state at a posture for the force R c_k (R = tool frame
/// → cell frame). Allocation-free once `workspace` is sized, except with
/// `with_startup`: the start-up maximum needs the free response from the
/// state q = q̇ = 0 at t = 0, Δd(t) = Δd_ss(t) + Σ_r g_r e^{λ_r t}, with λ_r,
/// g_r from the eigen-decomposition of the 2n-state matrix (one per call); it
/// is sampled at the series' instants until the decaying transient can no
/// longer raise the maximum.
OffsetResponse steady_state_offset(const PostureDynamics& dynamics,
                                   const Eigen::Matrix3d& tool_to_cell,
                                   const ForceHarmonics& harmonics, OffsetWorkspace& workspace,
                                   bool with_startup = false);

/// The same by direct time integration of Eq 1 (classical Runge-Kutta, the
/// force `force_model` evaluated at every stage), started from the static
/// deflection under the mean force (or from rest with `from_rest`, which
/// then also records the largest |Δd| since t = 0 as startup_m), over whole periods until two
/// successive periods differ by less than `tolerance` (relative, on the peak) or `max_periods`
/// pass; the measures are taken over the last period sampled at `steps_per_period` instants.
/// `periods_used` reports the periods run.
OffsetResponse steady_state_offset_time_domain(const PostureDynamics& dynamics,
                                               const Eigen::Matrix3d& tool_to_cell,
                                               const cutting::MillingForceModel& force_model,
                                               double period_s, int steps_per_period,
                                               int max_periods, double tolerance,
                                               int* periods_used = nullptr, bool from_rest = false);

}  // namespace robomill::planning
