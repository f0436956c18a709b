#include "robomill/cutting/milling_forces.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "robomill/core/parallel.hpp"

namespace robomill::cutting {
namespace {

void check_process(const tool::Tool& tool, const MillingProcess& process) {
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(process.spindle_rad_s))
    throw std::invalid_argument("spindle speed must be positive");
  if (!positive(process.feed_per_tooth_m))
    throw std::invalid_argument("feed per tooth must be positive");
  if (!positive(process.axial_depth_m))
    throw std::invalid_argument("axial depth must be positive");
  if (!positive(process.radial_depth_m))
    throw std::invalid_argument("radial depth must be positive");
  if (process.radial_depth_m > tool.diameter_m() * (1.0 + 1e-12)) {
    throw std::invalid_argument("radial depth exceeds the tool diameter");
  }
}

}  // namespace

MillingForceModel::MillingForceModel(const tool::Tool& tool, const CuttingLaw& law,
                                     const MillingProcess& process, int axial_elements)
    : tool_(tool),
      process_((check_process(tool, process), process)),
      law_(law,
           mean_chip_thickness_m(process.feed_per_tooth_m,
                                 radial_engagement(tool.radius_m(), tool.radius_m(),
                                                   process.radial_depth_m, process.direction))),
      nominal_engagement_(radial_engagement(tool.radius_m(), tool.radius_m(),
                                            process.radial_depth_m, process.direction)),
      mean_chip_m_(mean_chip_thickness_m(process.feed_per_tooth_m, nominal_engagement_)),
      elements_(tool::discretize_edge(tool, process.axial_depth_m, axial_elements)) {
  const int teeth = tool.teeth();
  pairs_.reserve(elements_.size() * static_cast<std::size_t>(teeth));
  radius_steps_m_.reserve(pairs_.capacity() * static_cast<std::size_t>(teeth));
  for (const tool::EdgeElement& element : elements_) {
    // Cylindrical edges get exact sin κ = 1, cos κ = 0 (cos(π/2) in floating
    // point is 6e-17 and would leak a spurious axial force).
    const bool cylindrical = element.kappa_rad == 0.5 * std::numbers::pi;
    element_sin_kappa_.push_back(cylindrical ? 1.0 : std::sin(element.kappa_rad));
    element_cos_kappa_.push_back(cylindrical ? 0.0 : std::cos(element.kappa_rad));
    const Engagement engagement = radial_engagement(tool.radius_m(), element.radius_m,
                                                    process.radial_depth_m, process.direction);
    for (int j = 0; j < teeth; ++j) {
      ElementTooth pair{};
      pair.angle_offset_rad = tool.pitch_angle_rad(j) - element.lag_rad;
      pair.entry_rad = engagement.entry_rad;
      pair.exit_rad = engagement.exit_rad;
      const double radius_j = tool.edge_radius_with_runout_m(j, element.height_m);
      pair.lever_m = radius_j;
      pair.min_offset_index = static_cast<int>(radius_steps_m_.size());
      // r_j − r_{j+i}: how much further tooth j reaches than the tooth that cut
      // i tooth periods earlier (runout chip thickness, Kline & DeVor). Edge j
      // sits at θ + 2πj/N, so tooth j + 1 leads: it passes any workpiece angle
      // one tooth period before tooth j (the simulator's swept surface agrees,
      // tests/simulation).
      for (int i = 1; i <= teeth; ++i) {
        const int earlier = (j + i) % teeth;
        radius_steps_m_.push_back(radius_j -
                                  tool.edge_radius_with_runout_m(earlier, element.height_m));
      }
      pairs_.push_back(pair);
    }
  }
}

double MillingForceModel::tooth_period_s() const noexcept {
  return 2.0 * std::numbers::pi / (process_.spindle_rad_s * tool_.teeth());
}

