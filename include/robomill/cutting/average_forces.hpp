#pragma once
// Closed-form mean milling forces of the linear law (Altintas, Manufacturing
// Automation, Eq 2.51), in robomill's tool frame. Used to identify cutting
// coefficients from measured mean forces (000 §6.2, 001 §3.2) and to check the
// time-domain force model.

#include <Eigen/Core>

#include "robomill/cutting/cutting_law.hpp"
#include "robomill/cutting/engagement.hpp"

namespace robomill::cutting {

/// The 3x6 matrix A with  F̄ = A · [Ktc Krc Kac Kte Kre Kae]ᵀ  for a flat end mill
/// of `teeth` teeth at axial depth ap, feed per tooth fz and engagement [φst, φex],
/// averaged over a tooth period (helix does not change a period's mean):
///   F̄x = N ap/2π [−fz Ktc I_sc − fz Krc I_ss − Kte I_c − Kre I_s]
///   F̄y = N ap/2π [ fz Ktc I_ss − fz Krc I_sc + Kte I_s − Kre I_c]
///   F̄z = N ap/2π [−fz Kac I_s − Kae I_1]
/// with I_sc = ∫sinφ cosφ, I_ss = ∫sin²φ, I_c = ∫cosφ, I_s = ∫sinφ, I_1 = ∫dφ.
Eigen::Matrix<double, 3, 6> mean_force_matrix(int teeth, double axial_depth_m,
                                              double feed_per_tooth_m,
                                              const Engagement& engagement);

/// F̄ of the linear law (the product of the matrix above and the coefficients).
Eigen::Vector3d mean_force_n(const LinearLaw& law, int teeth, double axial_depth_m,
                             double feed_per_tooth_m, const Engagement& engagement);

/// The six coefficients as a vector, in the order of mean_force_matrix().
Eigen::Matrix<double, 6, 1> to_vector(const LinearLaw& law);
LinearLaw linear_law_from_vector(const Eigen::Matrix<double, 6, 1>& coefficients);

}  // namespace robomill::cutting
