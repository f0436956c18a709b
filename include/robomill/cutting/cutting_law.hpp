#pragma once
// Cutting-force laws: the force a chip of thickness h and width b exerts on
// one edge element, split into tangential (against the cutting speed), radial
// (normal to the edge, towards the tool axis) and axial components.
//
// All laws give zero force for h ≤ 0 (002 Eq 27): an edge that does not
// remove material does not cut.

#include <string_view>
#include <variant>

namespace robomill::cutting {

/// Linear mechanistic law with shear and edge coefficients (000 Eq 13,
/// 001 Eq 12, 002 Eq 24):  F_q = (K_qc h + K_qe) b  for q ∈ {t, r, a}.
struct LinearLaw {
  double Ktc_pa = 0.0, Krc_pa = 0.0, Kac_pa = 0.0;                 ///< shear coefficients, N/m²
  double Kte_n_per_m = 0.0, Kre_n_per_m = 0.0, Kae_n_per_m = 0.0;  ///< edge coefficients, N/m
};

/// Exponential law (002 Eq 25) with the radial ratio of 002 Eq 28:
///   F_t = kF (h / h_ref)^m b,  F_r = kr F_t,  F_a = ka F_t.
/// h_ref is the unit the user's kF refers to (kF is the force per unit width
/// at h = h_ref), which keeps kF in plain N/m whatever m is.
struct ExponentialLaw {
  double kF_n_per_m = 0.0;
  double exponent = 1.0;  ///< m < 1 for real materials
  double reference_chip_m = 1e-3;
  double radial_ratio = 0.0;  ///< kr
  double axial_ratio = 0.0;   ///< ka
};

/// Fractional law (002 Eq 26) with the radial ratio of 002 Eq 28:
///   F_t = k0 b (h/hs + r (h/hs)²) / (1 + h/hs),  F_r = kr F_t,  F_a = ka F_t.
struct FractionalLaw {
  double k0_n_per_m = 0.0;
  double hs_m = 0.0;
  double r = 0.0;
  double radial_ratio = 0.0;
  double axial_ratio = 0.0;
};

/// Chip-thickness-dependent coefficients (004 Appendix A, Eq A1-A3):
///   K_tc = kc1 (t_c / h_ref)^b1,   K_r = kc2 (t_c / h_ref)^b2,
///   dF_t = K_tc h dz,  dF_r = K_r dF_t,
/// where t_c is the mean chip thickness over the engagement (Eq A3) and K_r is
/// a ratio (the paper's dF_r = K_rc dF_t). The paper does not state the units
/// of kc1 or t_c; h_ref makes that choice explicit (see docs/assumptions.md).
struct SizeDependentLaw {
  double kc1_pa = 0.0;
  double b1 = 0.0;
  double kc2 = 0.0;
  double b2 = 0.0;
  double reference_chip_m = 1e-3;
};

using CuttingLaw = std::variant<LinearLaw, ExponentialLaw, FractionalLaw, SizeDependentLaw>;

std::string_view law_name(const CuttingLaw& law) noexcept;

/// Throws std::invalid_argument naming the coefficient if a law is not
/// physical (non-finite values, negative pressures, hs ≤ 0, ...).
void validate(const CuttingLaw& law);

/// Tangential, radial and axial force on one edge element, N.
struct EdgeForce {
  double tangential_n = 0.0;
  double radial_n = 0.0;
  double axial_n = 0.0;
};

/// A law ready for the inner loop: size-dependent coefficients are resolved
/// for the process's mean chip thickness, so evaluation is branch-light and
/// allocation-free.
class ResolvedLaw {
 public:
  /// `mean_chip_m` is t_c of 004 Eq A3; only the size-dependent law uses it.
  ResolvedLaw(const CuttingLaw& law, double mean_chip_m);

  /// Force on an element cutting a chip of thickness `chip_m` and width
  /// `width_m`; zero for chip_m ≤ 0.
  EdgeForce operator()(double chip_m, double width_m) const noexcept {
    if (!(chip_m > 0.0))
      return {};
    switch (kind_) {
      case Kind::linear:
        return {(linear_.Ktc_pa * chip_m + linear_.Kte_n_per_m) * width_m,
                (linear_.Krc_pa * chip_m + linear_.Kre_n_per_m) * width_m,
                (linear_.Kac_pa * chip_m + linear_.Kae_n_per_m) * width_m};
      case Kind::ratio: {
        const double tangential = tangential_force(chip_m) * width_m;
        return {tangential, radial_ratio_ * tangential, axial_ratio_ * tangential};
      }
    }
    return {};
  }

  /// The linear coefficients this law reduces to (for the linear and the
  /// size-dependent law); used by summaries and by the stability engine.
  bool is_linear() const noexcept { return kind_ == Kind::linear; }
  const LinearLaw& linear() const noexcept { return linear_; }

 private:
  double tangential_force(double chip_m) const noexcept;  // per unit width

  enum class Kind { linear, ratio };
  Kind kind_ = Kind::linear;
  LinearLaw linear_;
  CuttingLaw law_;
  double radial_ratio_ = 0.0;
  double axial_ratio_ = 0.0;
};

}  // namespace robomill::cutting
