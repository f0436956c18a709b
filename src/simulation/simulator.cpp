// The time-domain milling simulation of simulator.hpp: swept-surface chip
// thickness (H), the cutting law per edge element, exact discretization of
// the structure with a first-order hold of the force.

#include "robomill/simulation/simulator.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "robomill/core/constants.hpp"
#include "robomill/cutting/engagement.hpp"

namespace robomill::simulation {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// Everything the force evaluation needs, precomputed; the surface memory is
/// the only part that changes (on committed evaluations).
class CuttingGeometry {
 public:
  CuttingGeometry(const tool::Tool& tool, const cutting::CuttingLaw& law,
                  const cutting::MillingProcess& process, const Workpiece& workpiece,
                  const SimulationOptions& options, double step_s)
      : law_(law, cutting::mean_chip_thickness_m(
                      process.feed_per_tooth_m,
                      cutting::radial_engagement(tool.radius_m(), tool.radius_m(),
                                                 process.radial_depth_m, process.direction))),
        teeth_(tool.teeth()),
        steps_per_tooth_(options.steps_per_tooth),
        cells_(tool.teeth() * options.steps_per_tooth),
        feed_speed_m_s_(process.feed_per_tooth_m * tool.teeth() * process.spindle_rad_s / kTwoPi),
        step_s_(step_s),
        border_x_m_(workpiece.border_x_m) {
    const auto elements =
        tool::discretize_edge(tool, process.axial_depth_m, options.axial_elements);
    elements_ = static_cast<int>(elements.size());
    // The radial band of the part (cutting/engagement.hpp's convention),
    // measured from the tool's radius, or from each element's own radius in
    // a raster's groove (Workpiece::raster_groove).
    band_min_y_m_.assign(elements.size(), -kInfinity);
    band_max_y_m_.assign(elements.size(), kInfinity);
    for (std::size_t k = 0; k < elements.size(); ++k) {
      const double radius = workpiece.raster_groove ? elements[k].radius_m : tool.radius_m();
      if (process.radial_depth_m < 2.0 * radius) {
        if (process.direction == cutting::MillingDirection::down)
          band_max_y_m_[k] = process.radial_depth_m - radius;
        else
          band_min_y_m_[k] = radius - process.radial_depth_m;
      }
    }
    const std::size_t grid = static_cast<std::size_t>(elements_) * cells_;
    sin_.resize(grid);
    cos_.resize(grid);
    surface_.resize(grid);
    width_.resize(elements.size());
    sin_kappa_.resize(elements.size());
    cos_kappa_.resize(elements.size());
    damping_.assign(elements.size(), 0.0);
    projection_.resize(elements.size() * teeth_);
    edge_radius_.resize(elements.size() * teeth_);
    for (int k = 0; k < elements_; ++k) {
      const tool::EdgeElement& e = elements[std::size_t(k)];
      const bool cylindrical = e.kappa_rad == 0.5 * std::numbers::pi;
      sin_kappa_[k] = cylindrical ? 1.0 : std::sin(e.kappa_rad);
      cos_kappa_[k] = cylindrical ? 0.0 : std::cos(e.kappa_rad);
      width_[k] = e.chip_width_m;
      for (int j = 0; j < teeth_; ++j) {
        const double r = tool.edge_radius_with_runout_m(j, e.height_m);
        edge_radius_[std::size_t(k) * teeth_ + j] = r;
        // (edge point − tool tip) · n: the edge's own projection ρ.
        projection_[std::size_t(k) * teeth_ + j] = r * sin_kappa_[k] - e.height_m * cos_kappa_[k];
      }
      for (int b = 0; b < cells_; ++b) {
        const double angle = options.start_angle_rad - e.lag_rad + kTwoPi * b / cells_;
        sin_[std::size_t(k) * cells_ + b] = std::sin(angle);
        cos_[std::size_t(k) * cells_ + b] = std::cos(angle);
      }
      if (options.process_damping) {
        // 000 Eq 19 per element: C = K_sp w² db / (4 V), V = r Ω.
        const auto& pd = *options.process_damping;
        damping_[k] = pd.indentation_n_per_m3 * pd.wear_land_m * pd.wear_land_m * width_[k] /
                      (4.0 * e.radius_m * process.spindle_rad_s);
        friction_ = pd.friction;
      }
    }
    // The nominal path before t = 0: cell b was last passed at step
    // (b mod spt) − spt by tooth ((b − step) / spt) mod N, rigidly.
    for (int k = 0; k < elements_; ++k) {
      for (int b = 0; b < cells_; ++b) {
        const int step = b % steps_per_tooth_ - steps_per_tooth_;
        const int tooth = ((b - step) / steps_per_tooth_) % teeth_;
        const std::size_t cell = std::size_t(k) * cells_ + b;
        const double centre_x = feed_speed_m_s_ * step * step_s_;
        surface_[cell] =
            centre_x * sin_kappa_[k] * sin_[cell] + projection_[std::size_t(k) * teeth_ + tooth];
      }
    }
  }