ToolLoad MillingForceModel::at(double rotation_rad) const noexcept {
  const int teeth = tool_.teeth();
  const double feed = process_.feed_per_tooth_m;
  double fx = 0.0, fy = 0.0, fz = 0.0, torque = 0.0;
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    const double sin_kappa = element_sin_kappa_[e];
    const double cos_kappa = element_cos_kappa_[e];
    const double width = elements_[e].chip_width_m;
    for (int j = 0; j < teeth; ++j) {
      const ElementTooth& pair = pairs_[e * static_cast<std::size_t>(teeth) + j];
      const double phi = wrap_angle_rad(rotation_rad + pair.angle_offset_rad);
      if (phi < pair.entry_rad || phi > pair.exit_rad)
        continue;  // g = 0 (000 Eq 12)
      const double sin_phi = std::sin(phi);
      const double cos_phi = std::cos(phi);
      double chip = std::numeric_limits<double>::infinity();
      const double* steps = &radius_steps_m_[static_cast<std::size_t>(pair.min_offset_index)];
      for (int i = 1; i <= teeth; ++i) {
        chip = std::min(chip, i * feed * sin_phi + steps[i - 1]);
      }
      chip *= sin_kappa;  // 001 Eq 14: h = fz sin φ sin κ
      const EdgeForce f = law_(chip, width);
      // 001 Eq 11 (Altintas' ball-end projection; κ = π/2 gives 002 Eq 29).
      fx += -f.tangential_n * cos_phi - f.radial_n * sin_kappa * sin_phi -
            f.axial_n * cos_kappa * sin_phi;
      fy += f.tangential_n * sin_phi - f.radial_n * sin_kappa * cos_phi -
            f.axial_n * cos_kappa * cos_phi;
      fz += f.radial_n * cos_kappa - f.axial_n * sin_kappa;
      torque += f.tangential_n * pair.lever_m;
    }
  }
  return {Eigen::Vector3d(fx, fy, fz), torque};
}

ForceSeries sample_forces(const MillingForceModel& model, const ForceSampling& sampling,
                          int threads) {
  if (sampling.revolutions < 1 || sampling.steps_per_tooth < 1) {
    throw std::invalid_argument("sampling needs at least one revolution and one step per tooth");
  }
  const std::size_t count = static_cast<std::size_t>(sampling.revolutions) *
                            static_cast<std::size_t>(model.tool().teeth()) *
                            static_cast<std::size_t>(sampling.steps_per_tooth);
  ForceSeries series;
  series.rotation_rad.resize(count);
  series.time_s.resize(count);
  series.force_n.resize(count);
  series.torque_nm.resize(count);
  const double step_s = model.tooth_period_s() / sampling.steps_per_tooth;
  const double spindle = model.process().spindle_rad_s;
  core::parallel_for(count, threads, [&](std::size_t i) {
    const double time = static_cast<double>(i) * step_s;
    const ToolLoad load = model.at(spindle * time);
    series.rotation_rad[i] = spindle * time;
    series.time_s[i] = time;
    series.force_n[i] = load.force_n;
    series.torque_nm[i] = load.torque_nm;
  });
  return series;
}

ForceStatistics summarize(const ForceSeries& series, double spindle_rad_s) {
  ForceStatistics stats;
  stats.mean_n.setZero();
  stats.min_n.setConstant(std::numeric_limits<double>::infinity());
  stats.max_n.setConstant(-std::numeric_limits<double>::infinity());
  stats.peak_n.setZero();
  if (series.size() == 0) {
    stats.min_n.setZero();
    stats.max_n.setZero();
    stats.peak_to_peak_n.setZero();
    return stats;
  }
  for (std::size_t i = 0; i < series.size(); ++i) {
    const Eigen::Vector3d& f = series.force_n[i];
    stats.mean_n += f;
    stats.min_n = stats.min_n.cwiseMin(f);
    stats.max_n = stats.max_n.cwiseMax(f);
    for (int c = 0; c < 3; ++c) {
      if (std::abs(f[c]) > std::abs(stats.peak_n[c]))
        stats.peak_n[c] = f[c];
    }
    stats.mean_torque_nm += series.torque_nm[i];
    stats.peak_torque_nm = std::max(stats.peak_torque_nm, std::abs(series.torque_nm[i]));
  }
  const double n = static_cast<double>(series.size());
  stats.mean_n /= n;
  stats.mean_torque_nm /= n;
  stats.peak_to_peak_n = stats.max_n - stats.min_n;
  stats.mean_power_w = stats.mean_torque_nm * spindle_rad_s;
  return stats;
}

int default_axial_elements(const tool::Tool& tool, double axial_depth_m) {
  // Resolve the helix lag to 0.5° per element and a ball nose to ≥ 40 slices;
  // without helix a flat edge is exact with one element.
  constexpr double lag_per_element_rad = 0.5 * std::numbers::pi / 180.0;
  const double lag_rad = tool.lag_angle_rad(axial_depth_m);
  int count = static_cast<int>(std::ceil(lag_rad / lag_per_element_rad));
  if (tool.type() == tool::ToolType::ball)
    count = std::max(count, 40);
  return std::clamp(count, 1, 2000);
}

}  // namespace robomill::cutting
