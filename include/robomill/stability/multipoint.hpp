#pragma once
// What paper 000's multipoint-contact model (§3 and §5, Eq 32-38) adds to the
// ordinary tip model of regenerative_model.hpp.
//
// The tool is not a rigid body carrying the tip's modes: each axial node k
// sees mode i with its own mass-normalized shape ψ_i(z_k) (000 Table 2 and
// Eq 35, measured at 3, 12, 24 and 36 mm from the free end), so the modal
// coupling becomes
//
//   P(t) = Σ_k ψ(z_k)ᵀ W_k(t) ψ(z_k)             (000 Eq 32, 36-37)
//
// instead of ψ(0)ᵀ (Σ_k W_k) ψ(0); process damping likewise (Eq 38). And the
// engagement g_{j,k} of each node may be the actual, deformation-corrected
// one g^a (Eq 20): its entry angle from the contact-boundary iteration
// (deflection/contact_boundary.hpp), which depends on the axial depth.

#include <functional>
#include <vector>

#include "robomill/dynamics/axial_shape.hpp"

namespace robomill::stability {

struct MultipointStructure {
  /// One per mode of the modal model, in its order: the mode's shape along
  /// the tool (distance from the tip); the shape at height z is the tip shape
  /// times shape(z)/shape(0). An empty AxialShape keeps the tip shape all
  /// along the tool (a rigid tool in that mode). Empty vector: every mode rigid.
  std::vector<dynamics::AxialShape> mode_shapes;
  /// The entry angle (rad, robomill's convention) of the edge at height z for
  /// axial depth ap — 000 Eq 20's g^a; the exit stays at the nominal angle.
  /// Empty: the nominal engagement. Must be safe to call from several threads.
  std::function<double(double axial_depth_m, double height_m)> entry_angle_rad;

  bool empty() const noexcept { return mode_shapes.empty() && !entry_angle_rad; }
};

}  // namespace robomill::stability
