// robomill stability JOB: the stability lobe diagram (DESIGN.md §3) by the
// zero-order approximation or the semi-/full-discretization methods.

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <numbers>
#include <optional>

#include "commands.hpp"
#include "robomill/core/error.hpp"
#include "robomill/dynamics/measured_receptance.hpp"
#include "robomill/dynamics/modal_model.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/deformation.hpp"
#include "robomill/io/structure.hpp"
#include "robomill/io/summary.hpp"
#include "robomill/stability/lobes.hpp"
#include "robomill/stability/process_damping.hpp"
#include "robomill/stability/zero_order.hpp"

namespace robomill::app {
namespace {

constexpr double kRpmPerRadS = 60.0 / (2.0 * std::numbers::pi);
using Settings = io::StabilitySettings;

/// One speed of a diagram, whatever method produced it.
struct Limit {
  double spindle_rad_s = 0.0;
  double depth_limit_m = 0.0;
  bool limited = false;
  double chatter_frequency_hz = 0.0;
  std::string bifurcation = "none";
  int mode = -1;  ///< governing mode of an envelope, −1 for a coupled diagram
};

stability::FloquetMethod floquet_method(Settings::Method method) {
  switch (method) {
    case Settings::Method::sdm:
      return stability::FloquetMethod::sdm;
    case Settings::Method::fdm2:
      return stability::FloquetMethod::fdm2;
    default:
      return stability::FloquetMethod::fdm;
  }
}

const char* method_name(Settings::Method method) {
  switch (method) {
    case Settings::Method::zoa:
      return "zoa";
    case Settings::Method::sdm:
      return "sdm";
    case Settings::Method::fdm:
      return "fdm";
    case Settings::Method::fdm2:
      return "fdm2";
  }
  return "?";
}

std::optional<stability::ProcessDamping> process_damping(const Settings& settings) {
  if (settings.process_damping == Settings::Damping::none)
    return std::nullopt;
  stability::ProcessDamping damping;
  damping.model = settings.process_damping == Settings::Damping::energy_balance
                      ? stability::ProcessDampingModel::energy_balance
                      : stability::ProcessDampingModel::linear_equivalent;
  damping.indentation_n_per_m3 = settings.indentation_n_per_m3;
  damping.wear_land_m = settings.wear_land_m;
  damping.friction = settings.friction;
  return damping;
}

std::vector<Limit> zero_order_diagram(const stability::RegenerativeModel& model,
                                      const Settings& settings, const std::vector<double>& speeds,
                                      bool envelope, int threads) {
  stability::ProcessDampedOptions options;
  options.zero_order.depth_max_m = settings.depth_max_m;
  options.method =
      envelope ? stability::MultiModeMethod::envelope : stability::MultiModeMethod::coupled;
  options.threads = threads;
  std::vector<Limit> limits;
  for (const auto& z :
       stability::process_damped_limits(model, process_damping(settings), speeds, options)) {
    limits.push_back({z.spindle_rad_s, z.depth_limit_m, z.limited, z.chatter_frequency_hz,
                      z.limited ? "hopf" : "none", z.mode});
  }
  return limits;
}

std::vector<Limit> floquet_diagram(const stability::RegenerativeModel& model,
                                   const stability::LobeOptions& options,
                                   const std::vector<double>& speeds) {
  std::vector<Limit> limits;
  for (const auto& p : stability::stability_boundary(model, speeds, options)) {
    limits.push_back(
        {p.spindle_rad_s, p.depth_limit_m, p.limited, p.chatter_frequency_hz, p.bifurcation, -1});
  }
  return limits;
}

/// 003 §3.2: the lowest envelope of the diagrams of each mode alone.
std::vector<Limit> floquet_envelope(const io::Job& job, const dynamics::ModalModel& modes,
                                    const stability::LobeOptions& options,
                                    const std::vector<double>& speeds) {
  std::vector<Limit> envelope;
  for (int q = 0; q < modes.size(); ++q) {
    const stability::RegenerativeModel single(tool::Tool(*job.tool), *job.cutting, *job.process,
                                              modes.subset({q}));
    const std::vector<Limit> diagram = floquet_diagram(single, options, speeds);
    if (envelope.empty()) {
      envelope = diagram;
      for (Limit& l : envelope)
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

io::CsvTable limit_table(const std::vector<Limit>& limits, bool with_mode) {
  std::vector<std::string> columns = {"spindle_rpm", "depth_limit_mm", "chatter_freq_hz",
                                      "bifurcation"};
  if (with_mode)
    columns.push_back("mode");
  io::CsvTable table(columns);
  for (const Limit& l : limits) {
    std::vector<io::CsvTable::Cell> row = {l.spindle_rad_s * kRpmPerRadS, l.depth_limit_m * 1e3,
                                           l.chatter_frequency_hz, l.bifurcation};
    if (with_mode)
      row.emplace_back(static_cast<double>(l.mode + 1));
    table.add_cells(row);
  }
  return table;
}

/// The limit at any speed inside the diagram's range, linear between speeds.
std::optional<double> interpolated_limit_m(const std::vector<Limit>& limits, double spindle_rad_s) {
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
    const Limit& a = limits[i];
    const Limit& b = limits[i + 1];
    if (spindle_rad_s <= b.spindle_rad_s) {
      const double t = (spindle_rad_s - a.spindle_rad_s) / (b.spindle_rad_s - a.spindle_rad_s);
      return a.depth_limit_m + t * (b.depth_limit_m - a.depth_limit_m);
    }
  }
  return limits.back().depth_limit_m;
}

/// The computed speed nearest to a test's: its chatter frequency and, in an
/// envelope, the governing mode say which structure the prediction blames.
const Limit& nearest_limit(const std::vector<Limit>& limits, double spindle_rad_s) {
  return *std::min_element(limits.begin(), limits.end(), [&](const Limit& a, const Limit& b) {
    return std::abs(a.spindle_rad_s - spindle_rad_s) < std::abs(b.spindle_rad_s - spindle_rad_s);
  });
}

nlohmann::json experiment_check(const io::Job& job, const dynamics::ModalModel* modes,
                                const std::vector<Limit>& limits) {
  nlohmann::json tests = nlohmann::json::array();
  int agree = 0, compared = 0;
  for (const io::Experiment& e : job.experiments) {
    nlohmann::json entry = {{"spindle_rpm", e.spindle_rad_s * kRpmPerRadS},
                            {"depth_mm", e.axial_depth_m * 1e3},
                            {"observed_chatter", e.chatter}};
    if (const auto limit = interpolated_limit_m(limits, e.spindle_rad_s)) {
      const bool predicted = e.axial_depth_m >= *limit;
      entry["limit_mm"] = *limit * 1e3;
      entry["predicted_chatter"] = predicted;
      entry["agrees"] = predicted == e.chatter;
      const Limit& nearest = nearest_limit(limits, e.spindle_rad_s);
      if (nearest.limited)
        entry["chatter_freq_hz"] = nearest.chatter_frequency_hz;
      if (nearest.mode >= 0 && modes) {
        entry["governing_mode"] = nearest.mode + 1;
        entry["governing_mode_fn_hz"] =
            modes->natural_rad_s()(nearest.mode) / (2.0 * std::numbers::pi);
      }
      ++compared;
      agree += predicted == e.chatter ? 1 : 0;
    } else {
      entry["note"] = "spindle speed outside the computed range";
    }
    tests.push_back(entry);
  }
  return {{"tests", tests},
          {"agree", agree},
          {"compared", compared},
          {"total", job.experiments.size()}};
}

/// The zero-order diagram straight from the measured FRFs: the measured
/// frequencies are the chatter-frequency grid, the FRFs (interpolated between
/// them) the receptance; no modal fit is involved.
std::vector<Limit> measured_frf_diagram(const io::Job& job, const std::vector<double>& speeds) {
  const dynamics::MeasuredReceptance receptance(io::load_measured_frfs(job));
  std::vector<double> grid_rad_s;
  for (const double f : receptance.frequencies_hz())
    grid_rad_s.push_back(2.0 * std::numbers::pi * f);
  const Eigen::Matrix3d a0 = stability::mean_cutting_stiffness_per_depth(
      tool::Tool(*job.tool), *job.cutting, *job.process);
  const stability::ZeroOrderSolver solver(a0, job.tool->teeth, receptance, std::move(grid_rad_s),
                                          job.stability->depth_max_m);
  std::vector<Limit> limits;
  for (const auto& z : solver.limits(speeds)) {
    limits.push_back({z.spindle_rad_s, z.depth_limit_m, z.limited, z.chatter_frequency_hz,
                      z.limited ? "hopf" : "none", -1});
  }
  return limits;
}

/// The parser checks the time step against the modal table; fitted modes are
/// known only now: two steps per period of the highest one.
void check_discretization(const io::Job& job, const dynamics::ModalModel& modes) {
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

nlohmann::json diagram_summary(const std::vector<Limit>& limits) {
  double min_limit = INFINITY, max_limit = 0.0, min_speed = 0.0;
  int unlimited = 0, flips = 0;
  for (const Limit& l : limits) {
    if (l.depth_limit_m < min_limit) {
      min_limit = l.depth_limit_m;
      min_speed = l.spindle_rad_s;
    }
    max_limit = std::max(max_limit, l.depth_limit_m);
    unlimited += l.limited ? 0 : 1;
    flips += l.bifurcation == "flip" ? 1 : 0;
  }
  return {{"min_limit_mm", min_limit * 1e3},
          {"min_limit_spindle_rpm", min_speed * kRpmPerRadS},
          {"max_limit_mm", max_limit * 1e3},
          {"speeds_stable_to_depth_max", unlimited},
          {"speeds_period_doubling", flips}};
}

/// 000 Figures 12-13: the diagram without and with process damping and
/// with and without the deformation-corrected engagement, all on the
/// multipoint model (the modes' shapes along the tool).
struct Variant {
  const char* name;  ///< column suffix: "", "process_damping", "deformation", "both"
  bool process_damping, deformation;
  std::vector<Limit> limits;
};

std::vector<Variant> deformation_variants(const io::Job& job, const dynamics::ModalModel& modes,
                                          const stability::LobeOptions& lobe_options,
                                          const std::vector<double>& speeds, int threads,
                                          nlohmann::json& report) {
  const Settings& settings = *job.stability;
  const deflection::DeflectionSetup setup = io::deflection_setup(job);
  const deflection::DeformedEngagement engagement(setup, settings.depth_max_m,
                                                  job.deflection->table_depths, threads);
  const std::vector<dynamics::AxialShape> shapes = io::mode_shapes_along_tool(job);
  const bool damping = lobe_options.process_damping.has_value();
  std::vector<Variant> variants = {{"", false, false, {}}};
  if (damping)
    variants.push_back({"process_damping", true, false, {}});
  variants.push_back({"deformation", false, true, {}});
  if (damping)
    variants.push_back({"both", true, true, {}});
  for (Variant& v : variants) {
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
  // How far the deformed engagement moved: the entry angle at the tip and at
  // the top of the flute for the deepest tabulated depth.
  const double deepest = engagement.depths_m().back();
  report = {{"robot_included", static_cast<bool>(setup.robot)},
            {"mode_shapes_along_tool", !shapes.empty()},
            {"table_depths", engagement.depths_m().size()},
            {"nominal_entry_deg", engagement.nominal_entry_rad() * 180.0 / std::numbers::pi},
            {"entry_at_depth_max_deg",
             {{"tip", engagement.entry_angle_rad(deepest, 0.0) * 180.0 / std::numbers::pi},
              {"top", engagement.entry_angle_rad(deepest, deepest) * 180.0 / std::numbers::pi}}}};
  return variants;
}

}  // namespace

CommandResult compute_stability(const io::Job& job, int threads) {
  io::require(
      job, {io::Section::tool, io::Section::cutting, io::Section::process, io::Section::stability});
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

  const auto start = std::chrono::steady_clock::now();
  const std::vector<double> speeds = stability::linear_range(
      settings.speed_from_rad_s, settings.speed_to_rad_s, settings.speed_count);
  const bool measured = job.dynamics_source == io::Job::DynamicsSource::frf;
  std::optional<dynamics::ModalModel> modes;
  if (!measured) {
    modes = io::structure_modes(job);
    if (job.dynamics_source != io::Job::DynamicsSource::table)
      check_discretization(job, *modes);
  }
  stability::LobeOptions lobe_options;
  lobe_options.method = floquet_method(settings.method);
  lobe_options.steps = settings.discretization;
  lobe_options.depth_max_m = settings.depth_max_m;
  lobe_options.depth_tolerance = settings.depth_tolerance;
  lobe_options.continuation = settings.continuation;
  lobe_options.threads = threads;
  if (settings.process_damping == Settings::Damping::linear_equivalent) {
    lobe_options.process_damping = stability::LinearProcessDamping{
        settings.indentation_n_per_m3, settings.wear_land_m, settings.friction};
  }

  const bool want_coupled = settings.modes != Settings::Modes::envelope;
  const bool want_envelope = settings.modes != Settings::Modes::coupled;
  std::vector<Limit> coupled, envelope;
  std::vector<Variant> variants;  // stability.deformation: 000's four diagrams
  nlohmann::json deformation;
  std::optional<stability::StabilityMap> map;
  if (measured) {
    coupled = measured_frf_diagram(job, speeds);
  } else if (settings.method == Settings::Method::zoa) {
    const stability::RegenerativeModel model(tool::Tool(*job.tool), *job.cutting, *job.process,
                                             *modes);
    if (want_coupled)
      coupled = zero_order_diagram(model, settings, speeds, false, threads);
    if (want_envelope)
      envelope = zero_order_diagram(model, settings, speeds, true, threads);
  } else if (settings.deformation) {
    if (settings.modes != Settings::Modes::coupled || settings.mode == Settings::Mode::map) {
      throw InputError("stability.deformation", 0,
                       "gives the coupled boundary diagrams of 000 (modes: coupled, mode: "
                       "boundary)");
    }
    variants = deformation_variants(job, *modes, lobe_options, speeds, threads, deformation);
    coupled = variants.front().limits;
  } else {
    // The time-domain methods take the modes' measured shapes along the tool
    // (000 Eq 35) when the table gives them: the multipoint model.
    stability::MultipointStructure structure;
    structure.mode_shapes = io::mode_shapes_along_tool(job);
    const stability::RegenerativeModel model(tool::Tool(*job.tool), *job.cutting, *job.process,
                                             *modes, structure);
    if (want_coupled)
      coupled = floquet_diagram(model, lobe_options, speeds);
    if (want_envelope)
      envelope = floquet_envelope(job, *modes, lobe_options, speeds);
    if (settings.mode == Settings::Mode::map) {
      const auto depths = stability::linear_range(settings.depth_max_m / settings.depth_count,
                                                  settings.depth_max_m, settings.depth_count);
      map = stability::stability_map(model, speeds, depths, lobe_options);
    }
  }
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::vector<Limit>& primary = want_coupled ? coupled : envelope;

  nlohmann::json summary = {
      {"command", "stability"},
      {"job", job.source.string()},
      {"method", method_name(settings.method)},
      {"elapsed_s", elapsed_s},
      {"speeds",
       {{"from_rpm", settings.speed_from_rad_s * kRpmPerRadS},
        {"to_rpm", settings.speed_to_rad_s * kRpmPerRadS},
        {"count", settings.speed_count}}},
      {"depth_max_mm", settings.depth_max_m * 1e3},
      {"depth_tolerance", settings.depth_tolerance},
      {"continuation", settings.continuation},
      {"modes", settings.modes == Settings::Modes::coupled    ? "coupled"
                : settings.modes == Settings::Modes::envelope ? "envelope"
                                                              : "both"},
      {"dynamics", io::dynamics_source_name(job.dynamics_source)},
      {"mode_count", modes ? modes->size() : 0},
      {"process_damping", settings.process_damping == Settings::Damping::none ? "none"
                          : settings.process_damping == Settings::Damping::energy_balance
                              ? "energy_balance"
                              : "linear_equivalent"},
      {"experiments", experiment_check(job, modes ? &*modes : nullptr, primary)},
  };
  std::string convergence_warning;
  if (settings.method != Settings::Method::zoa) {
    summary["discretization"] = settings.discretization;
    if (modes && modes->size() > 0) {
      // The parser asks for two steps per period of the highest mode (no
      // aliasing); the boundary converges at about eight (docs/assumptions.md,
      // measured on the 1-DOF benchmark at 1500 rpm: 2.2 steps per period
      // put the limit 2.4x too high).
      const double tau_max_s = 2.0 * std::numbers::pi / (job.tool->teeth * speeds.front());
      const double per_period =
          settings.discretization / (modes->highest_frequency_hz() * tau_max_s);
      summary["steps_per_period_of_highest_mode"] = per_period;
      if (per_period < 8.0) {
        convergence_warning = fmt::format(
            "{} steps per tooth period give {:.1f} steps per period of the {:.4g} Hz mode at "
            "{:.0f} rpm: the lowest speeds may not be converged; discretization: {:.0f} gives 8",
            settings.discretization, per_period, modes->highest_frequency_hz(),
            speeds.front() * kRpmPerRadS,
            std::ceil(8.0 * modes->highest_frequency_hz() * tau_max_s));
        summary["discretization_warning"] = convergence_warning;
      }
    }
  }
  if (job.posture_library) {
    // 001 Eq 16-18: where the table was interpolated and with what weights.
    const io::PostureLibrary& library = *job.posture_library;
    nlohmann::json query = nlohmann::json::array(), weights = nlohmann::json::array();
    for (Eigen::Index i = 0; i < library.query_rad.size(); ++i)
      query.push_back(library.query_rad[i] * 180.0 / std::numbers::pi);
    for (Eigen::Index i = 0; i < library.weights.size(); ++i)
      weights.push_back(library.weights[i]);
    summary["posture_interpolation"] = {{"at_deg", query},
                                        {"from", library.query_source},
                                        {"postures", library.postures_rad.size()},
                                        {"weights", weights},
                                        {"exact_posture", library.exact_index + 1}};
  }
  summary.update(diagram_summary(primary));
  if (want_coupled && want_envelope) {
    summary["envelope"] = diagram_summary(envelope);
    summary["envelope"]["experiments"] = experiment_check(job, &*modes, envelope);
  }
  if (!variants.empty()) {
    // 000 Figures 12-13: each variant's figures and its expansion over the
    // traditional diagram, speed by speed.
    nlohmann::json list = nlohmann::json::object();
    for (const Variant& v : variants) {
      nlohmann::json entry = diagram_summary(v.limits);
      double max_gain = -INFINITY, max_gain_rpm = 0.0;
      for (std::size_t i = 0; i < v.limits.size(); ++i) {
        const double gain = v.limits[i].depth_limit_m / coupled[i].depth_limit_m - 1.0;
        if (gain > max_gain) {
          max_gain = gain;
          max_gain_rpm = v.limits[i].spindle_rad_s * kRpmPerRadS;
        }
      }
      entry["max_expansion_pct"] = 100.0 * max_gain;
      entry["max_expansion_spindle_rpm"] = max_gain_rpm;
      entry["experiments"] = experiment_check(job, &*modes, v.limits);
      list[*v.name ? v.name : "traditional"] = entry;
    }
    deformation["variants"] = list;
    summary["deformation"] = deformation;
  }
  if (map) {
    summary["map"] = {{"speeds", map->spindle_rad_s.size()},
                      {"depths", map->depth_m.size()},
                      {"grid_points_per_s", static_cast<double>(map->spectral_radius.size()) /
                                                std::max(elapsed_s, 1e-9)}};
  }
  if (!job.name.empty())
    summary["name"] = job.name;

  CommandResult result;
  result.summary = std::move(summary);
  if (variants.empty()) {
    result.tables.emplace_back("sld", limit_table(primary, !want_coupled));
  } else {
    // One limit and chatter-frequency column per variant next to the
    // traditional diagram's (DESIGN.md's columns).
    std::vector<std::string> columns = {"spindle_rpm", "depth_limit_mm", "chatter_freq_hz",
                                        "bifurcation"};
    for (std::size_t v = 1; v < variants.size(); ++v) {
      columns.push_back(fmt::format("depth_limit_{}_mm", variants[v].name));
      columns.push_back(fmt::format("chatter_freq_{}_hz", variants[v].name));
    }
    io::CsvTable table(columns);
    for (std::size_t i = 0; i < primary.size(); ++i) {
      const Limit& l = primary[i];
      std::vector<io::CsvTable::Cell> row = {l.spindle_rad_s * kRpmPerRadS, l.depth_limit_m * 1e3,
                                             l.chatter_frequency_hz, l.bifurcation};
      for (std::size_t v = 1; v < variants.size(); ++v) {
        row.emplace_back(variants[v].limits[i].depth_limit_m * 1e3);
        row.emplace_back(variants[v].limits[i].chatter_frequency_hz);
      }
      table.add_cells(row);
    }
    result.tables.emplace_back("sld", std::move(table));
  }
  if (want_coupled && want_envelope)
    result.tables.emplace_back("sld_envelope", limit_table(envelope, true));
  if (map) {
    io::CsvTable table({"spindle_rpm", "depth_mm", "spectral_radius"});
    for (std::size_t i = 0; i < map->spindle_rad_s.size(); ++i) {
      for (std::size_t j = 0; j < map->depth_m.size(); ++j) {
        table.add_row(
            {map->spindle_rad_s[i] * kRpmPerRadS, map->depth_m[j] * 1e3,
             map->spectral_radius(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j))});
      }
    }
    result.tables.emplace_back("map", std::move(table));
  }

  const nlohmann::json figures = diagram_summary(primary);
  result.message = fmt::format(
      "stability ({}): {} speeds in {:.3f} s; limit {:.3f} mm (at {:.0f} rpm) … {:.3f} mm\n",
      method_name(settings.method), speeds.size(), elapsed_s, figures["min_limit_mm"].get<double>(),
      figures["min_limit_spindle_rpm"].get<double>(), figures["max_limit_mm"].get<double>());
  if (!convergence_warning.empty())
    result.message += "  warning: " + convergence_warning + "\n";
  if (!job.experiments.empty()) {
    const nlohmann::json& check = result.summary["experiments"];
    result.message += fmt::format("  experiments: {} of {} agree with the prediction\n",
                                  check["agree"].get<int>(), check["compared"].get<int>());
  }
  return result;
}

int run_stability(const JobCommandOptions& options) {
  return run_job_command(options, "stability", [&](const io::Job& job) {
    return compute_stability(job, options.threads);
  });
}

}  // namespace robomill::app
