#include "robomill/cutting/milling_forces.hpp"

#include <algorithm>
#include <array>
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

namespace {

// The slice of a general engagement holding height z (the last one above it).
std::size_t slice_of(const GeneralEngagement& engagement, double height_m) {
  const auto& tops = engagement.slice_top_m;
  const auto it = std::lower_bound(tops.begin(), tops.end(), height_m);
  return it == tops.end() ? tops.size() - 1 : static_cast<std::size_t>(it - tops.begin());
}

// The widest slice's arcs stand for the engagement in summaries and in the
// size-dependent law's mean chip thickness (004 Eq A3 over several arcs:
// fz Σ (cos φst − cos φex) / Σ (φex − φst)).
struct WidestSlice {
  Engagement span;
  double mean_chip_m = 0.0;
};

WidestSlice widest_slice(const GeneralEngagement& engagement) {
  WidestSlice widest;
  double widest_rad = 0.0;
  for (const std::vector<Engagement>& arcs : engagement.arcs) {
    double engaged_rad = 0.0, projected = 0.0;
    for (const Engagement& arc : arcs) {
      engaged_rad += arc.exit_rad - arc.entry_rad;
      projected += std::cos(arc.entry_rad) - std::cos(arc.exit_rad);
    }
    if (engaged_rad > widest_rad && !arcs.empty()) {
      widest_rad = engaged_rad;
      widest.span = {arcs.front().entry_rad, arcs.back().exit_rad};
      widest.mean_chip_m = engagement.feed_per_tooth_m * std::abs(projected) / engaged_rad;
    }
  }
  // A plunge has no lateral chip: the edge's chip is the axial feed's share
  // |fz,axial| cos κ, whose mean over a quarter-circle edge (κ from 0 to π/2)
  // is 2/π |fz,axial|. (A flat end mill's side edges, κ = π/2, cut nothing
  // then: the law's coefficients only have to exist.)
  if (!(widest.mean_chip_m > 0.0) && widest_rad > 0.0)
    widest.mean_chip_m = 2.0 / std::numbers::pi * std::abs(engagement.axial_feed_per_tooth_m);
  return widest;
}

MillingProcess general_process(const tool::Tool& tool, const GeneralEngagement& engagement) {
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(engagement.spindle_rad_s))
    throw std::invalid_argument("spindle speed must be positive");
  if (!(std::isfinite(engagement.feed_per_tooth_m) && engagement.feed_per_tooth_m >= 0.0) ||
      !std::isfinite(engagement.axial_feed_per_tooth_m))
    throw std::invalid_argument("feed per tooth must be finite, its lateral part non-negative");
  if (!positive(engagement.axial_depth_m))
    throw std::invalid_argument("axial depth must be positive");
  if (engagement.slice_top_m.empty() || engagement.arcs.size() != engagement.slice_top_m.size())
    throw std::invalid_argument("a general engagement needs one list of arcs per slice");
  MillingProcess process;
  process.spindle_rad_s = engagement.spindle_rad_s;
  process.feed_per_tooth_m = engagement.feed_per_tooth_m;
  process.axial_depth_m = engagement.axial_depth_m;
  const Engagement span = widest_slice(engagement).span;
  process.radial_depth_m =
      std::min(tool.diameter_m(),
               tool.radius_m() * std::abs(std::cos(span.entry_rad) - std::cos(span.exit_rad)));
  return process;
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
  // A straight band: one arc per element (cutting/engagement.hpp).
  build([&](const tool::EdgeElement& element) {
    return std::array<Engagement, 1>{radial_engagement(tool.radius_m(), element.radius_m,
                                                       process.radial_depth_m, process.direction)};
  });
}

MillingForceModel::MillingForceModel(const tool::Tool& tool, const CuttingLaw& law,
                                     const GeneralEngagement& engagement, int axial_elements)
    : tool_(tool),
      process_(general_process(tool, engagement)),
      law_(law, widest_slice(engagement).mean_chip_m),
      nominal_engagement_(widest_slice(engagement).span),
      mean_chip_m_(widest_slice(engagement).mean_chip_m),
      elements_(tool::discretize_edge(
          tool, std::clamp(engagement.edge_from_m, 0.0, 0.999 * engagement.axial_depth_m),
          engagement.axial_depth_m, axial_elements)) {
  build([&](const tool::EdgeElement& element) -> const std::vector<Engagement>& {
    return engagement.arcs[slice_of(engagement, element.height_m)];
  });
  // The axial feed's share of the chip, divided by sin κ (see at()).
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    const double sin_kappa = element_sin_kappa_[e];
    element_axial_chip_m_[e] =
        sin_kappa > 0.0 ? -engagement.axial_feed_per_tooth_m * element_cos_kappa_[e] / sin_kappa
                        : 0.0;
  }
}