  int elements() const noexcept { return elements_; }
  int teeth() const noexcept { return teeth_; }
  double feed_speed_m_s() const noexcept { return feed_speed_m_s_; }

  /// Force on the cutter at step `step` with vibration u and velocity u̇;
  /// `commit` updates the surface memory (H). `cutting_teeth` gets the number
  /// of teeth with a positive chip.
  Eigen::Vector3d force(long long step, const Eigen::Vector3d& u, const Eigen::Vector3d& velocity,
                        bool commit, int& cutting_teeth) {
    const double centre_x = feed_speed_m_s_ * static_cast<double>(step) * step_s_ + u.x();
    const double centre_y = u.y();
    const double centre_z = u.z();
    const int phase = static_cast<int>(step % cells_);
    Eigen::Vector3d total = Eigen::Vector3d::Zero();
    unsigned cutting_mask = 0;
    for (int k = 0; k < elements_; ++k) {
      const double sk = sin_kappa_[k], ck = cos_kappa_[k];
      const std::size_t row = std::size_t(k) * cells_;
      for (int j = 0; j < teeth_; ++j) {
        int b = phase + j * steps_per_tooth_;
        if (b >= cells_)
          b -= cells_;
        const std::size_t cell = row + b;
        const double sin_phi = sin_[cell], cos_phi = cos_[cell];
        const double nx = sk * sin_phi, ny = sk * cos_phi, nz = -ck;
        const double reach = centre_x * nx + centre_y * ny + centre_z * nz +
                             projection_[std::size_t(k) * teeth_ + j];
        double chip = reach - surface_[cell];
        if (commit && chip > 0.0)
          surface_[cell] = reach;
        if (!(chip > 0.0))
          continue;
        // Raw material behind the edge along −n (zero outside the part).
        const double r = edge_radius_[std::size_t(k) * teeth_ + j];
        const double px = centre_x + r * sin_phi, py = centre_y + r * cos_phi;
        const double band_min = band_min_y_m_[std::size_t(k)],
                     band_max = band_max_y_m_[std::size_t(k)];
        if (px < border_x_m_ || py > band_max || py < band_min)
          continue;
        if (nx > 0.0)
          chip = std::min(chip, (px - border_x_m_) / nx);
        if (ny > 0.0)
          chip = std::min(chip, (py - band_min) / ny);
        else if (ny < 0.0)
          chip = std::min(chip, (band_max - py) / -ny);
        if (!(chip > 0.0))
          continue;
        const cutting::EdgeForce f = law_(chip, width_[k]);
        // 001 Eq 11 (002 Eq 29 for κ = 90°).
        Eigen::Vector3d element(
            -cos_phi * f.tangential_n - nx * f.radial_n - ck * sin_phi * f.axial_n,
            sin_phi * f.tangential_n - ny * f.radial_n - ck * cos_phi * f.axial_n,
            ck * f.radial_n - sk * f.axial_n);
        if (damping_[k] > 0.0) {
          // 000 Eq 18: F = −c (n − μ t)(n · u̇), t the tangential-force direction.
          const double normal_speed = nx * velocity.x() + ny * velocity.y() + nz * velocity.z();
          const double c = damping_[k] * normal_speed;
          element -= c * Eigen::Vector3d(nx + friction_ * cos_phi, ny - friction_ * sin_phi, nz);
        }
        total += element;
        cutting_mask |= 1u << (j & 31);
      }
    }
    evaluations_ += static_cast<long long>(elements_) * teeth_;
    cutting_teeth = __builtin_popcount(cutting_mask);
    return total;
  }

