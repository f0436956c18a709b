#include "robomill/cutting/average_forces.hpp"

#include <cmath>
#include <numbers>

namespace robomill::cutting {

Eigen::Matrix<double, 3, 6> mean_force_matrix(int teeth, double axial_depth_m,
                                              double feed_per_tooth_m,
                                              const Engagement& engagement) {
  const double a = engagement.entry_rad;
  const double b = engagement.exit_rad;
  // Definite integrals over [φst, φex].
  const double i_sc = 0.5 * (std::sin(b) * std::sin(b) - std::sin(a) * std::sin(a));
  const double i_ss = 0.5 * (b - a) - 0.25 * (std::sin(2.0 * b) - std::sin(2.0 * a));
  const double i_c = std::sin(b) - std::sin(a);
  const double i_s = std::cos(a) - std::cos(b);
  const double i_1 = b - a;
  const double scale = teeth * axial_depth_m / (2.0 * std::numbers::pi);
  const double fz = feed_per_tooth_m;

  Eigen::Matrix<double, 3, 6> matrix;
  //        Ktc        Krc        Kac       Kte    Kre    Kae
  matrix << -fz * i_sc, -fz * i_ss, 0.0, -i_c, -i_s, 0.0,  //
      fz * i_ss, -fz * i_sc, 0.0, i_s, -i_c, 0.0,          //
      0.0, 0.0, -fz * i_s, 0.0, 0.0, -i_1;
  return scale * matrix;
}

Eigen::Matrix<double, 6, 1> to_vector(const LinearLaw& law) {
  Eigen::Matrix<double, 6, 1> v;
  v << law.Ktc_pa, law.Krc_pa, law.Kac_pa, law.Kte_n_per_m, law.Kre_n_per_m, law.Kae_n_per_m;
  return v;
}

LinearLaw linear_law_from_vector(const Eigen::Matrix<double, 6, 1>& v) {
  return LinearLaw{v[0], v[1], v[2], v[3], v[4], v[5]};
}

Eigen::Vector3d mean_force_n(const LinearLaw& law, int teeth, double axial_depth_m,
                             double feed_per_tooth_m, const Engagement& engagement) {
  return mean_force_matrix(teeth, axial_depth_m, feed_per_tooth_m, engagement) * to_vector(law);
}

}  // namespace robomill::cutting