template <class ArcsOfElement>
void MillingForceModel::build(ArcsOfElement&& element_arcs) {
  const int teeth = tool_.teeth();
  pairs_.reserve(elements_.size() * static_cast<std::size_t>(teeth));
  radius_steps_m_.reserve(pairs_.capacity() * static_cast<std::size_t>(teeth));
  element_axial_chip_m_.assign(elements_.size(), 0.0);
  element_arc_begin_.reserve(elements_.size() + 1);
  for (const tool::EdgeElement& element : elements_) {
    // Cylindrical edges get exact sin κ = 1, cos κ = 0 (cos(π/2) in floating
    // point is 6e-17 and would leak a spurious axial force).
    const bool cylindrical = element.kappa_rad == 0.5 * std::numbers::pi;
    element_sin_kappa_.push_back(cylindrical ? 1.0 : std::sin(element.kappa_rad));
    element_cos_kappa_.push_back(cylindrical ? 0.0 : std::cos(element.kappa_rad));
    element_arc_begin_.push_back(static_cast<int>(arcs_.size()));
    for (const Engagement& arc : element_arcs(element)) {
      if (!arc.empty())
        arcs_.push_back(arc);
    }
    for (int j = 0; j < teeth; ++j) {
      ElementTooth pair{};
      pair.angle_offset_rad = tool_.pitch_angle_rad(j) - element.lag_rad;
      const double radius_j = tool_.edge_radius_with_runout_m(j, element.height_m);
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
                                  tool_.edge_radius_with_runout_m(earlier, element.height_m));
      }
      pairs_.push_back(pair);
    }
  }
  element_arc_begin_.push_back(static_cast<int>(arcs_.size()));
}

double MillingForceModel::tooth_period_s() const noexcept {
  return 2.0 * std::numbers::pi / (process_.spindle_rad_s * tool_.teeth());
}

ToolLoad MillingForceModel::at(double rotation_rad) const noexcept {
  const int teeth = tool_.teeth();
  const double feed = process_.feed_per_tooth_m;
  double fx = 0.0, fy = 0.0, fz = 0.0, torque = 0.0;
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    const Engagement* arcs_begin = arcs_.data() + element_arc_begin_[e];
    const Engagement* arcs_end = arcs_.data() + element_arc_begin_[e + 1];
    if (arcs_begin == arcs_end)
      continue;  // this slice of the edge is in air
    const double sin_kappa = element_sin_kappa_[e];
    const double cos_kappa = element_cos_kappa_[e];
    const double axial_chip = element_axial_chip_m_[e];
    const double width = elements_[e].chip_width_m;
    for (int j = 0; j < teeth; ++j) {
      const ElementTooth& pair = pairs_[e * static_cast<std::size_t>(teeth) + j];
      const double phi = wrap_angle_rad(rotation_rad + pair.angle_offset_rad);
      bool engaged = false;  // g of 000 Eq 12, over every arc of the element
      for (const Engagement* arc = arcs_begin; arc != arcs_end && !engaged; ++arc)
        engaged = phi >= arc->entry_rad && phi <= arc->exit_rad;
      if (!engaged)
        continue;
      const double sin_phi = std::sin(phi);
      const double cos_phi = std::cos(phi);
      double chip = std::numeric_limits<double>::infinity();
      const double* steps = &radius_steps_m_[static_cast<std::size_t>(pair.min_offset_index)];
      for (int i = 1; i <= teeth; ++i) {
        chip = std::min(chip, i * (feed * sin_phi + axial_chip) + steps[i - 1]);
      }
      chip *= sin_kappa;  // 001 Eq 14: h = fz sin φ sin κ (axial_chip: see the constructor)
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
  // Resolve the helix lag to 0.5° per element and a rounded end (ball or torus
  // corner) to ≥ 40 slices;
  // without helix a flat edge is exact with one element.
  constexpr double lag_per_element_rad = 0.5 * std::numbers::pi / 180.0;
  const double lag_rad = tool.lag_angle_rad(axial_depth_m);
  int count = static_cast<int>(std::ceil(lag_rad / lag_per_element_rad));
  if (tool.corner_radius_m() > 0.0)  // a ball nose or a bull nose's corner
    count = std::max(count, 40);
  return std::clamp(count, 1, 2000);
}

}  // namespace robomill::cutting
