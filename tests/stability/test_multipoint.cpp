// 000's multipoint-contact model (§3, §5, Eq 32-38) in the regenerative model:
// with shapes that do not vary along the tool it is the ordinary tip model;
// with 000 Table 2's shapes the nodes higher up couple less; the
// deformation-corrected engagement shortens the contact and raises the limit.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "robomill/dynamics/axial_shape.hpp"
#include "robomill/stability/lobes.hpp"
#include "robomill/stability/multipoint.hpp"
#include "robomill/stability/regenerative_model.hpp"

namespace test_multipoint_cpp {

namespace {

using namespace robomill;
constexpr double kPi = std::numbers::pi;

// The 000 case: Ø12 mm, 3 teeth, 45° helix, 61 mm overhang; Eq 39
// coefficients; ae 4 mm down milling; Table 2's two tool modes with their
// tip masses (1/ψ(0)², ψ extrapolated to the tip).
struct Case000 {
  tool::Tool tool{[] {
    tool::ToolSpec s;
    s.diameter_m = 0.012;
    s.teeth = 3;
    s.helix_rad = kPi / 4;
    s.overhang_m = 0.061;
    return s;
  }()};
  cutting::CuttingLaw law{cutting::LinearLaw{855e6, 270.93e6, 0.0, 15.64e3, 14.167e3, 0.0}};
  cutting::MillingProcess process{[] {
    cutting::MillingProcess p;
    p.spindle_rad_s = 10000 * 2 * kPi / 60;
    p.feed_per_tooth_m = 0.02e-3;
    p.axial_depth_m = 2e-3;
    p.radial_depth_m = 4e-3;
    p.direction = cutting::MillingDirection::down;
    return p;
  }()};
  dynamics::AxialShape shape_x{{0.003, 0.012, 0.024, 0.036}, {3.232, 2.264, 1.738, 1.075}};
  dynamics::AxialShape shape_y{{0.003, 0.012, 0.024, 0.036}, {4.119, 3.347, 2.315, 1.755}};
  dynamics::ModalModel modes{{{2060.49, 0.0237, Eigen::Vector3d(shape_x.at(0.0), 0, 0)},
                              {2045.24, 0.0207, Eigen::Vector3d(0, shape_y.at(0.0), 0)}}};
};

stability::LobeOptions lobe_options(double depth_max_m) {
  stability::LobeOptions options;
  options.steps = 30;
  options.depth_max_m = depth_max_m;
  options.threads = 1;
  return options;
}

TEST(Multipoint, ShapesConstantAlongTheToolGiveTheTipModel) {
  const Case000 c;
  const stability::RegenerativeModel tip(c.tool, c.law, c.process, c.modes);
  stability::MultipointStructure constant;
  constant.mode_shapes = {dynamics::AxialShape({0.0}, {c.shape_x.at(0.0)}),
                          dynamics::AxialShape({0.0}, {c.shape_y.at(0.0)})};
  const stability::RegenerativeModel multipoint(c.tool, c.law, c.process, c.modes, constant);
  for (int s = 0; s < 24; ++s) {
    const double angle = s * 2 * kPi / 3 / 24 + 0.013;
    const Eigen::MatrixXd a = tip.modal_coupling(angle, 3e-3);
    const Eigen::MatrixXd b = multipoint.modal_coupling(angle, 3e-3);
    EXPECT_LT((a - b).norm(), 1e-12 * std::max(1.0, a.norm())) << angle;
  }
  const stability::LobeOptions options = lobe_options(10e-3);
  const std::vector<double> speeds = {8200 * 2 * kPi / 60, 11500 * 2 * kPi / 60};
  const auto l1 = stability::stability_boundary(tip, speeds, options);
  const auto l2 = stability::stability_boundary(multipoint, speeds, options);
  // The same sums in another order: equal to round-off, which the bracket
  // search turns into ~1e-9 relative (far inside its 1e-3 tolerance).
  for (std::size_t i = 0; i < speeds.size(); ++i)
    EXPECT_NEAR(l1[i].depth_limit_m, l2[i].depth_limit_m, 1e-7 * l1[i].depth_limit_m) << i;
}

TEST(Multipoint, Table2ShapesWeakenTheCouplingOfHigherNodes) {
  // ψ falls from 3.6 at the tip to 1.1 at 36 mm: elements up the flute move
  // the modes less, so over a deep cut the multipoint coupling is smaller
  // than the tip model's and the limit higher.
  const Case000 c;
  const stability::RegenerativeModel tip(c.tool, c.law, c.process, c.modes);
  stability::MultipointStructure along;
  along.mode_shapes = {c.shape_x, c.shape_y};
  const stability::RegenerativeModel multipoint(c.tool, c.law, c.process, c.modes, along);
  double tip_trace = 0.0, multipoint_trace = 0.0;
  for (int s = 0; s < 96; ++s) {
    const double angle = (s + 0.5) * 2 * kPi / 3 / 96;
    tip_trace += std::abs(tip.modal_coupling(angle, 8e-3).trace());
    multipoint_trace += std::abs(multipoint.modal_coupling(angle, 8e-3).trace());
  }
  EXPECT_LT(multipoint_trace, 0.9 * tip_trace);
  const stability::LobeOptions options = lobe_options(20e-3);
  const std::vector<double> speeds = {11500 * 2 * kPi / 60};
  const double tip_limit = stability::stability_boundary(tip, speeds, options)[0].depth_limit_m;
  const double multipoint_limit =
      stability::stability_boundary(multipoint, speeds, options)[0].depth_limit_m;
  std::printf(
      "[validation] 000 case at 11500 rpm: tip model %.3f mm, multipoint (Table 2 shapes) "
      "%.3f mm\n",
      tip_limit * 1e3, multipoint_limit * 1e3);
  EXPECT_GT(multipoint_limit, tip_limit);
}

TEST(Multipoint, LaterEntryShortensTheContactAndRaisesTheLimit) {
  // 000 Eq 20: a deformation-corrected entry angle later than the nominal
  // one removes part of the arc; with the nominal angle returned the model is
  // unchanged.
  const Case000 c;
  const double nominal = kPi - std::acos(1.0 - 4.0 / 6.0);
  stability::MultipointStructure same, later;
  same.entry_angle_rad = [nominal](double, double) { return nominal; };
  later.entry_angle_rad = [nominal](double, double) { return nominal + 2.0 * kPi / 180; };
  const stability::RegenerativeModel plain(c.tool, c.law, c.process, c.modes);
  const stability::RegenerativeModel unchanged(c.tool, c.law, c.process, c.modes, same);
  const stability::RegenerativeModel deformed(c.tool, c.law, c.process, c.modes, later);
  const stability::LobeOptions options = lobe_options(10e-3);
  const std::vector<double> speeds = {8200 * 2 * kPi / 60};
  const double a = stability::stability_boundary(plain, speeds, options)[0].depth_limit_m;
  const double b = stability::stability_boundary(unchanged, speeds, options)[0].depth_limit_m;
  const double d = stability::stability_boundary(deformed, speeds, options)[0].depth_limit_m;
  EXPECT_NEAR(a, b, 1e-12);
  EXPECT_GT(d, a * (1.0 + 1e-3));
  // Up milling has no deformation-corrected engagement in 000.
  cutting::MillingProcess up = c.process;
  up.direction = cutting::MillingDirection::up;
  EXPECT_THROW(stability::RegenerativeModel(c.tool, c.law, up, c.modes, later),
               std::invalid_argument);
  stability::MultipointStructure wrong;
  wrong.mode_shapes = {c.shape_x};
  EXPECT_THROW(stability::RegenerativeModel(c.tool, c.law, c.process, c.modes, wrong),
               std::invalid_argument);
}

}  // namespace

}  // namespace test_multipoint_cpp
