// robomill surface JOB: the machined surface of a ball-end (or flat-end)
// raster by a Z-map (001 §2.1-2.4), with runout, lead/tilt/redundancy and,
// with surface.vibration, the tool vibration of the time-domain simulation
// at the job's (posture-interpolated) dynamics (001 §2.2-2.3) → surface.csv,
// profiles.csv, surface.bmp, summary.json (docs/surface.md). The computation
// is analysis::run_surface_job; this file writes its results.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "robomill/analysis/surface_run.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/summary.hpp"

namespace robomill::commands {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

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

CommandResult compute_surface(const job::Job& job, int threads) {
  const analysis::SurfaceRun run = analysis::run_surface_job(job, threads);
  const job::SurfaceSettings& s = *job.surface;
  const tool::Tool cutter(*job.tool);
  const surface::ZMapGrid& grid = run.zmap.map.grid;
  const surface::RasterPath& path = run.path;
  const surface::SurfaceRoughness& r = run.roughness;
  const surface::ResolutionRules& rules = run.rules;
  const auto& vibration = run.vibration;
  const double path_time_s = run.path_time_s, zmap_s = run.zmap_s, elapsed_s = run.elapsed_s;
  const surface::ZMapResult& result = run.zmap;

  // Files.
  const surface::ZMap& map = result.map;
  io::CsvTable table({"x_mm", "y_mm", "z_um"});
  for (int j = 0; j < grid.nodes_y(); ++j)
    for (int i = 0; i < grid.nodes_x(); ++i)
      table.add_row({(grid.x0_m + i * grid.dx()) * 1e3, (grid.y0_m + j * grid.dy()) * 1e3,
                     map.at(i, j) * 1e6});
  const int middle_j = grid.cells_y / 2, middle_i = grid.cells_x / 2;
  io::CsvTable profiles({"profile", "x_mm", "y_mm", "z_um"});
  for (int i = 0; i < grid.nodes_x(); ++i)
    profiles.add_cells({std::string("feed"), (grid.x0_m + i * grid.dx()) * 1e3,
                        (grid.y0_m + middle_j * grid.dy()) * 1e3, map.at(i, middle_j) * 1e6});
  for (int j = 0; j < grid.nodes_y(); ++j)
    profiles.add_cells({std::string("stepover"), (grid.x0_m + middle_i * grid.dx()) * 1e3,
                        (grid.y0_m + j * grid.dy()) * 1e3, map.at(middle_i, j) * 1e6});
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
      {"feed_texture_interval_mm", r.feed_texture_interval_m * 1e3},
      {"feed_texture_interval_in_fz", r.feed_texture_interval_m / path.feed_per_tooth_m},
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
    summary["vibration"] = {
        {"structure", vibration->structure},
        {"dynamics", job::dynamics_source_name(job.dynamics_source)},
        {"natural_frequencies_hz", vibration->natural_frequencies_hz},
        {"steps_per_tooth", vibration->steps_per_tooth},
        {"warmup_s", vibration->warmup_s},
        {"entry_mm", s.entry_m ? nlohmann::json(*s.entry_m * 1e3) : nlohmann::json(nullptr)},
        {"restarts_each_pass", vibration->vibration.per_pass},
        {"start", s.entry_m         ? "entry"
                  : s.start_at_rest ? "rest"
                                    : "steady"},
        {"simulated_s", vibration->duration_s},
        {"chatter", vibration->verdict.chatter},
        {"chatter_freq_hz", vibration->verdict.chatter
                                ? nlohmann::json(vibration->verdict.frequency_hz)
                                : nlohmann::json(nullptr)},
        {"nonharmonic_fraction", vibration->verdict.nonharmonic_fraction},
        {"nonharmonic_rms_um", vibration->verdict.nonharmonic_rms_m * 1e6},
        {"chatter_floor_um", vibration->verdict.floor_m * 1e6},
        {"chatter_persistence", vibration->verdict.persistence},
        {"mean_um", io::xyz(vibration->mean_m * 1e6)},
        {"peak_to_peak_um", io::xyz(vibration->peak_to_peak_m * 1e6)}};
  } else {
    summary["vibration"] = nullptr;
  }

  CommandResult output;
  output.tables.emplace_back("surface", std::move(table));
  output.tables.emplace_back("profiles", std::move(profiles));
  if (vibration && !vibration->vibration.empty()) {
    // The vibration the Z-map added (spindle frame; from the first pass's
    // start, or from every pass's start when it restarts per pass), at most
    // 20 000 rows: what printed onto the surface, for the report's plot.
    const surface::Vibration& u = vibration->vibration;
    const std::size_t every = (u.displacement_m.size() + 19'999) / 20'000;
    io::CsvTable series({"t_s", "x_um", "y_um", "z_um"});
    for (std::size_t i = 0; i < u.displacement_m.size(); i += every) {
      const Eigen::Vector3d& d = u.displacement_m[i];
      series.add_row({static_cast<double>(i) * u.step_s, d.x() * 1e6, d.y() * 1e6, d.z() * 1e6});
    }
    output.tables.emplace_back("vibration", std::move(series));
  }
  output.texts.emplace_back("surface.bmp", heat_map_bmp(map));
  output.summary = std::move(summary);
  std::string character;
  if (vibration && vibration->verdict.chatter)
    character = fmt::format(
        "  the vibration is not locked to the spindle: chatter at {:.1f} Hz ({:.3f} x the spindle "
        "frequency; 0.5: period doubling)\n",
        vibration->verdict.frequency_hz,
        vibration->verdict.frequency_hz * 2.0 * std::numbers::pi / job.process->spindle_rad_s);
  output.message = fmt::format(
      "surface: {} x {} nodes over {:.4g} x {:.4g} mm, {} passes, {}; Z-map in {:.2f} s\n"
      "  Ra {:.4f} um, Rq {:.4f} um (step-over lines); feed lines Ra {:.4f} um\n"
      "  Sa {:.4f} um, Sq {:.4f} um, Sz {:.4f} um, max residual {:.4f} um\n",
      grid.nodes_x(), grid.nodes_y(), grid.length_x_m * 1e3, grid.length_y_m * 1e3, path.passes,
      vibration ? "with vibration" : "without vibration", zmap_s, r.stepover.ra_m * 1e6,
      r.stepover.rq_m * 1e6, r.feed.ra_m * 1e6, r.sa_m * 1e6, r.sq_m * 1e6, r.sz_m * 1e6,
      r.max_residual_m * 1e6);
  output.message += character;
  return output;
}

}  // namespace robomill::commands
