#include "robomill/deflection/contact_boundary.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"

namespace robomill::deflection {
namespace {

void check(const ContactProblem& p) {
  auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  if (!positive(p.tool_radius_m) || !positive(p.feed_per_tooth_m) || !positive(p.axial_depth_m) ||
      !positive(p.radial_depth_m)) {
    throw std::invalid_argument(
        "contact boundary: radius, feed per tooth, axial and radial depth must be positive");
  }
  if (p.radial_depth_m > 2.0 * p.tool_radius_m * (1.0 + 1e-12))
    throw std::invalid_argument("contact boundary: the radial depth exceeds the tool diameter");
  if (!(p.helix_rad >= 0.0 && p.helix_rad < 0.5 * kPi))
    throw std::invalid_argument("contact boundary: the helix angle must lie in [0, 90°)");
  if (p.elements < 1)
    throw std::invalid_argument("contact boundary: at least one axial element");
  const Eigen::Index size = 2 * (p.elements + 1);
  if (p.compliance.rows() != size || p.compliance.cols() != size || !p.compliance.allFinite()) {
    throw std::invalid_argument("contact boundary: the node compliance must be a finite " +
                                std::to_string(size) + " x " + std::to_string(size) + " matrix");
  }
}

/// Per-unit-length force of 000 Eq 9 and 13 at edge angle φ for chip h,
/// robomill's projection (x = −cos φ Ft − sin φ Fr, y = sin φ Ft − cos φ Fr).
Eigen::Vector2d force_per_length(const cutting::LinearLaw& law, double phi, double chip_m) {
  const double tangential = law.Ktc_pa * chip_m + law.Kte_n_per_m;
  const double radial = law.Krc_pa * chip_m + law.Kre_n_per_m;
  const double s = std::sin(phi), c = std::cos(phi);
  return {-c * tangential - s * radial, s * tangential - c * radial};
}

}  // namespace

double critical_depth_m(double tool_radius_m, double radial_depth_m, double helix_rad) {
  if (!(helix_rad > 0.0))
    return std::numeric_limits<double>::infinity();
  const double ratio = std::clamp(1.0 - radial_depth_m / tool_radius_m, -1.0, 1.0);
  return tool_radius_m * (0.5 * kPi - std::asin(ratio)) / std::tan(helix_rad);
}

double entry_angle_rad(double tool_radius_m, double radial_depth_m) {
  const double ratio = std::clamp(1.0 - radial_depth_m / tool_radius_m, -1.0, 1.0);
  return kPi - std::acos(ratio);
}

int contact_node_count(int elements, int position, double entry_rad, double exit_rad,
                       double lag_step_rad) {
  const int remaining = elements + 2 - position;  // Eq 24: nodes K … m + 1
  if (remaining <= 0 || exit_rad < entry_rad)
    return 0;
  if (!(lag_step_rad > 0.0))
    return remaining;
  // Eq 30-31: the nodes whose edge, trailing node K by (k − K) Δφ, is still
  // past the entry angle (a relative 1e-12 keeps a node exactly on it in).
  const double fit = (exit_rad - entry_rad) / lag_step_rad;
  const int in_arc = static_cast<int>(std::floor(fit * (1.0 + 1e-12) + 1e-12)) + 1;
  return std::min(remaining, in_arc);
}

ContactBoundary solve_contact_boundary(const ContactProblem& problem,
                                       const ContactOptions& options) {
  check(problem);
  const int m = problem.elements;
  const int nodes = m + 1;
  const double radius = problem.tool_radius_m;
  const double dz = problem.axial_depth_m / m;
  const double lag = dz * std::tan(problem.helix_rad) / radius;  // Eq 11
  const double exit = kPi;
  const double nominal_entry = entry_angle_rad(radius, problem.radial_depth_m);

  ContactBoundary result;
  result.critical_depth_m =
      critical_depth_m(radius, problem.radial_depth_m, problem.helix_rad);  // Eq 22
  result.contact_case = problem.axial_depth_m > result.critical_depth_m ? 2 : 1;
  result.lag_step_rad = lag;
  result.nominal_entry_rad = nominal_entry;

  Eigen::VectorXd deflection = Eigen::VectorXd::Zero(2 * nodes);  // carried between positions
  Eigen::VectorXd force(2 * nodes), updated(2 * nodes);
  std::vector<Eigen::Vector2d> per_length(static_cast<std::size_t>(nodes));
  std::vector<double> entry(static_cast<std::size_t>(nodes)),
      radial(static_cast<std::size_t>(nodes)), angle(static_cast<std::size_t>(nodes));
  std::vector<char> contact(static_cast<std::size_t>(nodes));

  // Engagement of every node for a deflection estimate (Eq 25-27).
  auto engage = [&](const Eigen::VectorXd& d, int generating) {
    for (int k = 0; k < nodes; ++k) {
      const auto i = static_cast<std::size_t>(k);
      radial[i] = std::clamp(problem.radial_depth_m - d[2 * k + 1], 0.0, 2.0 * radius);  // Eq 26
      entry[i] = entry_angle_rad(radius, radial[i]);                                     // Eq 27
      angle[i] = exit - (k - generating) * lag;                                          // Eq 25
      contact[i] = k >= generating && angle[i] >= entry[i] - 1e-12 && radial[i] > 0.0;
    }
  };
  // Node forces for the current engagement (Eq 9, 13, 28; elements split
  // equally between their nodes, 000 §4.2).
  auto assemble = [&](int generating) {
    force.setZero();
    for (int k = 0; k < nodes; ++k) {
      const auto i = static_cast<std::size_t>(k);
      double chip = problem.feed_per_tooth_m;
      if (options.chip_correction)  // Eq 21/28 in robomill's angles
        chip -= radius * (std::sin(nominal_entry) - std::sin(entry[i]));
      per_length[i] = force_per_length(problem.law, angle[i],
                                       std::max(0.0, chip) * std::max(0.0, std::sin(angle[i])));
    }
    for (int k = generating; k < m; ++k) {
      const auto lower = static_cast<std::size_t>(k), upper = lower + 1;
      if (!contact[lower])
        continue;
      // The edge leaves the cut inside an element whose upper node trails
      // past its entry angle: only that fraction of the element cuts.
      double fraction = 1.0;
      if (!contact[upper])
        fraction = lag > 0.0 ? std::clamp((angle[lower] - entry[lower]) / lag, 0.0, 1.0) : 1.0;
      if (fraction <= 0.0)
        continue;
      const Eigen::Vector2d element = 0.5 * (per_length[lower] + per_length[upper]) * dz * fraction;
      // Half to each node for a whole element; a partial one acts nearer its
      // lower node (at fraction / 2 of the element).
      const double to_upper = 0.5 * fraction;
      force.segment<2>(2 * k) += (1.0 - to_upper) * element;
      force.segment<2>(2 * k + 2) += to_upper * element;
    }
  };

  result.positions.reserve(static_cast<std::size_t>(nodes));
  for (int generating = 0; generating < nodes; ++generating) {
    const Eigen::VectorXd start = deflection;
    bool converged = false;
    ContactPosition position;
    position.generating_node = generating + 1;
    for (double relaxation = 1.0; relaxation >= 1.0 / 16.0 && !converged; relaxation *= 0.5) {
      deflection = start;
      position.relaxation = relaxation;
      for (int l = 1; l <= options.max_iterations; ++l) {
        engage(deflection, generating);
        assemble(generating);
        updated = problem.compliance * force;  // Eq 1-4
        updated = deflection + relaxation * (updated - deflection);
        // Eq 29: the change of every node's radial depth.
        double change = 0.0;
        for (int k = generating; k < nodes; ++k)
          change = std::max(change, std::abs(updated[2 * k + 1] - deflection[2 * k + 1]));
        deflection = updated;
        position.iterations = l;
        if (!deflection.allFinite())
          break;
        if (change <= options.tolerance_m) {
          converged = true;
          break;
        }
      }
    }
    if (!converged) {
      throw NumericalError(
          "the force-induced deformation did not converge at contact-line "
          "position " +
          std::to_string(generating + 1) + " of " + std::to_string(nodes) +
          " (000 Eq 29) even with relaxation 1/16: the system is too compliant "
          "for a static equilibrium at this depth");
    }
    engage(deflection, generating);
    assemble(generating);
    position.contact_nodes = static_cast<int>(std::count(contact.begin(), contact.end(), 1));
    position.nodes.resize(static_cast<std::size_t>(nodes));
    for (int k = 0; k < nodes; ++k) {
      const auto i = static_cast<std::size_t>(k);
      NodeState& s = position.nodes[i];
      s.height_m = k * dz;
      s.deflection_m = deflection.segment<2>(2 * k);
      s.force_n = force.segment<2>(2 * k);
      s.radial_depth_m = radial[i];
      s.entry_rad = entry[i];
      s.edge_angle_rad = angle[i];
      s.in_contact = contact[i] != 0;
    }
    result.positions.push_back(std::move(position));
  }
  return result;
}

}  // namespace robomill::deflection