  long long evaluations() const noexcept { return evaluations_; }

 private:
  cutting::ResolvedLaw law_;
  int teeth_, steps_per_tooth_, cells_, elements_ = 0;
  double feed_speed_m_s_, step_s_, border_x_m_;
  std::vector<double> band_min_y_m_, band_max_y_m_;  // per element
  double friction_ = 0.0;
  std::vector<double> sin_, cos_, surface_;  // element-major grids of cells
  std::vector<double> width_, sin_kappa_, cos_kappa_, damping_;
  std::vector<double> projection_, edge_radius_;  // element-major, per tooth
  long long evaluations_ = 0;
};

}  // namespace

ArcResolution engaged_arc_resolution(const tool::Tool& tool, const cutting::MillingProcess& process,
                                     const Workpiece& workpiece, int steps_across) {
  // In a groove every disk cuts a band ae wide measured from its own
  // radius, so the widest disk in the cut has the narrowest arc.
  const double radius =
      workpiece.raster_groove ? tool.edge_radius_m(process.axial_depth_m) : tool.radius_m();
  const cutting::Engagement arc =
      cutting::radial_engagement(radius, radius, process.radial_depth_m, process.direction);
  ArcResolution out;
  out.arc_rad = std::max(arc.exit_rad - arc.entry_rad, 1e-9);
  out.steps_per_tooth = static_cast<int>(
      std::ceil(steps_across * (kTwoPi / tool.teeth()) / out.arc_rad * (1.0 - 1e-12)));
  return out;
}

double process_damping_step_limit_s(const tool::Tool& tool, const cutting::MillingProcess& process,
                                    const LinearStructure& structure,
                                    const stability::LinearProcessDamping& damping) {
  if (structure.rigid())
    return std::numeric_limits<double>::infinity();
  // Teeth that can touch the part at once: those within the engaged arc
  // widened by the helix lag over the depth.
  const cutting::Engagement arc = cutting::radial_engagement(
      tool.radius_m(), tool.radius_m(), process.radial_depth_m, process.direction);
  const double pitch_rad = 2.0 * std::numbers::pi / tool.teeth();
  const double span_rad =
      arc.exit_rad - arc.entry_rad + std::abs(tool.lag_angle_rad(process.axial_depth_m));
  const int contacts =
      std::min(tool.teeth(), static_cast<int>(std::floor(span_rad / pitch_rad)) + 1);
  const double damping_n_s_per_m = contacts * damping.indentation_n_per_m3 * damping.wear_land_m *
                                   damping.wear_land_m * process.axial_depth_m /
                                   (4.0 * tool.radius_m() * process.spindle_rad_s);
  // Lᵀ M⁻¹ L: the tool-tip mobility at high frequency (the inverse "mass").
  const Eigen::Matrix3d inverse_mass =
      structure.force_input.transpose() * structure.mass.llt().solve(structure.force_input);
  const double rate = damping_n_s_per_m * Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(
                                              inverse_mass, Eigen::EigenvaluesOnly)
                                              .eigenvalues()
                                              .maxCoeff();
  return rate > 0.0 ? 1.0 / rate : std::numeric_limits<double>::infinity();
}

