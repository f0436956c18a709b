#pragma once
// The linear periodic delay model of regenerative milling (000 Eq 14, 16,
// 32-38; 001 Eq 14): the dynamic chip h_d = nᵀ (q(t) − q(t − τ)) of every
// engaged edge element produces the force F_d = W(t) (q(t) − q(t − τ)), with
//   W(ϕ) = Σ_{j,k} g_{jk} db_k · T(φ_jk, κ_k) [Ktc Krc Kac]ᵀ · n(φ_jk, κ_k)ᵀ,
// T the projection of 001 Eq 11 and n = (sin κ sin φ, sin κ cos φ, −cos κ).
// In modal coordinates η (q = Φ η, Φ the mass-normalized shapes) this is
//   η'' + 2ζΩ η' + Ω² η = P(t) (η(t) − η(t − τ)),   P = Φᵀ W Φ,   τ = 2π/(N Ω_s).
// W depends on the spindle angle only, so P is sampled once per depth over a
// tooth period in angle and reused at every spindle speed.

#include <Eigen/Core>
#include <array>
#include <functional>
#include <vector>

#include "robomill/cutting/cutting_law.hpp"
#include "robomill/cutting/process.hpp"
#include "robomill/dynamics/modal_model.hpp"
#include "robomill/stability/multipoint.hpp"
#include "robomill/tool/tool.hpp"

namespace robomill::stability {

/// P(t) over one tooth period, m steps of h = τ/m: node values at t_k = k h
/// (k = 0..m; the mean over [t_k − h/2, t_k + h/2]) and the mean over each
/// step [t_k, t_k+1] (k = 0..m−1).
struct CouplingSamples {
  std::vector<Eigen::MatrixXd> nodes;
  std::vector<Eigen::MatrixXd> means;
  /// (1/τ) ∫ P dt: what the zero-order approximation uses.
  Eigen::MatrixXd average;
};

class RegenerativeModel {
 public:
  /// `law` must reduce to a linear law (linear or size-dependent); throws
  /// std::invalid_argument otherwise. `process.axial_depth_m` is ignored: the
  /// depth is the variable of every stability query.
  /// `multipoint` (optional) makes it 000's multipoint-contact model: mode
  /// shapes along the tool and/or the deformation-corrected engagement
  /// (multipoint.hpp); throws std::invalid_argument when its mode count
  /// differs from the modal model's.
  RegenerativeModel(const tool::Tool& tool, const cutting::CuttingLaw& law,
                    const cutting::MillingProcess& process, const dynamics::ModalModel& modes,
                    MultipointStructure multipoint = {});

  /// 3x3 W at spindle angle ϕ for axial depth ap (N/m), before the modal
  /// projection, at the tool tip (Σ over the elements; with mode shapes along
  /// the tool the modal coupling is not ψ(0)ᵀ W ψ(0): see modal_coupling).
  Eigen::Matrix3d cutting_stiffness(double rotation_rad, double axial_depth_m) const;

  /// Σ_s cutting_stiffness((s + ½) period / samples, ap) over s < samples,
  /// the same values summed in the same order, with the edge's elements and
  /// their engagement found once instead of at every angle (the period
  /// average of the zero-order method, zero_order.hpp).
  Eigen::Matrix3d cutting_stiffness_sum(double period_rad, int samples, double axial_depth_m) const;

  /// The same sum split by shear coefficient: W is linear in (K_tc, K_rc,
  /// K_ac), so cutting_stiffness_sum = K_tc S[0] + K_rc S[1] + K_ac S[2]
  /// (to round-off: the terms are summed in another order). S depends on the
  /// tool, the process and the depth only, so one S serves every draw of the
  /// coefficients and the structure (the stability band, issue 33).
  std::array<Eigen::Matrix3d, 3> cutting_stiffness_sum_per_coefficient(double period_rad,
                                                                       int samples,
                                                                       double axial_depth_m) const;

  /// P = Σ_k ψ(z_k)ᵀ W_k ψ(z_k) at spindle angle ϕ (000 Eq 32, 37): the modal
  /// coupling the Floquet solver takes; ψ(0)ᵀ W ψ(0) for a tip model.
  Eigen::MatrixXd modal_coupling(double rotation_rad, double axial_depth_m) const;

  /// P sampled over a tooth period with `steps` steps; each step mean is
  /// integrated with `substeps` midpoint samples so that the entry and exit
  /// discontinuities are resolved.
  CouplingSamples sample(double axial_depth_m, int steps, int substeps = 8) const;

  /// Process damping of Ahmadi's linear-equivalent model (000 Eq 18-19): the
  /// force on the tool is F_c = C_eq' · D(ϕ) q', with C_eq' = K_sp w² / (4 v)
  /// the damping per unit engaged width and
  ///   D(ϕ) = Σ g db · T(φ, κ) [μ 1 0]ᵀ · nᵀ
  /// (radial force C_eq v_n with v_n = nᵀ q' the velocity into the part, and
  /// its friction share μ tangentially; T's radial column is −n, so the force
  /// opposes the motion). Returns D at spindle angle ϕ, m.
  Eigen::Matrix3d damping_shape(double rotation_rad, double axial_depth_m, double friction) const;

  /// Φᵀ D Φ sampled like sample(): the modal process-damping matrix per unit
  /// C_eq'; the Floquet solver's damping is C(t) = −C_eq' Φᵀ D Φ.
  CouplingSamples sample_damping(double axial_depth_m, int steps, double friction,
                                 int substeps = 8) const;

  /// True when W is proportional to the depth (straight flutes on a
  /// cylindrical edge), so samples at 1 m scale to any depth.
  bool proportional_to_depth() const noexcept { return proportional_; }
  const MultipointStructure& multipoint() const noexcept { return multipoint_; }

  const dynamics::ModalModel& modes() const noexcept { return modes_; }
  const tool::Tool& tool() const noexcept { return tool_; }
  const cutting::MillingProcess& process() const noexcept { return process_; }
  const cutting::LinearLaw& law() const noexcept { return law_; }
  /// Largest depth the edge discretization covers (the tool overhang).
  double max_depth_m() const noexcept { return tool_.overhang_m(); }

 private:
  tool::Tool tool_;
  cutting::MillingProcess process_;
  cutting::LinearLaw law_;
  dynamics::ModalModel modes_;
  Eigen::Matrix<double, 3, Eigen::Dynamic> shapes_;
  MultipointStructure multipoint_;
  bool shapes_along_tool_ = false;
  bool proportional_ = false;

  std::vector<tool::EdgeElement> edge(double axial_depth_m) const;
  /// The entry-angle override by height at depth ap, or empty.
  std::function<double(double)> entry_at(double axial_depth_m) const;
  /// Σ over engaged (element, tooth) of the modal projection of
  /// db · T [c]ᵀ · nᵀ, with the element's own shapes when they vary along
  /// the tool (c: the shear coefficients, or [μ 1 0] for process damping).
  Eigen::MatrixXd modal_sum(double rotation_rad, double axial_depth_m,
                            const Eigen::Vector3d& coefficients) const;
  template <class ModalOf>
  CouplingSamples sample_modal(ModalOf&& modal_at, int steps, int substeps) const;
};

}  // namespace robomill::stability
