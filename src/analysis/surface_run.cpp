// The `robomill surface` computation (001 §2.1-2.4) from a job: checks of
// 001 Eq 29-31, coverage and shank naming the job's fields, the raster path
// over the patch, the vibration from the time-domain simulation at the job's
// (posture-interpolated) dynamics, the Z-map and its roughness.

#include "robomill/analysis/surface_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "robomill/analysis/structure.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"
#include "robomill/cutting/milling_forces.hpp"
#include "robomill/simulation/simulator.hpp"
#include "robomill/simulation/structure.hpp"

namespace robomill::analysis {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

int line_or(int line, int fallback) {
  return line > 0 ? line : fallback;
}

/// 001 §2.1.4: the shank must stay above the stock (R (1 − sin θ) ≥ ap).
void check_shank(const job::Job& job, const job::SurfaceSettings& s, const tool::Tool& cutter,
                 const surface::ToolOrientation& orientation) {
  const double ap = job.process->axial_depth_m;
  const double clearance = surface::shank_clearance_m(cutter, orientation);
  if (clearance >= ap)
    return;
  if (cutter.type() != tool::ToolType::ball)
    throw InputError("process.ap", 0,
                     fmt::format("{:.4g} mm: the holder would cut (it clears {:.4g} mm)", ap * 1e3,
                                 clearance * 1e3));
  const double radius = cutter.radius_m();
  if (ap >= radius)
    throw InputError("process.ap", 0,
                     fmt::format("{:.4g} mm reaches above the ball ({:.4g} mm radius): the shank "
                                 "would cut; use ap below {:.4g} mm",
                                 ap * 1e3, radius * 1e3, radius * 1e3));
  const double theta_max = std::asin(1.0 - ap / radius);
  const double theta = std::acos(std::cos(orientation.lead_rad) * std::cos(orientation.tilt_rad));
  // Name the larger of the two angles and the value of it that would work.
  const bool lead = std::abs(orientation.lead_rad) >= std::abs(orientation.tilt_rad);
  const double other = lead ? orientation.tilt_rad : orientation.lead_rad;
  const double limit =
      std::acos(std::min(1.0, std::cos(theta_max) / std::max(std::cos(other), 1e-12)));
  throw InputError(
      lead ? "surface.lead" : "surface.tilt", line_or(lead ? s.lead_line : s.tilt_line, s.line),
      fmt::format("the tool axis is {:.3g} deg from the surface normal, so the shank (R(1 - sin "
                  "theta) = {:.4g} mm above the surface) cuts the {:.4g} mm of stock; the axis "
                  "may lean at most {:.3g} deg: use |{}| <= {:.3g} deg",
                  theta / kDegree, clearance * 1e3, ap * 1e3, theta_max / kDegree,
                  lead ? "lead" : "tilt", limit / kDegree));
}

simulation::LinearStructure vibration_structure(const job::Job& job,
                                                const job::SurfaceSettings& s) {
  if (job.modes.empty() && job.frf_files.empty() &&
      job.dynamics_source == job::Job::DynamicsSource::table)
    throw InputError("surface.vibration", line_or(s.vibration_line, s.line),
                     "needs the structure: add a dynamics: section (modes, or postures with "
                     "dynamics.at for 001's posture-dependent dynamics)");
  if (!job.cutting)
    throw InputError("surface.vibration", line_or(s.vibration_line, s.line),
                     "needs the cutting: section (the forces that drive the vibration)");
  return simulation::modal_structure(structure_modes(job));
}

/// 001 §2.2: the tool-tip vibration over the raster, from the time-domain
/// simulation of the cut (simulation/simulator.hpp) on the job's structure.
/// The raster's engagement is the previous pass's groove: every disk of the
/// edge cuts a crescent one step-over deep (Workpiece::raster_groove;
/// docs/surface.md).
SurfaceVibration simulate_vibration(const job::Job& job, const job::SurfaceSettings& s,
                                    const tool::Tool& cutter, double path_time_s,
                                    std::optional<double> border_m) {
  // One pass simulated from rest and reused for every pass: with an entry
  // (the part's border ahead of the cutter) or 001's dde23 reading (start:
  // rest — a zero history, the cut fully engaged from t = 0).
  const bool per_pass = border_m.has_value() || s.start_at_rest;
  SurfaceVibration run;
  const simulation::LinearStructure structure = vibration_structure(job, s);
  run.structure = structure.description;
  const Eigen::VectorXd frequencies = simulation::natural_frequencies_hz(structure);
  run.natural_frequencies_hz.assign(frequencies.data(), frequencies.data() + frequencies.size());
  const cutting::MillingProcess& process = *job.process;
  const double tooth_period_s = kTwoPi / (process.spindle_rad_s * cutter.teeth());
  int needed = 40;
  double slowest_decay_s = 0.0;
  for (int i = 0; i < structure.size(); ++i) {
    const double omega = std::sqrt(structure.stiffness(i, i) / structure.mass(i, i));
    const double zeta = structure.damping(i, i) / (2.0 * omega * structure.mass(i, i));
    needed = std::max(needed, static_cast<int>(std::ceil(8.0 * omega / kTwoPi * tooth_period_s)));
    if (zeta > 0.0)
      slowest_decay_s = std::max(slowest_decay_s, 1.0 / (zeta * omega));
  }
  // The raster's engagement: the previous pass's groove leaves a strip one
  // step-over wide at every height, so each disk of the edge cuts a crescent
  // of radial depth `stepover` (Workpiece::raster_groove), down to the tip.
  // The step must resolve its narrowest arc.
  cutting::MillingProcess raster = process;
  raster.radial_depth_m = s.stepover_m;
  simulation::Workpiece part;
  part.raster_groove = true;
  const simulation::ArcResolution arc = simulation::engaged_arc_resolution(cutter, raster, part);
  const bool arc_rules = arc.steps_per_tooth > needed;
  needed = std::max(needed, arc.steps_per_tooth);
  run.steps_per_tooth = s.simulation_steps_per_tooth > 0 ? s.simulation_steps_per_tooth : needed;
  if (run.steps_per_tooth < needed)
    throw InputError(
        "surface.steps_per_tooth", s.line,
        fmt::format("{} steps per tooth period do not resolve {}; use steps_per_tooth: {} or more",
                    run.steps_per_tooth,
                    arc_rules ? fmt::format("the engaged arc of {:.1f} deg ({} steps across it)",
                                            arc.arc_rad * 180.0 / std::numbers::pi,
                                            simulation::kStepsAcrossEngagedArc)
                              : std::string("the highest mode (8 steps per period)"),
                    needed));
  // Start in the steady cut: three decay times of the slowest mode (at most
  // 10 s) before the patch, unless surface.warmup says otherwise.
  // Per pass (entry, start: rest): no warm-up, the series restarts per pass.
  run.warmup_s =
      per_pass ? 0.0 : (s.warmup_s ? *s.warmup_s : std::min(10.0, 3.0 * slowest_decay_s));
  run.duration_s = run.warmup_s + path_time_s;
  const double steps = run.duration_s / tooth_period_s * run.steps_per_tooth;
  if (steps > 2e8)
    throw InputError("surface.vibration", line_or(s.vibration_line, s.line),
                     fmt::format("the simulation would take {:.3g} steps (limit 2e8); shorten the "
                                 "warmup, the patch or steps_per_tooth",
                                 steps));
  simulation::SimulationOptions options;
  options.duration_s = run.duration_s;
  options.steps_per_tooth = run.steps_per_tooth;
  options.axial_elements = cutting::default_axial_elements(cutter, process.axial_depth_m);
  options.record_every = std::max(1, static_cast<int>(std::ceil(steps / 4e6)));
  simulation::SimulationResult result;
  try {
    if (border_m)
      part.border_x_m = *border_m;
    result = simulation::simulate(cutter, *job.cutting, raster, structure, part, options);
  } catch (const std::invalid_argument& error) {
    throw InputError("surface.vibration", line_or(s.vibration_line, s.line), error.what());
  }
  simulation::ResponseOptions analysis;
  analysis.spindle_rad_s = process.spindle_rad_s;
  analysis.teeth = cutter.teeth();
  analysis.runout = cutter.runout().offset_m > 0.0;
  analysis.feed_per_tooth_m = process.feed_per_tooth_m;
  analysis.steady_window_s =
      std::max(0.5 * run.duration_s, kTwoPi / process.spindle_rad_s * (analysis.runout ? 1 : 0.5));
  try {
    run.verdict = simulation::analyze_response(result, analysis).chatter;
  } catch (const std::invalid_argument&) {
    // A run too short for a verdict (under a revolution): none.
  }
  run.vibration.step_s = result.record_interval_s;
  run.vibration.per_pass = per_pass;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (std::size_t i = 0; i < result.size(); ++i) {
    if (result.time_s[i] + 1e-12 < run.warmup_s)
      continue;
    const Eigen::Vector3d& u = result.displacement_m[i];
    run.vibration.displacement_m.push_back(u);
    run.mean_m += u;
    lo = lo.cwiseMin(u);
    hi = hi.cwiseMax(u);
  }
  if (!run.vibration.displacement_m.empty()) {
    run.mean_m /= static_cast<double>(run.vibration.displacement_m.size());
    run.peak_to_peak_m = hi - lo;
  }
  return run;
}

/// 001 Eq 29 (the grid against the feed and stepover) and Eq 31 (the edge
/// sampled at least as finely as the grid).
void check_resolution(const job::SurfaceSettings& s, const surface::ZMapGrid& grid,
                      const surface::ResolutionRules& rules) {
  if (s.grid_rule && std::max(grid.dx(), grid.dy()) > rules.max_cell_m * (1.0 + 1e-9))
    throw InputError(
        "surface.grid", line_or(s.grid_line, s.line),
        fmt::format("cells of {:.4g} x {:.4g} um are coarser than 001 Eq 29 allows (max(dx, dy) "
                    "<= min(fz, stepover) / 5 = {:.4g} um): use grid: [{}, {}] or more (or "
                    "grid_rule: false to accept a coarse grid)",
                    grid.dx() * 1e6, grid.dy() * 1e6, rules.max_cell_m * 1e6,
                    static_cast<long long>(std::ceil(grid.length_x_m / rules.max_cell_m - 1e-9)),
                    static_cast<long long>(std::ceil(grid.length_y_m / rules.max_cell_m - 1e-9))));
  // 001 Eq 31: the edge is sampled at least as finely as the grid.
  const double cell = std::min(grid.dx(), grid.dy());
  if (s.edge_spacing_m > cell * (1.0 + 1e-9))
    throw InputError("surface.edge_spacing", line_or(s.spacing_line, s.line),
                     fmt::format("{:.4g} um breaks 001 Eq 31 (the edge must be sampled at least "
                                 "as finely as the grid): use edge_spacing: {:.4g} um or less",
                                 s.edge_spacing_m * 1e6, cell * 1e6));
}

/// The raster's extent and timing, set by lay_out_passes.
struct PassLayout {
  std::optional<double> border_m;  // the part's edge ahead of the cutter's centre at t = 0
  double pass_time_s = 0.0;
  double path_time_s = 0.0;
};

/// Sets the path's first pass, passes and x extent from the job (checking
/// that they cover the patch) and returns the pass and path times.
PassLayout lay_out_passes(const job::SurfaceSettings& s, const tool::Tool& cutter,
                          const surface::ZMapGrid& grid, const surface::ResolutionRules& rules,
                          surface::RasterPath& path) {
  PassLayout layout;
  // The passes: the contact lines must cover the patch in y; by default they
  // reach beyond it by the width of the evaluated band on both sides.
  const double margin_m = rules.lateral_reach_m + cutter.runout().offset_m + 0.05e-3;
  const double y_lo = grid.y0_m, y_hi = grid.y0_m + grid.length_y_m;
  if (s.first_pass_y_m) {
    path.first_pass_y_m = *s.first_pass_y_m;
  } else {
    path.first_pass_y_m = y_lo - path.stepover_m * std::ceil(margin_m / path.stepover_m);
  }
  if (path.first_pass_y_m > y_lo + 1e-12)
    throw InputError("surface.first_pass", line_or(s.first_pass_line, s.line),
                     fmt::format("the first pass at y = {:.4g} mm leaves the patch's edge y = "
                                 "{:.4g} mm uncut: use first_pass: {:.4g} mm or less",
                                 path.first_pass_y_m * 1e3, y_lo * 1e3, y_lo * 1e3));
  const int needed_passes =
      static_cast<int>(std::ceil((y_hi - path.first_pass_y_m) / path.stepover_m - 1e-9)) + 1;
  const int default_passes =
      static_cast<int>(
          std::ceil((y_hi + margin_m - path.first_pass_y_m) / path.stepover_m - 1e-9)) +
      1;
  path.passes = s.passes > 0 ? s.passes : default_passes;
  if (path.passes < needed_passes)
    throw InputError(
        "surface.passes", line_or(s.passes_line, s.line),
        fmt::format("{} passes from y = {:.4g} mm every {:.4g} mm end at y = {:.4g} mm and do "
                    "not cover the patch (up to y = {:.4g} mm): use passes: {} or more",
                    path.passes, path.first_pass_y_m * 1e3, path.stepover_m * 1e3,
                    (path.first_pass_y_m + (path.passes - 1) * path.stepover_m) * 1e3, y_hi * 1e3,
                    needed_passes));
  // Along x each pass runs through the patch and beyond it by the band, a
  // revolution's feed and the runout.
  const double x_margin = margin_m + cutter.teeth() * path.feed_per_tooth_m;
  path.x_start_m = grid.x0_m - x_margin;
  if (s.entry_m) {
    // The tool starts with its leading edge at the part's border, `entry`
    // before the patch (or earlier, to finish the patch's first cells).
    path.x_start_m = std::min(path.x_start_m, grid.x0_m - *s.entry_m - cutter.radius_m());
    layout.border_m = grid.x0_m - *s.entry_m - path.x_start_m;
  }
  path.x_end_m = grid.x0_m + grid.length_x_m + x_margin;
  const double feed_speed = path.feed_per_tooth_m * cutter.teeth() * path.spindle_rad_s / kTwoPi;
  layout.pass_time_s = (path.x_end_m - path.x_start_m) / feed_speed;
  layout.path_time_s = path.passes * layout.pass_time_s;
  return layout;
}

}  // namespace

