// robomill deflection JOB: 000's force-induced deformation (§2 Eq 1-4) and
// the actual contact boundary (§4 Eq 20-31) over a sweep of axial depths —
// per node, the deformation, the actual radial depth and entry angle when the
// node cuts the wall: 000 Figure 11.

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "commands.hpp"
#include "robomill/core/error.hpp"
#include "robomill/core/parallel.hpp"
#include "robomill/deflection/deformed_engagement.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/deformation.hpp"
#include "robomill/io/summary.hpp"

namespace robomill::app {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

/// The sweep: the job's depths, or ap_lim/8 … 1.5 ap_lim (Eq 22) so that both
/// contact cases show; straight flutes (no ap_lim) sweep up to twice the
/// job's ap.
std::vector<double> sweep_depths(const io::Job& job, const deflection::DeflectionSetup& setup) {
  const io::DeflectionSettings& s = *job.deflection;
  double from = s.depth_from_m, to = s.depth_to_m;
  const int count = s.depth_count;
  if (!(to > 0.0)) {
    const double limit =
        deflection::critical_depth_m(setup.tool_radius_m, setup.radial_depth_m, setup.helix_rad);
    to = std::isfinite(limit) ? 1.5 * limit : 2.0 * job.process->axial_depth_m;
    to = std::min(to, setup.overhang_m);
    from = to / count;
  }
  std::vector<double> depths(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i)
    depths[static_cast<std::size_t>(i)] = count == 1 ? from : from + (to - from) * i / (count - 1);
  return depths;
}

}  // namespace

CommandResult compute_deflection(io::Job job, int threads) {
  io::require(job, {io::Section::tool, io::Section::cutting, io::Section::process});
  if (!job.deflection) {
    // No section: the defaults (documented in docs/job-reference.md).
    job.deflection = io::DeflectionSettings{};
    if (!job.robot || job.robot->posture_rad.empty())
      job.deflection->robot = false;
  }
  const deflection::DeflectionSetup setup = io::deflection_setup(job);
  const std::vector<double> depths = sweep_depths(job, setup);
  const auto start = std::chrono::steady_clock::now();
  std::vector<deflection::ContactBoundary> boundaries(depths.size());
  core::parallel_for(depths.size(), threads, [&](std::size_t i) {
    boundaries[i] = deflection::solve_contact_boundary(
        deflection::contact_problem(setup, depths[i]), setup.options);
  });
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  io::CsvTable table({"ap_mm", "node", "z_mm", "dx_um", "dy_um", "ae_actual_mm",
                      "entry_nominal_deg", "entry_actual_deg", "contact_nodes", "iterations",
                      "case"});
  nlohmann::json node1 = nlohmann::json::array();
  double max_deflection = 0.0, max_entry_increase = 0.0;
  for (std::size_t i = 0; i < depths.size(); ++i) {
    const deflection::ContactBoundary& b = boundaries[i];
    for (std::size_t k = 0; k < b.positions.size(); ++k) {
      const deflection::ContactPosition& position = b.positions[k];
      const deflection::NodeState& node = position.nodes[k];  // node k generating
      table.add_row({depths[i] * 1e3, static_cast<double>(k + 1), node.height_m * 1e3,
                     node.deflection_m.x() * 1e6, node.deflection_m.y() * 1e6,
                     node.radial_depth_m * 1e3, b.nominal_entry_rad * kDegPerRad,
                     node.entry_rad * kDegPerRad, static_cast<double>(position.contact_nodes),
                     static_cast<double>(position.iterations),
                     static_cast<double>(b.contact_case)});
      max_deflection = std::max(max_deflection, node.deflection_m.norm());
      max_entry_increase = std::max(max_entry_increase, node.entry_rad - b.nominal_entry_rad);
    }
    const deflection::NodeState& first = b.generating(1);
    node1.push_back({{"ap_mm", depths[i] * 1e3},
                     {"case", b.contact_case},
                     {"contact_nodes", b.positions[0].contact_nodes},
                     {"dx_um", first.deflection_m.x() * 1e6},
                     {"dy_um", first.deflection_m.y() * 1e6},
                     {"ae_actual_mm", first.radial_depth_m * 1e3},
                     {"entry_actual_deg", first.entry_rad * kDegPerRad}});
  }
  const double critical =
      deflection::critical_depth_m(setup.tool_radius_m, setup.radial_depth_m, setup.helix_rad);
  nlohmann::json summary = {
      {"command", "deflection"},
      {"job", job.source.string()},
      {"elapsed_s", elapsed_s},
      {"elements", setup.elements},
      {"robot_included", static_cast<bool>(setup.robot)},
      {"chip_correction", setup.options.chip_correction},
      {"flexural_rigidity_N_m2", setup.flexural_rigidity_n_m2},
      {"nominal_entry_deg", boundaries.front().nominal_entry_rad * kDegPerRad},
      {"max_deflection_um", max_deflection * 1e6},
      {"max_entry_increase_deg", max_entry_increase * kDegPerRad},
      {"node1", node1}};
  if (std::isfinite(critical))
    summary["critical_depth_mm"] = critical * 1e3;  // Eq 22
  else
    summary["critical_depth_note"] = "straight flutes: every depth is Case 1 (Eq 22 is infinite)";
  if (!job.name.empty())
    summary["name"] = job.name;

  CommandResult result;
  result.tables.emplace_back("deflection", std::move(table));
  result.summary = std::move(summary);
  result.message = fmt::format(
      "deflection: {} depths in {:.3f} s; ap_lim {} (Eq 22); max deformation {:.1f} um, entry "
      "angle up to +{:.3f}° ({})\n",
      depths.size(), elapsed_s,
      std::isfinite(critical) ? fmt::format("{:.3f} mm", critical * 1e3) : "infinite",
      max_deflection * 1e6, max_entry_increase * kDegPerRad,
      setup.robot ? "tool and robot" : "tool only");
  return result;
}

int run_deflection(const JobCommandOptions& options) {
  return run_job_command(options, "deflection", [&](const io::Job& job) {
    return compute_deflection(job, options.threads);
  });
}

}  // namespace robomill::app
