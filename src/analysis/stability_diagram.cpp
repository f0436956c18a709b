#include "robomill/analysis/stability_diagram.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "robomill/analysis/deformation.hpp"
#include "robomill/analysis/process_damping.hpp"
#include "robomill/analysis/structure.hpp"
#include "robomill/core/error.hpp"
#include "robomill/deflection/deformed_engagement.hpp"
#include "robomill/dynamics/measured_receptance.hpp"
#include "robomill/stability/multipoint.hpp"
#include "robomill/stability/process_damping.hpp"
#include "robomill/stability/zero_order.hpp"

namespace robomill::analysis {
namespace {

using Settings = job::StabilitySettings;

Bifurcation bifurcation_from(const std::string& name) {
  if (name == "hopf")
    return Bifurcation::hopf;
  if (name == "flip")
    return Bifurcation::flip;
  if (name == "fold")
    return Bifurcation::fold;
  return Bifurcation::none;
}

std::vector<StabilityLimit> zero_order_diagram(
    const stability::RegenerativeModel& model, const Settings& settings,
    const std::vector<double>& speeds, bool envelope, int threads,
    const stability::MeanCuttingStiffnessBasis* cut_basis) {
  stability::ProcessDampedOptions options;
  options.zero_order.depth_max_m = settings.depth_max_m;
  if (cut_basis)
    options.mean_stiffness_per_depth = (*cut_basis)(model.law());
  options.method =
      envelope ? stability::MultiModeMethod::envelope : stability::MultiModeMethod::coupled;
  options.threads = threads;
  std::vector<StabilityLimit> limits;
  for (const auto& z :
       stability::process_damped_limits(model, process_damping(settings), speeds, options)) {
    limits.push_back({z.spindle_rad_s, z.depth_limit_m, z.limited, z.chatter_frequency_hz,
                      z.limited ? Bifurcation::hopf : Bifurcation::none, z.mode});
  }
  return limits;
}

std::vector<StabilityLimit> floquet_diagram(const stability::RegenerativeModel& model,
                                            const stability::LobeOptions& options,
                                            const std::vector<double>& speeds) {
  std::vector<StabilityLimit> limits;
  for (const auto& p : stability::stability_boundary(model, speeds, options)) {
    limits.push_back({p.spindle_rad_s, p.depth_limit_m, p.limited, p.chatter_frequency_hz,
                      bifurcation_from(p.bifurcation), -1});
  }
  return limits;
}

/// 003 §3.2: the lowest envelope of the diagrams of each mode alone.
std::vector<StabilityLimit> floquet_envelope(const job::Job& job, const dynamics::ModalModel& modes,
                                             const stability::LobeOptions& options,
                                             const std::vector<double>& speeds) {
  std::vector<StabilityLimit> envelope;
  for (int q = 0; q < modes.size(); ++q) {
    const stability::RegenerativeModel single(tool::Tool(*job.tool), *job.cutting, *job.process,
                                              modes.subset({q}));
    const std::vector<StabilityLimit> diagram = floquet_diagram(single, options, speeds);
    if (envelope.empty()) {
      envelope = diagram;
      for (StabilityLimit& l : envelope)
        l.mode = q;
      continue;
    }
    for (std::size_t i = 0; i < diagram.size(); ++i) {
      if (diagram[i].depth_limit_m < envelope[i].depth_limit_m) {
        envelope[i] = diagram[i];
        envelope[i].mode = q;
      }
    }
  }
  return envelope;
}

/// The zero-order diagram straight from the measured FRFs: the measured
/// frequencies are the chatter-frequency grid, the FRFs (interpolated between
/// them) the receptance; no modal fit is involved.
std::vector<StabilityLimit> measured_frf_diagram(const job::Job& job,
                                                 const std::vector<double>& speeds) {
  const dynamics::MeasuredReceptance receptance(analysis::load_measured_frfs(job));
  std::vector<double> grid_rad_s;
  for (const double f : receptance.frequencies_hz())
    grid_rad_s.push_back(2.0 * std::numbers::pi * f);
  const Eigen::Matrix3d a0 = stability::mean_cutting_stiffness_per_depth(
      tool::Tool(*job.tool), *job.cutting, *job.process);
  const stability::ZeroOrderSolver solver(a0, job.tool->teeth, receptance, std::move(grid_rad_s),
                                          job.stability->depth_max_m);
  std::vector<StabilityLimit> limits;
  for (const auto& z : solver.limits(speeds)) {
    limits.push_back({z.spindle_rad_s, z.depth_limit_m, z.limited, z.chatter_frequency_hz,
                      z.limited ? Bifurcation::hopf : Bifurcation::none, -1});
  }
  return limits;
}

/// The parser checks the time step against the modal table; fitted modes are
/// known only now: two steps per period of the highest one.
void check_stability_discretization(const job::Job& job, const dynamics::ModalModel& modes) {
  const Settings& settings = *job.stability;
  if (settings.method == Settings::Method::zoa)
    return;
  const double tau_max = 2.0 * std::numbers::pi / (job.tool->teeth * settings.speed_from_rad_s);
  const double needed = std::ceil(2.0 * modes.highest_frequency_hz() * tau_max * (1.0 - 1e-12));
  if (settings.discretization < needed) {
    throw InputError("stability.discretization", 0,
                     fmt::format("{} steps per tooth period are too coarse for the fitted {:g} Hz "
                                 "mode: at least {:.0f} needed (or method zoa)",
                                 settings.discretization, modes.highest_frequency_hz(), needed));
  }
}

/// 000 Figures 12-13: the traditional diagram, with process damping (when
/// the job gives it), with the deformation-corrected engagement, and both.
std::vector<DeformationVariant> deformation_variants(const job::Job& job,
                                                     const dynamics::ModalModel& modes,
                                                     const stability::LobeOptions& lobe_options,
                                                     const std::vector<double>& speeds, int threads,
                                                     DeformedEngagementFigures& figures) {
  const Settings& settings = *job.stability;
  const deflection::DeflectionSetup setup = analysis::deflection_setup(job);
  const deflection::DeformedEngagement engagement(setup, settings.depth_max_m,
                                                  job.deflection->table_depths, threads);
  const std::vector<dynamics::AxialShape> shapes = analysis::mode_shapes_along_tool(job);
  const bool damping = lobe_options.process_damping.has_value();
  std::vector<DeformationVariant> variants;
  variants.push_back({"traditional", false, false, {}, 0.0, 0.0, {}});
  if (damping)
    variants.push_back({"process_damping", true, false, {}, 0.0, 0.0, {}});
  variants.push_back({"deformation", false, true, {}, 0.0, 0.0, {}});
  if (damping)
    variants.push_back({"both", true, true, {}, 0.0, 0.0, {}});
  for (DeformationVariant& v : variants) {
    stability::MultipointStructure structure;
    structure.mode_shapes = shapes;
    if (v.deformation) {
      structure.entry_angle_rad = [&engagement](double depth_m, double height_m) {
        return engagement.entry_angle_rad(depth_m, height_m);
      };
    }
    const stability::RegenerativeModel model(tool::Tool(*job.tool), *job.cutting, *job.process,
                                             modes, structure);
    stability::LobeOptions o = lobe_options;
    if (!v.process_damping)
      o.process_damping.reset();
    v.limits = floquet_diagram(model, o, speeds);
  }
  // Each variant's expansion over the traditional diagram, speed by speed.
  const std::vector<StabilityLimit>& traditional = variants.front().limits;
  for (DeformationVariant& v : variants) {
    v.max_expansion = -INFINITY;
    for (std::size_t i = 0; i < v.limits.size(); ++i) {
      const double gain = v.limits[i].depth_limit_m / traditional[i].depth_limit_m - 1.0;
      if (gain > v.max_expansion) {
        v.max_expansion = gain;
        v.max_expansion_spindle_rad_s = v.limits[i].spindle_rad_s;
      }
    }
  }
  const double deepest = engagement.depths_m().back();
  figures.robot_included = static_cast<bool>(setup.robot);
  figures.mode_shapes_along_tool = !shapes.empty();
  figures.table_depths = static_cast<int>(engagement.depths_m().size());
  figures.nominal_entry_rad = engagement.nominal_entry_rad();
  figures.entry_at_depth_max_tip_rad = engagement.entry_angle_rad(deepest, 0.0);
  figures.entry_at_depth_max_top_rad = engagement.entry_angle_rad(deepest, deepest);
  return variants;
}

/// The computed speed nearest to a test's.
const StabilityLimit& nearest_limit(const std::vector<StabilityLimit>& limits,
                                    double spindle_rad_s) {
  return *std::min_element(limits.begin(), limits.end(),
                           [&](const StabilityLimit& a, const StabilityLimit& b) {
                             return std::abs(a.spindle_rad_s - spindle_rad_s) <
                                    std::abs(b.spindle_rad_s - spindle_rad_s);
                           });
}

}  // namespace

const char* to_string(Bifurcation bifurcation) noexcept {
  switch (bifurcation) {
    case Bifurcation::none:
      return "none";
    case Bifurcation::hopf:
      return "hopf";
    case Bifurcation::flip:
      return "flip";
    case Bifurcation::fold:
      return "fold";
  }
  return "none";
}

DiagramFigures diagram_figures(const std::vector<StabilityLimit>& limits) {
  DiagramFigures figures;
  figures.min_limit_m = INFINITY;
  for (const StabilityLimit& l : limits) {
    if (l.depth_limit_m < figures.min_limit_m) {
      figures.min_limit_m = l.depth_limit_m;
      figures.min_limit_spindle_rad_s = l.spindle_rad_s;
    }
    figures.max_limit_m = std::max(figures.max_limit_m, l.depth_limit_m);
    figures.speeds_stable_to_depth_max += l.limited ? 0 : 1;
    figures.speeds_period_doubling += l.bifurcation == Bifurcation::flip ? 1 : 0;
  }
  return figures;
}

std::optional<double> interpolated_limit_m(const std::vector<StabilityLimit>& limits,
                                           double spindle_rad_s) {
  if (limits.empty())
    return std::nullopt;
  if (limits.size() == 1) {
    return std::abs(limits[0].spindle_rad_s - spindle_rad_s) <= 1e-9 * spindle_rad_s
               ? std::optional(limits[0].depth_limit_m)
               : std::nullopt;
  }
  if (spindle_rad_s < limits.front().spindle_rad_s || spindle_rad_s > limits.back().spindle_rad_s) {
    return std::nullopt;
  }
  for (std::size_t i = 0; i + 1 < limits.size(); ++i) {
    const StabilityLimit& a = limits[i];
    const StabilityLimit& b = limits[i + 1];
    if (spindle_rad_s <= b.spindle_rad_s) {
      const double t = (spindle_rad_s - a.spindle_rad_s) / (b.spindle_rad_s - a.spindle_rad_s);
      return a.depth_limit_m + t * (b.depth_limit_m - a.depth_limit_m);
    }
  }
  return limits.back().depth_limit_m;
}

stability::FloquetMethod floquet_method(job::StabilitySettings::Method method) {
  switch (method) {
    case Settings::Method::sdm:
      return stability::FloquetMethod::sdm;
    case Settings::Method::fdm2:
      return stability::FloquetMethod::fdm2;
    default:
      return stability::FloquetMethod::fdm;
  }
}

ExperimentComparison compare_experiments(const std::vector<job::Experiment>& experiments,
                                         const std::vector<StabilityLimit>& limits,
                                         const dynamics::ModalModel* modes) {
  ExperimentComparison comparison;
  for (const job::Experiment& e : experiments) {
    // A recording's verdict is learn's (docs/learning.md), not written here;
    // a hammer test is no cut; a cut of another ae or direction has a
    // diagram of its own (learn predicts it).
    if (!e.verdict_given || e.hammer() || e.radial_depth_m || e.direction)
      continue;
    ExperimentCheck check;
    check.experiment = e;
    check.limit_m = interpolated_limit_m(limits, e.spindle_rad_s);
    if (check.limit_m) {
      check.predicted_chatter = e.axial_depth_m >= *check.limit_m;
      check.agrees = check.predicted_chatter == e.chatter;
      const StabilityLimit& nearest = nearest_limit(limits, e.spindle_rad_s);
      if (nearest.limited)
        check.chatter_frequency_hz = nearest.chatter_frequency_hz;
      check.governing_mode = nearest.mode;
      if (nearest.mode >= 0 && modes)
        check.governing_mode_fn_hz =
            modes->natural_rad_s()(nearest.mode) / (2.0 * std::numbers::pi);
      ++comparison.compared;
      comparison.agree += check.agrees ? 1 : 0;
    }
    comparison.tests.push_back(std::move(check));
  }
  return comparison;
}

StabilityDiagram stability_diagram(const job::Job& job, int threads,
                                   const stability::MeanCuttingStiffnessBasis* cut_basis) {
  job::require(job, {job::Section::tool, job::Section::cutting, job::Section::process,
                     job::Section::stability});
  const Settings& settings = *job.stability;
  if (settings.process_damping == Settings::Damping::energy_balance &&
      settings.method != Settings::Method::zoa) {
    throw InputError("stability.process_damping", 0,
                     "the energy-balance model applies to the zero-order method (003 §3.2); use "
                     "method: zoa, or model: linear_equivalent with sdm/fdm/fdm2");
  }
  if (settings.mode == Settings::Mode::map && settings.method == Settings::Method::zoa) {
    throw InputError("stability.mode", 0,
                     "a spectral-radius map needs a time-domain method (sdm, fdm or fdm2)");
  }

  StabilityDiagram diagram;
  diagram.method = settings.method;
  diagram.diagrams = settings.modes;
  const auto start = std::chrono::steady_clock::now();
  diagram.speeds_rad_s = stability::linear_range(settings.speed_from_rad_s, settings.speed_to_rad_s,
                                                 settings.speed_count);
  const std::vector<double>& speeds = diagram.speeds_rad_s;
  const bool measured = job.dynamics_source == job::Job::DynamicsSource::frf;
  std::optional<dynamics::ModalModel>& modes = diagram.modes;
  if (!measured) {
    modes = analysis::structure_modes(job);
    if (job.dynamics_source != job::Job::DynamicsSource::table)
      check_stability_discretization(job, *modes);
  }
  stability::LobeOptions lobe_options;
  lobe_options.method = floquet_method(settings.method);
  lobe_options.steps = settings.discretization;
  lobe_options.depth_max_m = settings.depth_max_m;
  lobe_options.depth_tolerance = settings.depth_tolerance;
  lobe_options.continuation = settings.continuation;
  lobe_options.threads = threads;
  if (settings.process_damping == Settings::Damping::linear_equivalent) {
    // 000 Eq 18-19 inside the time-domain methods.
    lobe_options.process_damping = stability::LinearProcessDamping{
        settings.indentation_n_per_m3, settings.wear_land_m, settings.friction};
  }

  const bool want_coupled = settings.modes != Settings::Modes::envelope;
  const bool want_envelope = settings.modes != Settings::Modes::coupled;
  if (measured) {
    diagram.coupled = measured_frf_diagram(job, speeds);
  } else if (settings.method == Settings::Method::zoa) {
    const stability::RegenerativeModel model(tool::Tool(*job.tool), *job.cutting, *job.process,
                                             *modes);
    if (want_coupled)
      diagram.coupled = zero_order_diagram(model, settings, speeds, false, threads, cut_basis);
    if (want_envelope)
      diagram.envelope = zero_order_diagram(model, settings, speeds, true, threads, cut_basis);
  } else if (settings.deformation) {
    if (settings.modes != Settings::Modes::coupled || settings.mode == Settings::Mode::map) {
      throw InputError("stability.deformation", 0,
                       "gives the coupled boundary diagrams of 000 (modes: coupled, mode: "
                       "boundary)");
    }
    DeformedEngagementFigures figures;
    diagram.variants = deformation_variants(job, *modes, lobe_options, speeds, threads, figures);
    diagram.deformation = figures;
    diagram.coupled = diagram.variants.front().limits;
  } else {
    // The time-domain methods take the modes' measured shapes along the tool
    // (000 Eq 35) when the table gives them: the multipoint model.
    stability::MultipointStructure structure;
    structure.mode_shapes = analysis::mode_shapes_along_tool(job);
    const stability::RegenerativeModel model(tool::Tool(*job.tool), *job.cutting, *job.process,
                                             *modes, structure);
    if (want_coupled)
      diagram.coupled = floquet_diagram(model, lobe_options, speeds);
    if (want_envelope)
      diagram.envelope = floquet_envelope(job, *modes, lobe_options, speeds);
    if (settings.mode == Settings::Mode::map) {
      const auto depths = stability::linear_range(settings.depth_max_m / settings.depth_count,
                                                  settings.depth_max_m, settings.depth_count);
      diagram.map = stability::stability_map(model, speeds, depths, lobe_options);
    }
  }
  diagram.elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const dynamics::ModalModel* structure = modes ? &*modes : nullptr;
  diagram.experiments = compare_experiments(job.experiments, diagram.primary(), structure);
  if (want_coupled && want_envelope)
    diagram.envelope_experiments =
        compare_experiments(job.experiments, diagram.envelope, structure);
  for (DeformationVariant& v : diagram.variants)
    v.experiments = compare_experiments(job.experiments, v.limits, structure);

  if (settings.method != Settings::Method::zoa && modes && modes->size() > 0) {
    DiscretizationCheck check;
    check.discretization = settings.discretization;
    check.highest_mode_hz = modes->highest_frequency_hz();
    check.lowest_spindle_rad_s = speeds.front();
    const double tau_max_s = 2.0 * std::numbers::pi / (job.tool->teeth * speeds.front());
    check.steps_per_period = settings.discretization / (check.highest_mode_hz * tau_max_s);
    check.discretization_for_convergence = std::ceil(
        DiscretizationCheck::converged_steps_per_period * check.highest_mode_hz * tau_max_s);
    diagram.discretization = check;
  }
  return diagram;
}

}  // namespace robomill::analysis
