#include "robomill/cutting/cutting_law.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace robomill::cutting {
namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;  // clang 14 lacks aggregate CTAD

void require_finite(double value, const char* name) {
  if (!std::isfinite(value))
    throw std::invalid_argument(std::string(name) + " must be finite");
}

void require_non_negative(double value, const char* name) {
  require_finite(value, name);
  if (value < 0.0)
    throw std::invalid_argument(std::string(name) + " must not be negative");
}

void require_positive(double value, const char* name) {
  require_finite(value, name);
  if (!(value > 0.0))
    throw std::invalid_argument(std::string(name) + " must be positive");
}

}  // namespace

std::string_view law_name(const CuttingLaw& law) noexcept {
  return std::visit(
      Overloaded{[](const LinearLaw&) { return std::string_view("linear"); },
                 [](const ExponentialLaw&) { return std::string_view("exponential"); },
                 [](const FractionalLaw&) { return std::string_view("fractional"); },
                 [](const SizeDependentLaw&) { return std::string_view("size_dependent"); }},
      law);
}

void validate(const CuttingLaw& law) {
  std::visit(Overloaded{[](const LinearLaw& l) {
                          // Shear coefficients are pressures and positive in practice; a
                          // negative axial coefficient is legitimate (helix direction).
                          require_positive(l.Ktc_pa, "Ktc");
                          require_non_negative(l.Krc_pa, "Krc");
                          require_finite(l.Kac_pa, "Kac");
                          require_non_negative(l.Kte_n_per_m, "Kte");
                          require_non_negative(l.Kre_n_per_m, "Kre");
                          require_finite(l.Kae_n_per_m, "Kae");
                        },
                        [](const ExponentialLaw& l) {
                          require_positive(l.kF_n_per_m, "kF");
                          require_positive(l.exponent, "exponent");
                          require_positive(l.reference_chip_m, "chip_unit");
                          require_non_negative(l.radial_ratio, "kr");
                          require_finite(l.axial_ratio, "ka");
                        },
                        [](const FractionalLaw& l) {
                          require_positive(l.k0_n_per_m, "k0");
                          require_positive(l.hs_m, "hs");
                          require_non_negative(l.r, "r");
                          require_non_negative(l.radial_ratio, "kr");
                          require_finite(l.axial_ratio, "ka");
                        },
                        [](const SizeDependentLaw& l) {
                          require_positive(l.kc1_pa, "kc1");
                          require_finite(l.b1, "b1");
                          require_non_negative(l.kc2, "kc2");
                          require_finite(l.b2, "b2");
                          require_positive(l.reference_chip_m, "chip_unit");
                        }},
             law);
}

ResolvedLaw::ResolvedLaw(const CuttingLaw& law, double mean_chip_m) : law_(law) {
  validate(law);
  std::visit(Overloaded{[&](const LinearLaw& l) {
                          kind_ = Kind::linear;
                          linear_ = l;
                        },
                        [&](const ExponentialLaw& l) {
                          kind_ = Kind::ratio;
                          radial_ratio_ = l.radial_ratio;
                          axial_ratio_ = l.axial_ratio;
                        },
                        [&](const FractionalLaw& l) {
                          kind_ = Kind::ratio;
                          radial_ratio_ = l.radial_ratio;
                          axial_ratio_ = l.axial_ratio;
                        },
                        [&](const SizeDependentLaw& l) {
                          // 004 Eq A2 evaluated once at the process's mean chip thickness
                          // (Eq A3); afterwards the law is linear with dF_r = K_r dF_t.
                          if (!(mean_chip_m > 0.0) || !std::isfinite(mean_chip_m)) {
                            throw std::invalid_argument(
                                "size-dependent law needs a positive mean chip thickness");
                          }
                          const double chip_ratio = mean_chip_m / l.reference_chip_m;
                          const double tangential_pa = l.kc1_pa * std::pow(chip_ratio, l.b1);
                          const double radial_ratio = l.kc2 * std::pow(chip_ratio, l.b2);
                          kind_ = Kind::linear;
                          linear_ = LinearLaw{};
                          linear_.Ktc_pa = tangential_pa;
                          linear_.Krc_pa = radial_ratio * tangential_pa;
                        }},
             law);
}

double ResolvedLaw::tangential_force(double chip_m) const noexcept {
  if (const auto* exponential = std::get_if<ExponentialLaw>(&law_)) {
    // 002 Eq 25.
    return exponential->kF_n_per_m *
           std::pow(chip_m / exponential->reference_chip_m, exponential->exponent);
  }
  const auto& fractional = std::get<FractionalLaw>(law_);
  // 002 Eq 26: finite slope k0/hs at h = 0, tends to k0 r h/hs for h ≫ hs.
  const double normalized = chip_m / fractional.hs_m;
  return fractional.k0_n_per_m * (normalized + fractional.r * normalized * normalized) /
         (1.0 + normalized);
}

}  // namespace robomill::cutting
