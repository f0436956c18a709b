// The atlas's job-level pieces (robomill/commands/commands.hpp): its
// computation from a job, the job's identity in a store, and the export of a
// store's finished items. The run over a store (threads, MPI ranks, batches
// committed as they finish) is the command line's (apps/robomill).

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "robomill/commands/commands.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/csv.hpp"

namespace robomill::commands {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;
constexpr double kRpmPerRadS = 60.0 / (2.0 * std::numbers::pi);

}  // namespace

atlas::AtlasContext atlas_context(const io::Job& job, const robot::RobotModel& model) {
  std::optional<tool::Tool> tool;
  if (job.tool)
    tool.emplace(*job.tool);
  return atlas::AtlasContext(
      *job.atlas, model,
      Eigen::Map<const Eigen::VectorXd>(job.robot->posture_rad.data(), model.dof()), tool,
      job.cutting, job.process);
}

atlas::StoreIdentity atlas_store_identity(const std::filesystem::path& job_file,
                                          const std::vector<std::string>& overrides, int dof) {
  std::ifstream in(job_file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  std::string canonical = text.str();
  for (const std::string& o : overrides)
    canonical += "\n# --set " + o;
  atlas::StoreIdentity identity;
  identity.job_text = canonical;
  identity.job_hash = atlas::fnv1a_hex(canonical);
  identity.dof = dof;
  return identity;
}

CommandResult compute_atlas_export(const io::Job& job, const atlas::StoreIdentity& identity) {
  const atlas::AtlasSpec& spec = *job.atlas;
  atlas::AtlasStore store(spec.store, identity);
  const std::int64_t total = store.item_total();
  const std::vector<atlas::StoredItem> rows = store.finished();
  const int dof = store.dof();
  std::vector<std::string> columns = {"item",
                                      "x_mm",
                                      "y_mm",
                                      "z_mm",
                                      "redundancy_deg",
                                      "reachable",
                                      "lowest_fn_hz",
                                      "compliance_feed_um_per_N",
                                      "compliance_normal_um_per_N",
                                      "compliance_axial_um_per_N",
                                      "condition_number",
                                      "depth_min_mm",
                                      "speed_at_min_rpm",
                                      "depth_max_mm",
                                      "speed_at_max_rpm"};
  for (int j = 0; j < dof; ++j)
    columns.push_back(fmt::format("q{}_deg", j + 1));
  io::CsvTable table(columns);
  int reachable = 0;
  double fn_low = INFINITY, fn_high = 0.0, dmin_low = INFINITY, dmin_high = 0.0;
  for (const atlas::StoredItem& s : rows) {
    const atlas::AtlasResult& r = s.result;
    std::vector<double> row = {static_cast<double>(s.item.id),
                               s.item.position_m.x() * 1e3,
                               s.item.position_m.y() * 1e3,
                               s.item.position_m.z() * 1e3,
                               s.item.redundancy_rad * kDegPerRad,
                               r.reachable ? 1.0 : 0.0,
                               r.lowest_frequency_hz,
                               r.compliance_feed_m_per_n * 1e6,
                               r.compliance_normal_m_per_n * 1e6,
                               r.compliance_axial_m_per_n * 1e6,
                               r.condition_number,
                               r.depth_min_m * 1e3,
                               r.speed_at_min_rad_s * kRpmPerRadS,
                               r.depth_max_m * 1e3,
                               r.speed_at_max_rad_s * kRpmPerRadS};
    for (int j = 0; j < dof; ++j)
      row.push_back(r.reachable && r.q.size() == dof ? r.q[j] * kDegPerRad : 0.0);
    table.add_row(row);
    if (r.reachable) {
      ++reachable;
      if (spec.frequency) {
        fn_low = std::min(fn_low, r.lowest_frequency_hz);
        fn_high = std::max(fn_high, r.lowest_frequency_hz);
      }
      if (spec.stability) {
        dmin_low = std::min(dmin_low, r.depth_min_m);
        dmin_high = std::max(dmin_high, r.depth_min_m);
      }
    }
  }
  nlohmann::json summary = {{"command", "atlas"},
                            {"job", job.source.string()},
                            {"store", spec.store.string()},
                            {"job_hash", identity.job_hash},
                            {"code_version", identity.code_version},
                            {"items", total},
                            {"finished", rows.size()},
                            {"complete", static_cast<std::int64_t>(rows.size()) == total},
                            {"reachable", reachable}};
  if (reachable > 0 && spec.frequency)
    summary["lowest_fn_hz"] = {{"min", fn_low}, {"max", fn_high}};
  if (reachable > 0 && spec.stability)
    summary["depth_min_mm"] = {{"min", dmin_low * 1e3}, {"max", dmin_high * 1e3}};
  CommandResult result;
  result.tables.emplace_back("atlas", std::move(table));
  result.summary = std::move(summary);
  result.message =
      fmt::format("atlas: {} of {} items finished ({} reachable)", rows.size(), total, reachable);
  return result;
}

}  // namespace robomill::commands
