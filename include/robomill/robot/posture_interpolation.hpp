#pragma once
// Posture-dependent dynamics by inverse-distance weighting in joint space
// (001 §2.2.2, Eq 16-18, validated in §3.1 on 15 measured postures).
//
// A library holds s measured postures q_i (joint angles, rad) each with a
// payload v_i (FRFs, modal parameters, anything linear). At a query posture q
//
//   d_i = ‖W (q − q_i)‖₂                                          (001 Eq 17)
//   α_i = d_i^(−p) / Σ_j d_j^(−p)                                 (001 Eq 18)
//   v(q) = Σ_i α_i v_i                                            (001 Eq 16)
//
// with W = diag(joint weights) (1 in the paper). 001 Eq 18 uses p = 1 (the
// plain inverse distance), so that is the default; p = 2 (Shepard's usual
// choice) makes the nearest postures dominate more. At a measured posture
// (d_i below the tolerance) the payload is returned exactly: Eq 18 is the
// limit 0/0 there.

#include <Eigen/Core>
#include <complex>
#include <vector>

namespace robomill::robot {

struct IdwOptions {
  /// Power p of the inverse distance, > 0; 001 Eq 18 uses 1.
  double power = 1.0;
  /// Per-joint weights of the distance (empty: all 1, as 001 Eq 17), ≥ 0 and
  /// not all zero. A weight of 2 makes a radian of that joint count double.
  Eigen::VectorXd joint_weights;
  /// A query within this weighted distance (rad) of a measured posture takes
  /// that posture's payload exactly.
  double exact_tolerance_rad = 1e-12;
};

struct IdwResult {
  Eigen::VectorXd value;    ///< Σ α_i v_i (001 Eq 16)
  Eigen::VectorXd weights;  ///< α_i ≥ 0, Σ α_i = 1 (001 Eq 18)
  int exact_index = -1;     ///< the measured posture hit exactly, or −1
};

/// The weights α_i of 001 Eq 17-18 alone (value left empty). Throws
/// std::invalid_argument (with the offending posture or joint named) for an
/// empty library, postures of different lengths, non-finite angles or
/// weights, p ≤ 0 or a negative tolerance.
IdwResult idw_weights(const std::vector<Eigen::VectorXd>& postures_rad,
                      const Eigen::VectorXd& query_rad, const IdwOptions& options = {});

/// The generic interpolation of 001 Eq 16: payloads may have any length but
/// all the same, one per posture, finite. Throws std::invalid_argument as
/// idw_weights does, and for mismatched or non-finite payloads.
IdwResult idw_interpolate(const std::vector<Eigen::VectorXd>& postures_rad,
                          const std::vector<Eigen::VectorXd>& payloads,
                          const Eigen::VectorXd& query_rad, const IdwOptions& options = {});

/// One measured mode along one tool-frame axis (0 = x, 1 = y, 2 = z), in the
/// form dynamics::directional_mode takes.
struct DirectionalModeParameters {
  int axis = 0;
  double natural_frequency_hz = 0.0;
  double damping_ratio = 0.0;
  double stiffness_n_per_m = 0.0;
};

/// How the modal stiffness is averaged.
enum class StiffnessAveraging {
  /// Average 1/k (default): the static receptance Σ 1/k is linear in the
  /// compliances, so this matches 001 Eq 16's averaging of FRFs at low
  /// frequency, and joint compliances add in series (C = J Kq⁻¹ Jᵀ). The
  /// result is a weighted harmonic mean, inside [min k, max k].
  kCompliance,
  /// Average k itself (a weighted arithmetic mean).
  kStiffness,
};

/// Interpolates modal tables: every posture lists the same modes in the same
/// order (same axis per position, e.g. the x modes then the y modes). fn and ζ
/// are averaged directly, k as chosen. Throws std::invalid_argument for
/// tables of different lengths or axis orders, or a parameter that is not
/// positive and finite (ζ must lie in (0, 1)).
std::vector<DirectionalModeParameters> interpolate_modal_tables(
    const std::vector<Eigen::VectorXd>& postures_rad,
    const std::vector<std::vector<DirectionalModeParameters>>& tables,
    const Eigen::VectorXd& query_rad, const IdwOptions& options = {},
    StiffnessAveraging stiffness = StiffnessAveraging::kCompliance);

/// Measured FRFs of one posture on a frequency grid: rows are frequencies,
/// columns channels (Hxx, Hyy, …), receptance in m/N.
struct PostureFrf {
  Eigen::VectorXd frequency_hz;
  Eigen::MatrixXcd receptance_m_per_n;
};

/// 001 Eq 16 on FRFs: real and imaginary parts averaged with the same
/// weights (the complex average). All postures must share the grid (to 1e-9
/// relative) and the channel count; values must be finite. Throws
/// std::invalid_argument otherwise.
PostureFrf interpolate_frfs(const std::vector<Eigen::VectorXd>& postures_rad,
                            const std::vector<PostureFrf>& frfs, const Eigen::VectorXd& query_rad,
                            const IdwOptions& options = {});

}  // namespace robomill::robot
