// robomill deflection JOB: 000's force-induced deformation (§2 Eq 1-4) and
// the actual contact boundary (§4 Eq 20-31) over a sweep of axial depths —
// per node, the deformation, the actual radial depth and entry angle when the
// node cuts the wall: 000 Figure 11. The sweep is analysis::deflection_sweep's;
// this file writes it as deflection.csv and summary.json.

#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>

#include "robomill/analysis/deflection_sweep.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/summary.hpp"

namespace robomill::commands {

CommandResult compute_deflection(job::Job job, int threads) {
  const analysis::DeflectionSweep sweep = analysis::deflection_sweep(job, threads);
  const deflection::DeflectionSetup& setup = sweep.setup;
  const std::vector<double>& depths = sweep.depths_m;

  io::CsvTable table({"ap_mm", "node", "z_mm", "dx_um", "dy_um", "ae_actual_mm",
                      "entry_nominal_deg", "entry_actual_deg", "contact_nodes", "iterations",
                      "case"});
  nlohmann::json node1 = nlohmann::json::array();
  for (std::size_t i = 0; i < depths.size(); ++i) {
    const deflection::ContactBoundary& b = sweep.boundaries[i];
    for (std::size_t k = 0; k < b.positions.size(); ++k) {
      const deflection::ContactPosition& position = b.positions[k];
      const deflection::NodeState& node = position.nodes[k];  // node k generating
      table.add_row({depths[i] * 1e3, static_cast<double>(k + 1), node.height_m * 1e3,
                     node.deflection_m.x() * 1e6, node.deflection_m.y() * 1e6,
                     node.radial_depth_m * 1e3, b.nominal_entry_rad * kDegPerRad,
                     node.entry_rad * kDegPerRad, static_cast<double>(position.contact_nodes),
                     static_cast<double>(position.iterations),
                     static_cast<double>(b.contact_case)});
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
  const double critical = sweep.critical_depth_m;
  nlohmann::json summary = {
      {"command", "deflection"},
      {"job", job.source.string()},
      {"elapsed_s", sweep.elapsed_s},
      {"elements", setup.elements},
      {"robot_included", static_cast<bool>(setup.robot)},
      {"chip_correction", setup.options.chip_correction},
      {"flexural_rigidity_N_m2", setup.flexural_rigidity_n_m2},
      {"nominal_entry_deg", sweep.boundaries.front().nominal_entry_rad * kDegPerRad},
      {"max_deflection_um", sweep.max_deflection_m * 1e6},
      {"max_entry_increase_deg", sweep.max_entry_increase_rad * kDegPerRad},
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
      depths.size(), sweep.elapsed_s,
      std::isfinite(critical) ? fmt::format("{:.3f} mm", critical * 1e3) : "infinite",
      sweep.max_deflection_m * 1e6, sweep.max_entry_increase_rad * kDegPerRad,
      setup.robot ? "tool and robot" : "tool only");
  return result;
}

}  // namespace robomill::commands
