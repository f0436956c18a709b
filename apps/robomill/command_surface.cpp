// robomill surface JOB: the machined surface of a ball-end (or flat-end)
// raster by a Z-map (001 §2.1-2.4), with runout, lead/tilt/redundancy and,
// with surface.vibration, the tool vibration of the time-domain simulation
// at the job's (posture-interpolated) dynamics (001 §2.2-2.3) → surface.csv,
// profiles.csv, surface.bmp, summary.json (docs/surface.md).

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "commands.hpp"
#include "robomill/core/error.hpp"
#include "robomill/cutting/milling_forces.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/output_bundle.hpp"
#include "robomill/io/structure.hpp"
#include "robomill/io/summary.hpp"
#include "robomill/simulation/simulator.hpp"
#include "robomill/simulation/structure.hpp"
#include "robomill/surface/roughness.hpp"
#include "robomill/surface/topography.hpp"

namespace robomill::app {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kDegree = std::numbers::pi / 180.0;

int line_or(int line, int fallback) {
  return line > 0 ? line : fallback;
}

/// 001 §2.1.4: the shank must stay above the stock (R (1 − sin θ) ≥ ap).
void check_shank(const io::Job& job, const io::SurfaceSettings& s, const tool::Tool& cutter,
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

simulation::LinearStructure vibration_structure(const io::Job& job, const io::SurfaceSettings& s) {
  if (job.modes.empty() && job.frf_files.empty() &&
      job.dynamics_source == io::Job::DynamicsSource::table)
    throw InputError("surface.vibration", line_or(s.vibration_line, s.line),
                     "needs the structure: add a dynamics: section (modes, or postures with "
                     "dynamics.at for 001's posture-dependent dynamics)");
  if (!job.cutting)
    throw InputError("surface.vibration", line_or(s.vibration_line, s.line),
                     "needs the cutting: section (the forces that drive the vibration)");
  return simulation::modal_structure(io::structure_modes(job));
}

struct VibrationRun {
  surface::Vibration vibration;
  double warmup_s = 0.0, duration_s = 0.0;
  int steps_per_tooth = 0;
  std::vector<double> natural_frequencies_hz;
  Eigen::Vector3d mean_m = Eigen::Vector3d::Zero(), peak_to_peak_m = Eigen::Vector3d::Zero();
  std::string structure;
};

/// 001 §2.2: the tool-tip vibration over the raster, from the time-domain
/// simulation of the cut (simulation/simulator.hpp) on the job's structure.
/// The raster's crescent-shaped engagement is modelled as half immersion at
/// depth ap (the stock beside the pass; docs/surface.md).
VibrationRun simulate_vibration(const io::Job& job, const io::SurfaceSettings& s,
                                const tool::Tool& cutter, double path_time_s, int threads) {
  (void)threads;
  VibrationRun run;
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
  run.steps_per_tooth = s.simulation_steps_per_tooth > 0 ? s.simulation_steps_per_tooth : needed;
  if (run.steps_per_tooth < needed)
    throw InputError("surface.steps_per_tooth", s.line,
                     fmt::format("{} steps per tooth period do not resolve the highest mode; "
                                 "use steps_per_tooth: {} or more",
                                 run.steps_per_tooth, needed));
  // Start in the steady cut: three decay times of the slowest mode (at most
  // 10 s) before the patch, unless surface.warmup says otherwise.
  run.warmup_s = s.warmup_s ? *s.warmup_s : std::min(10.0, 3.0 * slowest_decay_s);
  run.duration_s = run.warmup_s + path_time_s;
  const double steps = run.duration_s / tooth_period_s * run.steps_per_tooth;
  if (steps > 2e8)
    throw InputError("surface.vibration", line_or(s.vibration_line, s.line),
                     fmt::format("the simulation would take {:.3g} steps (limit 2e8); shorten the "
                                 "warmup, the patch or steps_per_tooth",
                                 steps));
  cutting::MillingProcess half = process;
  half.radial_depth_m = cutter.radius_m();
  simulation::SimulationOptions options;
  options.duration_s = run.duration_s;
  options.steps_per_tooth = run.steps_per_tooth;
  options.axial_elements = cutting::default_axial_elements(cutter, process.axial_depth_m);
  options.record_every = std::max(1, static_cast<int>(std::ceil(steps / 4e6)));
  simulation::SimulationResult result;
  try {
    result = simulation::simulate(cutter, *job.cutting, half, structure, simulation::Workpiece{},
                                  options);
  } catch (const std::invalid_argument& error) {
    throw InputError("surface.vibration", line_or(s.vibration_line, s.line), error.what());
  }
  run.vibration.step_s = result.record_interval_s;
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

/// A dependency-free picture: 24-bit BMP heat map of the heights (y up).
std::string heat_map_bmp(const surface::ZMap& map) {
  const int w = map.grid.nodes_x(), h = map.grid.nodes_y();
  const auto [lo_it, hi_it] = std::minmax_element(map.z_m.begin(), map.z_m.end());
  const double lo = *lo_it, span = std::max(*hi_it - lo, 1e-15);
  const int row_bytes = (3 * w + 3) / 4 * 4;
  const std::uint32_t image = static_cast<std::uint32_t>(row_bytes * h);
  std::string out(54 + image, '\0');
  auto put32 = [&](std::size_t at, std::uint32_t v) {
    for (int b = 0; b < 4; ++b)
      out[at + b] = static_cast<char>((v >> (8 * b)) & 0xff);
  };
  out[0] = 'B';
  out[1] = 'M';
  put32(2, 54 + image);
  put32(10, 54);
  put32(14, 40);
  put32(18, static_cast<std::uint32_t>(w));
  put32(22, static_cast<std::uint32_t>(h));  // bottom-up rows: row 0 is y0
  out[26] = 1;
  out[28] = 24;
  put32(34, image);
  // A viridis-like ramp: dark blue → teal → green → yellow.
  static constexpr double stops[5][3] = {
      {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const double f = std::clamp((map.at(i, j) - lo) / span, 0.0, 1.0) * 4.0;
      const int k = std::min(3, static_cast<int>(f));
      const double t = f - k;
      const std::size_t at = 54 + static_cast<std::size_t>(j) * row_bytes + 3 * i;
      for (int c = 0; c < 3; ++c)  // BMP stores blue, green, red
        out[at + 2 - c] =
            static_cast<char>(std::lround((1.0 - t) * stops[k][c] + t * stops[k + 1][c]));
    }
  return out;
}

nlohmann::json profile_json(const surface::ProfileRoughness& p) {
  return {{"Ra_um", p.ra_m * 1e6}, {"Rq_um", p.rq_m * 1e6}, {"Rz_um", p.rz_m * 1e6}};
}

}  // namespace

int run_surface(const JobCommandOptions& options) {
  const io::Job job = load(options);
  io::require(job, {io::Section::tool, io::Section::process});
  if (!job.surface)
    throw InputError("surface", 0,
                     "required: the surface: section (area, grid, and optionally stepover, "
                     "passes, lead, tilt, redundancy, vibration)");
  const io::SurfaceSettings& s = *job.surface;
  const auto start = std::chrono::steady_clock::now();
  const tool::Tool cutter(*job.tool);
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
  path.x_end_m = grid.x0_m + grid.length_x_m + x_margin;
  const double feed_speed = path.feed_per_tooth_m * cutter.teeth() * path.spindle_rad_s / kTwoPi;
  const double path_time_s = path.passes * (path.x_end_m - path.x_start_m) / feed_speed;

  std::optional<VibrationRun> vibration;
  if (s.vibration) {
    vibration = simulate_vibration(job, s, cutter, path_time_s, options.threads);
    if (vibration->vibration.amplitude_m() > 0.05e-3)
      throw InputError("surface.vibration", line_or(s.vibration_line, s.line),
                       fmt::format("the tool vibrates by {:.4g} um around its mean (chatter or "
                                   "an unstable cut?): the Z-map expects a stable cut; check "
                                   "with robomill stability or simulate",
                                   vibration->vibration.amplitude_m() * 1e6));
  }
  const surface::Vibration none;
  const surface::Vibration& u = vibration ? vibration->vibration : none;

  // 001 Eq 30 with the band the run evaluates.
  const double budget =
      surface::automatic_height_budget(cutter, orientation, path, u.amplitude_m());
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
  zopt.threads = options.threads;
  const auto zmap_start = std::chrono::steady_clock::now();
  const surface::ZMapResult result =
      surface::cut_zmap(cutter, ap, orientation, path, grid, u, zopt);
  const double zmap_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - zmap_start).count();
  for (double z : result.map.z_m)
    if (!(z < ap))
      throw InputError("surface.area", line_or(s.area_line, s.line),
                       "part of the patch is never reached by the tool (it stays at the stock "
                       "top); move the patch inside the path or add passes");
  const surface::SurfaceRoughness r = surface::roughness(result.map);
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // Files.
  const surface::ZMap& map = result.map;
  io::CsvTable table({"x_mm", "y_mm", "z_um"});
  for (int j = 0; j < grid.nodes_y(); ++j)
    for (int i = 0; i < grid.nodes_x(); ++i)
      table.add_row({(grid.x0_m + i * grid.dx()) * 1e3, (grid.y0_m + j * grid.dy()) * 1e3,
                     map.at(i, j) * 1e6});
  const int middle_j = grid.cells_y / 2, middle_i = grid.cells_x / 2;
  std::string profile_text = "profile,x_mm,y_mm,z_um\n";
  for (int i = 0; i < grid.nodes_x(); ++i)
    profile_text +=
        fmt::format("feed,{:.9g},{:.9g},{:.9g}\n", (grid.x0_m + i * grid.dx()) * 1e3,
                    (grid.y0_m + middle_j * grid.dy()) * 1e3, map.at(i, middle_j) * 1e6);
  for (int j = 0; j < grid.nodes_y(); ++j)
    profile_text +=
        fmt::format("stepover,{:.9g},{:.9g},{:.9g}\n", (grid.x0_m + middle_i * grid.dx()) * 1e3,
                    (grid.y0_m + j * grid.dy()) * 1e3, map.at(middle_i, j) * 1e6);

  const double radius = cutter.radius_m();
  const surface::ZMapStats& st = result.stats;
  nlohmann::json summary = {
      {"command", "surface"},
      {"job", job.source.string()},
      {"Ra_um", r.stepover.ra_m * 1e6},
      {"Rq_um", r.stepover.rq_m * 1e6},
      {"Sa_um", r.sa_m * 1e6},
      {"Sq_um", r.sq_m * 1e6},
      {"Sz_um", r.sz_m * 1e6},
      {"max_residual_um", r.max_residual_m * 1e6},
      {"profiles", {{"feed", profile_json(r.feed)}, {"stepover", profile_json(r.stepover)}}},
      {"feed_mark_um", r.feed_mark_m * 1e6},
      {"analytic",
       {{"scallop_um", cutter.type() == tool::ToolType::ball
                           ? nlohmann::json(surface::scallop_height(radius, path.stepover_m) * 1e6)
                           : nlohmann::json(nullptr)},
        {"feed_mark_um",
         cutter.type() == tool::ToolType::ball
             ? nlohmann::json(surface::scallop_height(radius, path.feed_per_tooth_m) * 1e6)
             : nlohmann::json(nullptr)}}},
      {"grid",
       {{"nodes", {grid.nodes_x(), grid.nodes_y()}},
        {"dx_um", grid.dx() * 1e6},
        {"dy_um", grid.dy() * 1e6},
        {"eq29_max_cell_um", rules.max_cell_m * 1e6},
        {"eq29_satisfied", std::max(grid.dx(), grid.dy()) <= rules.max_cell_m * (1.0 + 1e-9)}}},
      {"path",
       {{"passes", path.passes},
        {"first_pass_mm", path.first_pass_y_m * 1e3},
        {"stepover_mm", path.stepover_m * 1e3},
        {"x_from_mm", path.x_start_m * 1e3},
        {"x_to_mm", path.x_end_m * 1e3},
        {"feed_per_tooth_mm", path.feed_per_tooth_m * 1e3},
        {"pattern", s.zigzag ? "zigzag" : "one_way"},
        {"duration_s", path_time_s}}},
      {"orientation_deg",
       {{"lead", s.lead_rad / kDegree},
        {"tilt", s.tilt_rad / kDegree},
        {"redundancy", s.redundancy_rad / kDegree}}},
      {"zmap",
       {{"steps_per_revolution", st.steps_per_revolution},
        {"time_step_s", st.time_step_s},
        {"edge_points_per_tooth", st.edge_points},
        {"edge_spacing_um", st.edge_spacing_m * 1e6},
        {"eq30_step_travel_um", st.step_travel_m * 1e6},
        {"height_budget_um", st.height_budget_m * 1e6},
        {"point_evaluations", st.point_evaluations},
        {"node_tests", st.node_tests},
        {"node_updates", st.node_updates},
        {"elapsed_s", zmap_s}}},
      {"elapsed_s", elapsed_s}};
  if (vibration) {
    summary["vibration"] = {{"structure", vibration->structure},
                            {"dynamics", io::dynamics_source_name(job.dynamics_source)},
                            {"natural_frequencies_hz", vibration->natural_frequencies_hz},
                            {"steps_per_tooth", vibration->steps_per_tooth},
                            {"warmup_s", vibration->warmup_s},
                            {"simulated_s", vibration->duration_s},
                            {"mean_um", io::xyz(vibration->mean_m * 1e6)},
                            {"peak_to_peak_um", io::xyz(vibration->peak_to_peak_m * 1e6)}};
  } else {
    summary["vibration"] = nullptr;
  }

  const std::filesystem::path out = output_dir(options, job, "surface");
  io::OutputBundle bundle(out);
  if (job.output.csv) {
    bundle.add("surface.csv", table.to_string());
    bundle.add("profiles.csv", profile_text);
  }
  bundle.add("surface.bmp", heat_map_bmp(map));
  if (job.output.json)
    bundle.add("summary.json", io::summary_text(summary));
  bundle.commit();

  if (!options.quiet) {
    std::cout << fmt::format(
        "surface: {} x {} nodes over {:.4g} x {:.4g} mm, {} passes, {}; Z-map in {:.2f} s\n"
        "  Ra {:.4f} um, Rq {:.4f} um (step-over lines); feed lines Ra {:.4f} um\n"
        "  Sa {:.4f} um, Sq {:.4f} um, Sz {:.4f} um, max residual {:.4f} um\n",
        grid.nodes_x(), grid.nodes_y(), grid.length_x_m * 1e3, grid.length_y_m * 1e3, path.passes,
        vibration ? "with vibration" : "without vibration", zmap_s, r.stepover.ra_m * 1e6,
        r.stepover.rq_m * 1e6, r.feed.ra_m * 1e6, r.sa_m * 1e6, r.sq_m * 1e6, r.sz_m * 1e6,
        r.max_residual_m * 1e6);
    std::cout << "  wrote " << out.string() << '\n';
  }
  return 0;
}

}  // namespace robomill::app
