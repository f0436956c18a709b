#include "robomill/stability/regenerative_model.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <stdexcept>
#include <string>

#include "robomill/cutting/engagement.hpp"
#include "robomill/cutting/milling_forces.hpp"

namespace robomill::stability {
namespace {

cutting::LinearLaw linearize(const cutting::CuttingLaw& law, const tool::Tool& tool,
                             const cutting::MillingProcess& process) {
  const cutting::Engagement engagement = cutting::radial_engagement(
      tool.radius_m(), tool.radius_m(), process.radial_depth_m, process.direction);
  const cutting::ResolvedLaw resolved(
      law, cutting::mean_chip_thickness_m(process.feed_per_tooth_m, engagement));
  if (!resolved.is_linear()) {
    throw std::invalid_argument(
        "stability analysis needs a linear cutting law (linear or size_dependent), got " +
        std::string(cutting::law_name(law)));
  }
  return resolved.linear();
}

}  // namespace

RegenerativeModel::RegenerativeModel(const tool::Tool& tool, const cutting::CuttingLaw& law,
                                     const cutting::MillingProcess& process,
                                     const dynamics::ModalModel& modes,
                                     MultipointStructure multipoint)
    : tool_(tool),
      process_(process),
      law_(linearize(law, tool, process)),
      modes_(modes),
      shapes_(modes.shape_matrix()),
      multipoint_(std::move(multipoint)) {
  if (!(process.radial_depth_m > 0.0) || process.radial_depth_m > tool.diameter_m() * (1 + 1e-12)) {
    throw std::invalid_argument("radial depth must lie in (0, tool diameter]");
  }
  if (!multipoint_.mode_shapes.empty() &&
      static_cast<int>(multipoint_.mode_shapes.size()) != modes.size()) {
    throw std::invalid_argument(
        "multipoint model: " + std::to_string(multipoint_.mode_shapes.size()) +
        " mode shapes along the tool for " + std::to_string(modes.size()) + " modes");
  }
  for (std::size_t i = 0; i < multipoint_.mode_shapes.size(); ++i) {
    const dynamics::AxialShape& shape = multipoint_.mode_shapes[i];
    if (shape.empty())
      continue;
    if (!(std::abs(shape.at(0.0)) > 0.0)) {
      throw std::invalid_argument("multipoint model: mode " + std::to_string(i + 1) +
                                  "'s shape along the tool is zero at the tip");
    }
    shapes_along_tool_ = true;
  }
  if (multipoint_.entry_angle_rad && process.direction != cutting::MillingDirection::down) {
    throw std::invalid_argument(
        "the deformation-corrected engagement (000 §4) is defined for down milling");
  }
  // W scales with the depth only for straight cylindrical flutes whose
  // engagement and shapes do not change along the tool.
  proportional_ =
      tool.type() == tool::ToolType::flat && tool.helix_rad() == 0.0 && multipoint_.empty();
}

std::vector<tool::EdgeElement> RegenerativeModel::edge(double axial_depth_m) const {
  if (proportional_) {
    // Straight cylindrical flutes: one element of the whole depth is exact,
    // and any depth (also the unit depth used for scaling) is allowed.
    tool::EdgeElement element;
    element.height_m = 0.5 * axial_depth_m;
    element.axial_length_m = axial_depth_m;
    element.chip_width_m = axial_depth_m;
    element.radius_m = tool_.radius_m();
    element.kappa_rad = 0.5 * std::numbers::pi;
    return {element};
  }
  return tool::discretize_edge(tool_, axial_depth_m,
                               cutting::default_axial_elements(tool_, axial_depth_m));
}

namespace {

// An edge element with what its engagement needs that does not change with
// the spindle angle.
struct EngagedElement {
  const tool::EdgeElement* element;
  double sin_kappa, cos_kappa;
  cutting::Engagement engagement;
};

// `entry` (optional) replaces the entry angle by the element's height (000
// Eq 20, the deformation-corrected engagement).
std::vector<EngagedElement> engaged_elements(const tool::Tool& tool,
                                             const cutting::MillingProcess& process,
                                             const std::vector<tool::EdgeElement>& edge,
                                             const std::function<double(double)>& entry) {
  std::vector<EngagedElement> elements;
  elements.reserve(edge.size());
  for (const tool::EdgeElement& element : edge) {
    const bool cylindrical = element.kappa_rad == 0.5 * std::numbers::pi;
    EngagedElement e{&element, cylindrical ? 1.0 : std::sin(element.kappa_rad),
                     cylindrical ? 0.0 : std::cos(element.kappa_rad),
                     cutting::radial_engagement(tool.radius_m(), element.radius_m,
                                                process.radial_depth_m, process.direction)};
    if (entry)
      e.engagement.entry_rad = std::max(e.engagement.entry_rad, entry(element.height_m));
    elements.push_back(e);
  }
  return elements;
}

// Calls visit(element, db, T, n) for every engaged (element, tooth) at
// spindle angle ϕ: T the projection of 001 Eq 11 (columns Ft, Fr, Fa), n the
// edge normal.
template <class Visit>
void for_each_engaged(const tool::Tool& tool, const std::vector<EngagedElement>& elements,
                      double rotation_rad, Visit&& visit) {
  for (const EngagedElement& e : elements) {
    const tool::EdgeElement& element = *e.element;
    const double sin_kappa = e.sin_kappa, cos_kappa = e.cos_kappa;
    for (int j = 0; j < tool.teeth(); ++j) {
      const double phi =
          cutting::wrap_angle_rad(rotation_rad + tool.pitch_angle_rad(j) - element.lag_rad);
      if (phi < e.engagement.entry_rad || phi > e.engagement.exit_rad)
        continue;
      const double s = std::sin(phi), c = std::cos(phi);
      Eigen::Matrix3d projection;
      projection << -c, -sin_kappa * s, -cos_kappa * s,  //
          s, -sin_kappa * c, -cos_kappa * c,             //
          0.0, cos_kappa, -sin_kappa;
      const Eigen::Vector3d normal(sin_kappa * s, sin_kappa * c, -cos_kappa);
      visit(element, element.chip_width_m, projection, normal);
    }
  }
}

template <class Visit>
void for_each_engaged(const tool::Tool& tool, const cutting::MillingProcess& process,
                      const std::vector<tool::EdgeElement>& edge, double rotation_rad,
                      const std::function<double(double)>& entry, Visit&& visit) {
  for_each_engaged(tool, engaged_elements(tool, process, edge, entry), rotation_rad,
                   std::forward<Visit>(visit));
}

}  // namespace

Eigen::Matrix3d RegenerativeModel::cutting_stiffness(double rotation_rad,
                                                     double axial_depth_m) const {
  // Same geometry as the force model (MillingForceModel::at); only the
  // chip-thickness (shear) coefficients respond to vibration.
  const Eigen::Vector3d shear(law_.Ktc_pa, law_.Krc_pa, law_.Kac_pa);
  Eigen::Matrix3d stiffness = Eigen::Matrix3d::Zero();
  for_each_engaged(tool_, process_, edge(axial_depth_m), rotation_rad, entry_at(axial_depth_m),
                   [&](const tool::EdgeElement&, double width, const Eigen::Matrix3d& projection,
                       const Eigen::Vector3d& normal) {
                     stiffness += width * (projection * shear) * normal.transpose();
                   });
  return stiffness;
}

Eigen::Matrix3d RegenerativeModel::cutting_stiffness_sum(double period_rad, int samples,
                                                         double axial_depth_m) const {
  const Eigen::Vector3d shear(law_.Ktc_pa, law_.Krc_pa, law_.Kac_pa);
  const std::vector<tool::EdgeElement> edge_elements = edge(axial_depth_m);
  const std::vector<EngagedElement> elements =
      engaged_elements(tool_, process_, edge_elements, entry_at(axial_depth_m));
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (int s = 0; s < samples; ++s) {
    Eigen::Matrix3d stiffness = Eigen::Matrix3d::Zero();
    for_each_engaged(tool_, elements, (s + 0.5) * period_rad / samples,
                     [&](const tool::EdgeElement&, double width, const Eigen::Matrix3d& projection,
                         const Eigen::Vector3d& normal) {
                       stiffness += width * (projection * shear) * normal.transpose();
                     });
    sum += stiffness;
  }
  return sum;
}

std::array<Eigen::Matrix3d, 3> RegenerativeModel::cutting_stiffness_sum_per_coefficient(
    double period_rad, int samples, double axial_depth_m) const {
  const std::vector<tool::EdgeElement> edge_elements = edge(axial_depth_m);
  const std::vector<EngagedElement> elements =
      engaged_elements(tool_, process_, edge_elements, entry_at(axial_depth_m));
  std::array<Eigen::Matrix3d, 3> sums;
  for (Eigen::Matrix3d& m : sums)
    m.setZero();
  for (int s = 0; s < samples; ++s) {
    for_each_engaged(tool_, elements, (s + 0.5) * period_rad / samples,
                     [&](const tool::EdgeElement&, double width, const Eigen::Matrix3d& projection,
                         const Eigen::Vector3d& normal) {
                       for (int q = 0; q < 3; ++q)
                         sums[static_cast<std::size_t>(q)] +=
                             width * projection.col(q) * normal.transpose();
                     });
  }
  return sums;
}

Eigen::Matrix3d RegenerativeModel::damping_shape(double rotation_rad, double axial_depth_m,
                                                 double friction) const {
  const Eigen::Vector3d split(friction, 1.0, 0.0);  // 000 Eq 18: [Ft; Fr] = C_eq [μ; 1] v_n
  Eigen::Matrix3d shape = Eigen::Matrix3d::Zero();
  for_each_engaged(tool_, process_, edge(axial_depth_m), rotation_rad, entry_at(axial_depth_m),
                   [&](const tool::EdgeElement&, double width, const Eigen::Matrix3d& projection,
                       const Eigen::Vector3d& normal) {
                     // Like the chip force with h replaced by the normal
                     // velocity v_n = nᵀ q'; the radial column of T is −n, so
                     // the indentation force opposes the motion into the part.
                     shape += width * (projection * split) * normal.transpose();
                   });
  return shape;
}

std::function<double(double)> RegenerativeModel::entry_at(double axial_depth_m) const {
  if (!multipoint_.entry_angle_rad)
    return {};
  return [this, axial_depth_m](double height_m) {
    return multipoint_.entry_angle_rad(axial_depth_m, height_m);
  };
}

Eigen::MatrixXd RegenerativeModel::modal_sum(double rotation_rad, double axial_depth_m,
                                             const Eigen::Vector3d& coefficients) const {
  const int n = modes_.size();
  if (!shapes_along_tool_) {
    Eigen::Matrix3d w = Eigen::Matrix3d::Zero();
    for_each_engaged(tool_, process_, edge(axial_depth_m), rotation_rad, entry_at(axial_depth_m),
                     [&](const tool::EdgeElement&, double width, const Eigen::Matrix3d& projection,
                         const Eigen::Vector3d& normal) {
                       w += width * (projection * coefficients) * normal.transpose();
                     });
    return shapes_.transpose() * w * shapes_;
  }
  // 000 Eq 32, 37-38: each element with the modes' shapes at its height.
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(n, n);
  Eigen::Matrix<double, 3, Eigen::Dynamic> local(3, n);
  for_each_engaged(
      tool_, process_, edge(axial_depth_m), rotation_rad, entry_at(axial_depth_m),
      [&](const tool::EdgeElement& element, double width, const Eigen::Matrix3d& projection,
          const Eigen::Vector3d& normal) {
        for (int i = 0; i < n; ++i) {
          const dynamics::AxialShape& along = multipoint_.mode_shapes[static_cast<std::size_t>(i)];
          const double factor = along.empty() ? 1.0 : along.at(element.height_m) / along.at(0.0);
          local.col(i) = shapes_.col(i) * factor;
        }
        const Eigen::Vector3d force = width * (projection * coefficients);
        p.noalias() += (local.transpose() * force) * (normal.transpose() * local);
      });
  return p;
}

Eigen::MatrixXd RegenerativeModel::modal_coupling(double rotation_rad, double axial_depth_m) const {
  return modal_sum(rotation_rad, axial_depth_m,
                   Eigen::Vector3d(law_.Ktc_pa, law_.Krc_pa, law_.Kac_pa));
}

template <class ModalOf>
CouplingSamples RegenerativeModel::sample_modal(ModalOf&& modal, int steps, int substeps) const {
  if (steps < 1 || substeps < 1)
    throw std::invalid_argument("steps and substeps must be ≥ 1");
  const double period_rad = 2.0 * std::numbers::pi / tool_.teeth();
  const double step_rad = period_rad / steps;
  CouplingSamples samples;
  samples.nodes.reserve(static_cast<std::size_t>(steps) + 1);
  samples.means.reserve(static_cast<std::size_t>(steps));
  // Window means: `means[k]` over the step [t_k, t_k+1] (semi-discretization),
  // `nodes[k]` over [t_k − h/2, t_k + h/2] (the node values of the full
  // discretization). Point values at the nodes would sample the entry/exit
  // discontinuities at arbitrary phases, making the boundary jump with the
  // discretization at low immersion; window means converge smoothly.
  auto window_mean = [&](double start_step) {
    Eigen::MatrixXd mean = Eigen::MatrixXd::Zero(modes_.size(), modes_.size());
    for (int s = 0; s < substeps; ++s)
      mean += modal((start_step + (s + 0.5) / substeps) * step_rad);
    return Eigen::MatrixXd(mean / substeps);
  };
  samples.average = Eigen::MatrixXd::Zero(modes_.size(), modes_.size());
  for (int k = 0; k < steps; ++k) {
    samples.means.push_back(window_mean(k));
    samples.average += samples.means.back() / steps;
  }
  for (int k = 0; k <= steps; ++k)
    samples.nodes.push_back(window_mean(k - 0.5));
  return samples;
}

CouplingSamples RegenerativeModel::sample(double axial_depth_m, int steps, int substeps) const {
  return sample_modal([&](double angle) { return modal_coupling(angle, axial_depth_m); }, steps,
                      substeps);
}

CouplingSamples RegenerativeModel::sample_damping(double axial_depth_m, int steps, double friction,
                                                  int substeps) const {
  return sample_modal(
      [&](double angle) {
        return modal_sum(angle, axial_depth_m, Eigen::Vector3d(friction, 1.0, 0.0));
      },
      steps, substeps);
}

}  // namespace robomill::stability