SimulationResult simulate(const tool::Tool& tool, const cutting::CuttingLaw& law,
                          const cutting::MillingProcess& process, const LinearStructure& structure,
                          const Workpiece& workpiece, const SimulationOptions& options) {
  if (!(process.spindle_rad_s > 0.0) || !(process.feed_per_tooth_m > 0.0) ||
      !(process.axial_depth_m > 0.0) || !(process.radial_depth_m > 0.0))
    throw std::invalid_argument("simulate: spindle speed, feed, ap and ae must be positive");
  if (!(options.duration_s > 0.0) || !std::isfinite(options.duration_s))
    throw std::invalid_argument("simulate: the duration must be positive");
  if (options.steps_per_tooth < 1 || options.axial_elements < 1 || options.record_every < 1)
    throw std::invalid_argument("simulate: steps_per_tooth, axial_elements, record_every ≥ 1");
  if (tool.teeth() > 32)
    throw std::invalid_argument("simulate: at most 32 teeth");

  const double tooth_period_s = kTwoPi / (process.spindle_rad_s * tool.teeth());
  const double step_s = tooth_period_s / options.steps_per_tooth;
  const long long steps = static_cast<long long>(std::ceil(options.duration_s / step_s - 1e-6));
  if (steps > 200'000'000)
    throw std::invalid_argument("simulate: more than 2e8 steps");

  if (options.process_damping &&
      step_s > process_damping_step_limit_s(tool, process, structure, *options.process_damping))
    throw std::invalid_argument("simulate: the step is too coarse for the process damping");

  CuttingGeometry geometry(tool, law, process, workpiece, options, step_s);
  const DiscreteStructure d = discretize(structure, step_s);
  const int m = d.state_size();

  SimulationResult result;
  result.step_s = step_s;
  result.record_interval_s = step_s * options.record_every;
  const std::size_t records = static_cast<std::size_t>(steps / options.record_every) + 1;
  result.time_s.reserve(records);
  result.force_n.reserve(records);
  result.displacement_m.reserve(records);
  result.teeth_cutting.reserve(records);
  if (workpiece.has_border())
    result.full_engagement_s = std::max(0.0, workpiece.border_x_m / geometry.feed_speed_m_s());

  // State z = (q, q̇) and workspaces: nothing below allocates.
  Eigen::VectorXd state = Eigen::VectorXd::Zero(m), predicted(m), next(m);
  Eigen::Vector3d u = Eigen::Vector3d::Zero(), velocity = Eigen::Vector3d::Zero();
  int cutting = 0, trial_cutting = 0;
  Eigen::Vector3d force = geometry.force(0, u, velocity, true, cutting);
  for (long long step = 0;; ++step) {
    if (cutting > 0 && result.first_contact_s < 0.0)
      result.first_contact_s = static_cast<double>(step) * step_s;
    if (step % options.record_every == 0) {
      result.time_s.push_back(static_cast<double>(step) * step_s);
      result.force_n.push_back(force);
      result.displacement_m.push_back(u);
      result.teeth_cutting.push_back(cutting);
    }
    if (step == steps)
      break;
    if (m == 0) {
      force = geometry.force(step + 1, u, velocity, true, cutting);
      continue;
    }
    // Predictor: force held over the step.
    predicted.noalias() = d.transition * state;
    predicted.noalias() += d.hold * force;
    const Eigen::Vector3d predicted_force = geometry.force(
        step + 1, d.displacement * predicted, d.velocity * predicted, false, trial_cutting);
    // Corrector: first-order hold between F_n and the predicted F_{n+1}.
    next = predicted;
    next.noalias() += d.ramp * (predicted_force - force);
    state.swap(next);
    u.noalias() = d.displacement * state;
    velocity.noalias() = d.velocity * state;
    force = geometry.force(step + 1, u, velocity, true, cutting);
  }
  result.element_evaluations = geometry.evaluations();
  return result;
}

}  // namespace robomill::simulation