SurfaceRun run_surface_job(const job::Job& job, int threads) {
  require(job, {job::Section::tool, job::Section::process});
  if (!job.surface)
    throw InputError("surface", 0,
                     "required: the surface: section (area, grid, and optionally stepover, "
                     "passes, lead, tilt, redundancy, vibration)");
  const job::SurfaceSettings& s = *job.surface;
  const auto start = std::chrono::steady_clock::now();
  SurfaceRun out;
  const tool::Tool cutter(*job.tool);
  if (cutter.type() == tool::ToolType::bull)
    throw InputError("tool.type", 0,
                     "bull: the surface topography (paper 001) models flat and ball end mills; "
                     "a bull-nose cutter's Z-map is not implemented");
  const cutting::MillingProcess& process = *job.process;
  const double ap = process.axial_depth_m;

  surface::ToolOrientation orientation;
  orientation.lead_rad = s.lead_rad;
  orientation.tilt_rad = s.tilt_rad;
  orientation.redundancy_rad = s.redundancy_rad;
  check_shank(job, s, cutter, orientation);

  surface::ZMapGrid grid;
  grid.x0_m = s.origin_x_m;
  grid.y0_m = s.origin_y_m;
  grid.length_x_m = s.area_x_m;
  grid.length_y_m = s.area_y_m;
  grid.cells_x = s.cells_x;
  grid.cells_y = s.cells_y;

  surface::RasterPath path;
  path.spindle_rad_s = process.spindle_rad_s;
  path.feed_per_tooth_m = process.feed_per_tooth_m;
  path.stepover_m = s.stepover_m;
  path.pattern = s.zigzag ? surface::RasterPattern::zigzag : surface::RasterPattern::one_way;

  // 001 Eq 29: max(dx, dy) ≤ min(fz, fp) / 5.
  const surface::ResolutionRules rules =
      surface::resolution_rules(cutter, ap, orientation, path, grid, 0.0);
  check_resolution(s, grid, rules);

  const PassLayout layout = lay_out_passes(s, cutter, grid, rules, path);
  const std::optional<double>& border_m = layout.border_m;
  const double pass_time_s = layout.pass_time_s;
  const double path_time_s = layout.path_time_s;

  std::optional<SurfaceVibration> vibration;
  if (s.vibration) {
    vibration = simulate_vibration(
        job, s, cutter, (border_m || s.start_at_rest) ? pass_time_s : path_time_s, border_m);
    if (vibration->vibration.amplitude_m() > 0.05e-3)
      throw InputError("surface.vibration", line_or(s.vibration_line, s.line),
                       fmt::format("the tool vibrates by {:.4g} um around its mean (chatter or "
                                   "an unstable cut?): the Z-map expects a stable cut; check "
                                   "with robomill stability or simulate",
                                   vibration->vibration.amplitude_m() * 1e6));
  }
  if (vibration) {
    // The Z-map turns the spindle as the simulation did: from the simulated
    // start (tooth 1 at +y) at the start of the warm-up, or of every pass.
    path.restart_each_pass = vibration->vibration.per_pass;
    path.start_angle_rad = std::fmod(path.spindle_rad_s * vibration->warmup_s, kTwoPi);
  }
  const surface::Vibration none;
  const surface::Vibration& u = vibration ? vibration->vibration : none;

  // 001 Eq 30 with the band the run evaluates.
  const double budget = surface::automatic_height_budget(cutter, orientation, path, u);
  const surface::ResolutionRules run_rules =
      surface::resolution_rules(cutter, ap, orientation, path, grid, budget);
  if (s.steps_per_revolution > 0 && s.steps_per_revolution < run_rules.min_steps_per_revolution)
    throw InputError(
        "surface.steps_per_revolution", line_or(s.steps_line, s.line),
        fmt::format("{} steps per revolution move the outermost evaluated edge point ({:.4g} mm "
                    "from the axis) by more than a cell in one step (001 Eq 30): use "
                    "steps_per_revolution: {} or more",
                    s.steps_per_revolution, run_rules.max_edge_radius_m * 1e3,
                    run_rules.min_steps_per_revolution));

  surface::ZMapOptions zopt;
  zopt.steps_per_revolution = s.steps_per_revolution;
  zopt.edge_spacing_m = s.edge_spacing_m;
  zopt.threads = threads;
  const auto zmap_start = std::chrono::steady_clock::now();
  out.zmap = surface::cut_zmap(cutter, ap, orientation, path, grid, u, zopt);
  out.zmap_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - zmap_start).count();
  for (double z : out.zmap.map.z_m)
    if (!(z < ap))
      throw InputError("surface.area", line_or(s.area_line, s.line),
                       "part of the patch is never reached by the tool (it stays at the stock "
                       "top); move the patch inside the path or add passes");
  out.roughness = surface::roughness(out.zmap.map);
  out.path = path;
  out.rules = rules;
  out.orientation = orientation;
  out.path_time_s = path_time_s;
  out.vibration = std::move(vibration);
  out.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace robomill::analysis
