// robomill toolpath JOB: the program the cell runs, over the stock — the
// engagement, forces, torque and power at every sample (docs/toolpath.md).

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <numbers>
#include <set>

#include "robomill/commands/commands.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/output_bundle.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/io/program_writer.hpp"
#include "robomill/io/robot_path.hpp"
#include "robomill/io/summary.hpp"
#include "robomill/robot/kinematics.hpp"
#include "robomill/toolpath/deflection_compensation.hpp"
#include "robomill/toolpath/feed_schedule.hpp"
#include "robomill/toolpath/program_analysis.hpp"
#include "robomill/toolpath/program_optimization.hpp"
#include "robomill/toolpath/robot_along_path.hpp"

namespace robomill::commands {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;
constexpr double kRpmPerRadS = 60.0 / (2.0 * std::numbers::pi);
constexpr std::size_t kPreviewRows = 20000;

const char* motion_name(toolpath::MotionKind kind) {
  switch (kind) {
    case toolpath::MotionKind::rapid:
      return "rapid";
    case toolpath::MotionKind::arc:
      return "arc";
    case toolpath::MotionKind::dwell:
      return "dwell";
    default:
      return "linear";
  }
}

std::vector<std::string> sample_columns() {
  return {"line",
          "t_s",
          "x_mm",
          "y_mm",
          "z_mm",
          "axis_i",
          "axis_j",
          "axis_k",
          "tool",
          "motion",
          "feed_mm_min",
          "spindle_rpm",
          "feed_per_tooth_mm",
          "ap_mm",
          "ae_mm",
          "engagement_deg",
          "entry_deg",
          "exit_deg",
          "arcs",
          "section_mm2",
          "chip_area_mm2",
          "fx_N",
          "fy_N",
          "fz_N",
          "force_mean_N",
          "force_peak_N",
          "torque_Nm",
          "torque_peak_Nm",
          "power_W",
          "analysed",
          "plunge"};
}

// The robot's columns (robot_along_path.hpp), after the program's.
io::CsvTable sample_table(int dof = 0) {
  std::vector<std::string> columns = sample_columns();
  if (dof > 0) {
    columns.emplace_back("psi_deg");
    for (int j = 1; j <= dof; ++j)
      columns.push_back(fmt::format("q{}_deg", j));
    for (const char* c :
         {"reachable", "joint_margin_deg", "singularity", "ap_limit_mm", "margin", "chatter",
          "at_risk", "chatter_freq_hz", "dev_x_um", "dev_y_um", "dev_z_um", "deflection_um",
          "form_error_um", "floor_error_um", "dynamics_recomputed", "contact", "offset_um"})
      columns.emplace_back(c);
  }
  return io::CsvTable(columns);
}

void add_sample(io::CsvTable& table, const toolpath::PathSample& s,
                const toolpath::RobotSample* robot = nullptr) {
  std::vector<io::CsvTable::Cell> cells = {static_cast<double>(s.line),
                                           s.t_s,
                                           s.tip_m.x() * 1e3,
                                           s.tip_m.y() * 1e3,
                                           s.tip_m.z() * 1e3,
                                           s.axis.x(),
                                           s.axis.y(),
                                           s.axis.z(),
                                           static_cast<double>(s.tool),
                                           std::string(motion_name(s.kind)),
                                           s.feed_m_s * 6e4,
                                           s.spindle_rad_s * kRpmPerRadS,
                                           s.feed_per_tooth_m * 1e3,
                                           s.axial_depth_m * 1e3,
                                           s.radial_width_m * 1e3,
                                           s.engaged_rad * kDegPerRad,
                                           s.entry_rad * kDegPerRad,
                                           s.exit_rad * kDegPerRad,
                                           static_cast<double>(s.arcs),
                                           s.section_m2 * 1e6,
                                           s.chip_area_m2 * 1e6,
                                           s.force_mean_n.x(),
                                           s.force_mean_n.y(),
                                           s.force_mean_n.z(),
                                           s.force_mean_magnitude_n,
                                           s.force_peak_n,
                                           s.torque_mean_nm,
                                           s.torque_peak_nm,
                                           s.power_w,
                                           s.analysed ? 1.0 : 0.0,
                                           s.plunge ? 1.0 : 0.0};
  if (robot) {
    const toolpath::RobotSample& r = *robot;
    const std::string empty;
    cells.emplace_back(r.redundancy_rad * kDegPerRad);
    for (Eigen::Index j = 0; j < r.q_rad.size(); ++j)
      cells.emplace_back(r.q_rad[j] * kDegPerRad);
    cells.emplace_back(r.reachable ? 1.0 : 0.0);
    cells.emplace_back(r.joint_margin_rad * kDegPerRad);
    cells.emplace_back(r.singularity);
    const bool limit = r.stability;
    cells.emplace_back(limit ? io::CsvTable::Cell(r.depth_limit_m * 1e3) : empty);
    cells.emplace_back(limit ? io::CsvTable::Cell(r.margin) : empty);
    cells.emplace_back(limit ? io::CsvTable::Cell(r.chatter ? 1.0 : 0.0) : empty);
    cells.emplace_back(limit ? io::CsvTable::Cell(r.at_risk ? 1.0 : 0.0) : empty);
    cells.emplace_back(
        limit && r.chatter_frequency_hz > 0.0 ? io::CsvTable::Cell(r.chatter_frequency_hz) : empty);
    const bool bent = r.reachable && s.analysed && s.kind != toolpath::MotionKind::rapid;
    for (int a = 0; a < 3; ++a)
      cells.emplace_back(bent ? io::CsvTable::Cell(r.deflection_m[a] * 1e6) : empty);
    cells.emplace_back(bent ? io::CsvTable::Cell(r.deflection_m.norm() * 1e6) : empty);
    cells.emplace_back(bent && r.wall ? io::CsvTable::Cell(r.form_error_m * 1e6) : empty);
    cells.emplace_back(bent ? io::CsvTable::Cell(r.floor_error_m * 1e6) : empty);
    cells.emplace_back(limit ? io::CsvTable::Cell(r.exact ? 1.0 : 0.0) : empty);
    cells.emplace_back(bent ? io::CsvTable::Cell(r.contact ? 1.0 : 0.0) : empty);
    cells.emplace_back(r.has_offset ? io::CsvTable::Cell(r.steady_offset_m * 1e6) : empty);
  }
  table.add_cells(cells);
}

// summary.json's robot_along_path: the worst lines with their advice, the
// robot drawn at the worst posture.
nlohmann::json robot_summary(const io::RobotPathSetup& setup, const toolpath::RobotAlongPath& along,
                             const toolpath::RobotPathSummary& r) {
  nlohmann::json worst = nlohmann::json::array();
  for (const toolpath::WorstLine& w : r.worst_lines) {
    std::string advice;
    if (w.margin < 1.0) {
      advice = fmt::format("chatter: lower ap to {:.2f} mm", w.depth_limit_m * 1e3 * 0.9);
      if (w.better_depth_limit_m > w.axial_depth_m)
        advice += fmt::format(" or move the spindle to {:.0f} rpm (stable to {:.2f} mm)",
                              w.better_spindle_rad_s * kRpmPerRadS, w.better_depth_limit_m * 1e3);
    } else if (w.margin < setup.settings.risk_margin) {
      advice = fmt::format("at risk: {:.0f} % below the limit", (1.0 - 1.0 / w.margin) * 100.0);
      if (w.better_depth_limit_m > w.depth_limit_m * 1.05)
        advice += fmt::format("; {:.0f} rpm is stable to {:.2f} mm",
                              w.better_spindle_rad_s * kRpmPerRadS, w.better_depth_limit_m * 1e3);
    } else {
      advice = "stable";
    }
    worst.push_back({{"line", w.line},
                     {"t_s", w.t_s},
                     {"margin", w.margin},
                     {"ap_mm", w.axial_depth_m * 1e3},
                     {"ap_limit_mm", w.depth_limit_m * 1e3},
                     {"spindle_rpm", w.spindle_rad_s * kRpmPerRadS},
                     {"chatter_freq_hz", w.chatter_frequency_hz},
                     {"form_error_um", w.form_error_m * 1e6},
                     {"better_spindle_rpm", w.better_spindle_rad_s * kRpmPerRadS},
                     {"better_ap_limit_mm", w.better_depth_limit_m * 1e3},
                     {"advice", advice}});
  }
  const double fraction = r.stability_samples > 0 ? static_cast<double>(r.at_risk) /
                                                        static_cast<double>(r.stability_samples)
                                                  : 0.0;
  nlohmann::json out = {
      {"robot", along.model().name()},
      {"dof", along.model().dof()},
      {"structure", setup.structure_source},
      {"redundancy_deg", setup.settings.redundancy_rad * kDegPerRad},
      {"redundancy_source", r.oriented_samples > 0 ? "program" : "job"},
      {"oriented_samples", r.oriented_samples},
      {"redundancy_range_deg",
       {r.min_redundancy_rad * kDegPerRad, r.max_redundancy_rad * kDegPerRad}},
      {"samples", r.samples},
      {"analysed_samples", r.analysed},
      {"stability_samples", r.stability_samples},
      {"unreachable_samples", r.unreachable},
      {"unreachable_lines", r.unreachable_lines},
      {"joint_limit_samples", r.joint_limit},
      {"first_joint_limit_line", r.first_joint_limit_line},
      {"min_singularity", r.min_singularity},
      {"min_singularity_line", r.min_singularity_line},
      {"fraction_at_risk", fraction},
      {"risk_margin", setup.settings.risk_margin},
      {"chatter_samples", r.chatter},
      {"at_risk_samples", r.at_risk},
      {"min_margin", r.min_margin},
      {"min_margin_line", r.min_margin_line},
      {"max_form_error_um", r.max_form_error_m * 1e6},
      {"deflection_model", setup.settings.contact.enabled ? "contact" : "static"},
      {"contact_samples", r.contact_samples},
      {"max_form_error_line", r.max_form_error_line},
      {"max_floor_error_um", r.max_floor_error_m * 1e6},
      {"max_deflection_um", r.max_deflection_m * 1e6},
      {"dynamics_recomputations", r.exact_limits},
      {"shortcut_tolerance", setup.settings.tolerance},
      {"shortcut_checked_samples", r.checked},
      {"shortcut_max_error", r.shortcut_max_error},
      {"worst_lines", worst},
      {"notes", setup.notes},
  };
  if (setup.settings.offset.enabled) {
    // 004 Eq 6 over the program's samples: what `robomill optimize` reports
    // as dm for its own path (docs/toolpath.md, "004's offset").
    out["offset"] = {{"measure", std::string(planning::to_string(setup.settings.offset.measure))},
                     {"harmonics", setup.settings.offset.harmonics},
                     {"samples", r.offset_samples},
                     {"dm_um", r.mean_offset_m * 1e6},
                     {"max_um", r.max_offset_m * 1e6},
                     {"max_line", r.max_offset_line}};
  }
  if (!r.worst_lines.empty()) {
    const toolpath::WorstLine& w = r.worst_lines.front();
    nlohmann::json origins = nlohmann::json::array();
    for (const Eigen::Vector3d& p : along.joint_origins(w.q_rad))
      origins.push_back({p.x() * 1e3, p.y() * 1e3, p.z() * 1e3});
    std::vector<double> q_deg;
    for (Eigen::Index j = 0; j < w.q_rad.size(); ++j)
      q_deg.push_back(w.q_rad[j] * kDegPerRad);
    const Eigen::Isometry3d tool = robot::tool_pose(along.model(), w.q_rad);
    const Eigen::Vector3d axis = tool.linear().col(2);
    out["worst_posture"] = {{"line", w.line},
                            {"q_deg", q_deg},
                            {"joint_origins_mm", origins},
                            {"tool_tip_mm",
                             {tool.translation().x() * 1e3, tool.translation().y() * 1e3,
                              tool.translation().z() * 1e3}},
                            {"tool_axis", {axis.x(), axis.y(), axis.z()}}};
  }
  return out;
}

io::CsvTable move_table(const toolpath::ProgramAnalysis& analysis) {
  io::CsvTable table({"line", "move", "tool", "motion", "length_mm", "time_s", "feed_mm_min",
                      "spindle_rpm", "samples", "engaged_samples", "removed_mm3", "max_ap_mm",
                      "max_ae_mm", "max_engagement_deg", "max_force_N", "max_torque_Nm",
                      "max_power_W", "tool_described"});
  for (const toolpath::MoveTotals& m : analysis.moves) {
    table.add_cells({static_cast<double>(m.line), static_cast<double>(m.move),
                     static_cast<double>(m.tool), std::string(motion_name(m.kind)),
                     m.length_m * 1e3, m.time_s, m.feed_m_s * 6e4, m.spindle_rad_s * kRpmPerRadS,
                     static_cast<double>(m.samples), static_cast<double>(m.engaged_samples),
                     m.removed_m3 * 1e9, m.max_axial_depth_m * 1e3, m.max_radial_width_m * 1e3,
                     m.max_engaged_rad * kDegPerRad, m.max_force_n, m.max_torque_nm, m.max_power_w,
                     m.tool_described ? 1.0 : 0.0});
  }
  return table;
}

io::CsvTable stock_table(const toolpath::DexelStock& stock) {
  io::CsvTable table({"x_mm", "y_mm", "z_mm"});
  const std::vector<double> heights = stock.top_heights_m();
  const int nx = stock.counts()[0], ny = stock.counts()[1];
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      table.add_row({stock.cell_centre_m(0, i) * 1e3, stock.cell_centre_m(1, j) * 1e3,
                     heights[static_cast<std::size_t>(j) * nx + i] * 1e3});
  return table;
}

// The stock the job describes: a full box, or the height map an earlier run
// left (stock.csv: x_mm, y_mm, z_mm with x fastest).
toolpath::DexelStock make_stock(const io::Job& job) {
  const io::StockSettings& s = *job.stock;
  const toolpath::StockBox box{s.min_m, s.max_m};
  try {
    if (s.height_map.empty())
      return toolpath::DexelStock(box, s.resolution_m);
    const io::CsvTable map = io::read_csv(s.height_map);
    const int x = map.find("x_mm"), y = map.find("y_mm"), z = map.find("z_mm");
    if (x < 0 || y < 0 || z < 0 || map.rows() < 1)
      throw InputError("stock.height_map", s.line,
                       fmt::format("'{}' needs the columns x_mm, y_mm, z_mm (stock.csv of "
                                   "robomill toolpath)",
                                   s.height_map.string()));
    std::size_t nx = 1;
    while (nx < map.rows() && map.at(nx, y) == map.at(0, y))
      ++nx;
    if (map.rows() % nx != 0)
      throw InputError(
          "stock.height_map", s.line,
          fmt::format("'{}' is not a regular grid (x fastest, then y)", s.height_map.string()));
    std::vector<double> heights(map.rows());
    for (std::size_t r = 0; r < map.rows(); ++r)
      heights[r] = map.at(r, z) * 1e-3;
    return toolpath::DexelStock::from_height_map(box, s.resolution_m, static_cast<int>(nx),
                                                 static_cast<int>(map.rows() / nx), heights);
  } catch (const std::invalid_argument& error) {
    throw InputError("stock", s.line, error.what());
  }
}

// The cutters by tool number, and the program's own word on them (APT CUTTER)
// checked against the job's.
toolpath::Tooling make_tooling(const io::Job& job, const toolpath::Program& program) {
  toolpath::Tooling tooling;
  const io::ToolpathSettings& settings = *job.toolpath;
  if (settings.tools.empty())
    tooling.emplace(0, tool::Tool(*job.tool));
  for (const auto& [number, spec] : settings.tools)
    tooling.emplace(number, tool::Tool(spec));
  for (const toolpath::ToolCall& call : program.tool_calls) {
    auto it = tooling.find(call.tool);
    if (it == tooling.end())
      it = tooling.find(0);
    if (it == tooling.end())
      continue;
    const tool::Tool& cutter = it->second;
    const std::string where = settings.tools.empty() ? std::string("the job's tool")
                                                     : fmt::format("toolpath.tools.T{}", call.tool);
    if (call.diameter_m && std::abs(*call.diameter_m - cutter.diameter_m()) > 1e-6)
      throw InputError(
          settings.file.filename().string(), call.line,
          fmt::format("the program's cutter T{} is {:.4g} mm in diameter, {} is "
                      "{:.4g} mm; describe the program's cutter",
                      call.tool, *call.diameter_m * 1e3, where, cutter.diameter_m() * 1e3));
    if (call.corner_radius_m) {
      const bool ball = cutter.type() == tool::ToolType::ball;
      const double job_corner = ball ? cutter.radius_m() : 0.0;
      if (std::abs(*call.corner_radius_m - job_corner) > 1e-6)
        throw InputError(settings.file.filename().string(), call.line,
                         fmt::format("the program's cutter T{} has a corner radius of {:.4g} mm, "
                                     "{} is a {} end mill (corner radius {:.4g} mm); robomill "
                                     "models flat (0) and ball (R) ends",
                                     call.tool, *call.corner_radius_m * 1e3, where,
                                     ball ? "ball" : "flat", job_corner * 1e3));
    }
  }
  return tooling;
}

// The job's sampling and force settings for a run over the program.
toolpath::ProgramAnalysisSettings program_analysis_settings(const io::ToolpathSettings& settings,
                                                            int threads, std::string source_name) {
  toolpath::ProgramAnalysisSettings analysis;
  analysis.sample_spacing_m = settings.spacing_m;
  analysis.rapid_speed_m_s = settings.rapid_speed_m_s;
  analysis.default_spindle_rad_s = settings.spindle_rad_s;
  analysis.force_steps_per_tooth = settings.force_steps_per_tooth;
  analysis.threads = threads;
  analysis.source_name = std::move(source_name);
  return analysis;
}

// What --optimize keeps of the first pass: the samples whose limits were
// solved or that are at risk (the solved ones bracket every interpolated run)
// and, for every sample, whether it was at risk (2: no limit there).
struct OptimizationRecord {
  std::vector<toolpath::RecordedSample> recorded;
  std::vector<unsigned char> at_risk;
};
constexpr std::size_t kMaxRecorded = 50000;

void record(OptimizationRecord& record, const toolpath::PathSample& sample,
            const toolpath::RobotSample& robot) {
  record.at_risk.push_back(robot.stability ? (robot.at_risk ? 1 : 0) : 2);
  if (robot.stability && (robot.exact || robot.at_risk) && record.recorded.size() < kMaxRecorded)
    record.recorded.push_back({sample, robot.q_rad, robot.margin});
}

std::string program_extension(const io::ToolpathSettings& settings) {
  const std::string extension = settings.file.extension().string();
  return extension.empty() ? ".nc" : extension;
}

// Writes `text` to a scratch file and reads it back with the program's own
// reader (the written program must parse as it will on the cell).
toolpath::Program read_back(const io::ToolpathSettings& settings, const std::string& text,
                            const std::filesystem::path& scratch_file, std::size_t expected_moves) {
  {
    std::ofstream file(scratch_file, std::ios::binary | std::ios::trunc);
    file << text;
    if (!file)
      throw Error("cannot write " + scratch_file.string());
  }
  io::ToolpathSettings again = settings;
  again.file = scratch_file;
  toolpath::Program program;
  try {
    program = io::read_program(again);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(scratch_file, ignored);
    throw;
  }
  std::error_code ignored;
  std::filesystem::remove(scratch_file, ignored);
  if (program.moves.size() != expected_moves)
    throw Error(fmt::format("the written program reads back as {} moves, the original as {}",
                            program.moves.size(), expected_moves));
  return program;
}

nlohmann::json loads_json(const toolpath::MoveLoads& loads) {
  return {{"force_peak_N", loads.force_peak_n},
          {"torque_peak_Nm", loads.torque_peak_nm},
          {"deflection_um", loads.deflection_m * 1e6},
          {"joint_speed_deg_s", loads.joint_speed_rad_s * kDegPerRad}};
}

// The feed edits of a schedule: each changed line rescaled with a comment
// naming the binding cap and the loads before and after, and the restores
// (io::with_feed_restores).
std::vector<io::FeedEdit> feed_edits(const toolpath::Program& program,
                                     const toolpath::FeedSchedule& schedule,
                                     const toolpath::FeedLimits& limits) {
  std::vector<io::FeedEdit> changed;
  for (const toolpath::LineFeed& line : schedule.lines) {
    if (!line.changed())
      continue;
    const toolpath::MoveLoads& b = line.before;
    const toolpath::MoveLoads& a = line.after;
    std::string loads;
    if (limits.force_max_n > 0.0)
      loads += fmt::format(", peak force {:.0f} -> {:.0f} N", b.force_peak_n, a.force_peak_n);
    if (limits.torque_max_nm > 0.0)
      loads +=
          fmt::format(", peak torque {:.2f} -> {:.2f} N*m", b.torque_peak_nm, a.torque_peak_nm);
    if (limits.deflection_max_m > 0.0)
      loads += fmt::format(", deflection {:.0f} -> {:.0f} um", b.deflection_m * 1e6,
                           a.deflection_m * 1e6);
    if (limits.joint_speed_max_rad_s > 0.0)
      loads += fmt::format(", fastest joint {:.1f} -> {:.1f} deg/s",
                           b.joint_speed_rad_s * kDegPerRad, a.joint_speed_rad_s * kDegPerRad);
    changed.push_back(
        {line.line, line.scale, line.programmed_m_s,
         fmt::format("robomill: feed {:.0f} -> {:.0f} mm/min ({}){}", line.programmed_m_s * 6e4,
                     line.programmed_m_s * line.scale * 6e4, line.binding, loads)});
  }
  return io::with_feed_restores(program, std::move(changed));
}

// Median, 90th percentile and largest of a sample (0 for none).
struct Percentiles {
  double median = 0.0, p90 = 0.0, max = 0.0;
};
Percentiles percentiles(std::vector<double> values) {
  Percentiles p;
  if (values.empty())
    return p;
  std::sort(values.begin(), values.end());
  const auto at = [&](double q) {
    return values[std::min(values.size() - 1, static_cast<std::size_t>(q * values.size()))];
  };
  p.median = at(0.5);
  p.p90 = at(0.9);
  p.max = values.back();
  return p;
}

// The deflection compensation (toolpath/deflection_compensation.hpp) of the
// program --optimize has written: the corrections collected on its analysis
// (the after-run), written in the program's own frame and units, read back
// and checked move by move against the corrected path, then analysed once
// more for the residual against the path the CAM wrote.
nlohmann::json compensate_program(const io::Job& job, const io::RobotPathSetup& setup,
                                  const toolpath::Tooling& tooling,
                                  const toolpath::RobotPathSettings& robot_settings,
                                  const toolpath::ProgramAnalysisSettings& analysis_settings,
                                  const toolpath::PathCorrections& collected,
                                  const toolpath::Program& program, std::string& text,
                                  const std::filesystem::path& scratch_file, std::string& message) {
  const io::ToolpathSettings& settings = *job.toolpath;
  const std::vector<toolpath::LineCorrection> all = collected.corrections(program);
  // Workpiece frame → the program's own (the readers applied
  // toolpath.origin/orientation): offsets turn back by its rotation.
  const Eigen::Matrix3d to_program = settings.program_to_workpiece.linear().transpose();
  std::vector<io::PointEdit> point_edits;
  for (const toolpath::LineCorrection& c : all) {
    io::PointEdit edit{c.line, to_program * c.offset_m, {}, ""};
    double largest = c.offset_m.norm();
    for (const toolpath::CorrectionPoint& p : c.points) {
      edit.points.push_back({p.u, to_program * p.offset_m});
      largest = std::max(largest, p.offset_m.norm());
    }
    edit.comment = fmt::format("robomill: compensated, up to {:.1f} um against the predicted error",
                               largest * 1e6);
    point_edits.push_back(std::move(edit));
  }
  const io::PointEditResult edited = io::write_point_edits(text, settings.format, point_edits);
  std::map<int, std::string> skipped;
  for (const auto& s : edited.skipped)
    skipped[s.line] = s.reason;
  std::vector<toolpath::LineCorrection> written;
  std::size_t added = 0;
  double largest_m = 0.0;
  for (const toolpath::LineCorrection& c : all) {
    if (skipped.count(c.line))
      continue;
    written.push_back(c);
    added += c.points.size();
    largest_m = std::max(largest_m, c.offset_m.norm());
    for (const toolpath::CorrectionPoint& p : c.points)
      largest_m = std::max(largest_m, p.offset_m.norm());
  }
  const std::vector<Eigen::Vector3d> expected = toolpath::corrected_ends(program, written);
  const toolpath::Program corrected =
      read_back(settings, edited.text, scratch_file, expected.size());
  for (std::size_t m = 0; m < corrected.moves.size(); ++m) {
    if ((corrected.moves[m].end_m - expected[m]).norm() > 1e-6)
      throw Error(fmt::format(
          "the compensated program's line {} ends at [{:.4f}, {:.4f}, {:.4f}] mm, not the "
          "intended [{:.4f}, {:.4f}, {:.4f}] mm; nothing was written",
          corrected.moves[m].line, corrected.moves[m].end_m.x() * 1e3,
          corrected.moves[m].end_m.y() * 1e3, corrected.moves[m].end_m.z() * 1e3,
          expected[m].x() * 1e3, expected[m].y() * 1e3, expected[m].z() * 1e3));
  }

  // The written program analysed: each wall sample's error against the
  // programmed line it stands for, e' − (p' − p)·w' with p the nearest point
  // of that line (the compensated moves of one line all stand for it).
  std::vector<std::size_t> original(corrected.moves.size());
  {
    std::map<std::size_t, std::size_t> points_of;
    for (const toolpath::LineCorrection& c : written)
      points_of[c.move] = c.points.size();
    std::size_t w = 0;
    for (std::size_t m = 0; m < program.moves.size(); ++m) {
      const std::size_t count = points_of.count(m) ? points_of[m] + 1 : 1;
      for (std::size_t k = 0; k < count && w < original.size(); ++k)
        original[w++] = m;
    }
  }
  toolpath::ProgramAnalysisSettings again = analysis_settings;
  again.move_spacing_m.clear();  // the written program has moves of its own
  again.move_steps.clear();
  // A redundancy schedule follows the moves a compensated line became (ψ
  // linear along the programmed line: each part takes its stretch of it).
  toolpath::RobotPathSettings corrected_settings = robot_settings;
  if (!robot_settings.redundancy_by_move.empty()) {
    std::map<std::size_t, std::vector<double>> cuts;  // 0, the points' u, 1
    for (const toolpath::LineCorrection& c : written) {
      std::vector<double>& u = cuts[c.move];
      u.push_back(0.0);
      for (const toolpath::CorrectionPoint& p : c.points)
        u.push_back(p.u);
      u.push_back(1.0);
    }
    corrected_settings.redundancy_by_move.clear();
    for (std::size_t m = 0; m < program.moves.size(); ++m) {
      const auto [from, to] =
          m < robot_settings.redundancy_by_move.size()
              ? robot_settings.redundancy_by_move[m]
              : std::pair{robot_settings.redundancy_rad, robot_settings.redundancy_rad};
      const auto it = cuts.find(m);
      if (it == cuts.end()) {
        corrected_settings.redundancy_by_move.emplace_back(from, to);
        continue;
      }
      for (std::size_t k = 0; k + 1 < it->second.size(); ++k)
        corrected_settings.redundancy_by_move.emplace_back(from + (to - from) * it->second[k],
                                                           from + (to - from) * it->second[k + 1]);
    }
  }
  toolpath::RobotAlongPath along(*setup.model, setup.structure, tooling, *job.cutting,
                                 setup.stability, corrected_settings);
  toolpath::DexelStock stock = make_stock(job);
  std::vector<toolpath::RobotSample> block_out;
  std::vector<double> residuals_m;  // |e' − (p' − p)·w'| at every wall sample
  const toolpath::ProgramAnalysis analysis = toolpath::analyse_program(
      corrected, tooling, *job.cutting, stock, again,
      [&](std::span<const toolpath::PathSample> block) {
        block_out.resize(block.size());
        along.evaluate(block, block_out);
        for (std::size_t i = 0; i < block.size(); ++i) {
          const toolpath::RobotSample& r = block_out[i];
          const toolpath::PathSample& sample = block[i];
          if (!r.wall || !r.reachable || !sample.analysed ||
              sample.kind == toolpath::MotionKind::rapid)
            continue;
          const toolpath::Move& nominal = program.moves[original[sample.move]];
          double shift = 0.0;
          if (nominal.kind == toolpath::MotionKind::linear) {
            const Eigen::Vector3d d = nominal.end_m - nominal.start_m;
            const double t =
                d.squaredNorm() > 0.0
                    ? std::clamp((sample.tip_m - nominal.start_m).dot(d) / d.squaredNorm(), 0.0,
                                 1.0)
                    : 0.0;
            shift = (sample.tip_m - (nominal.start_m + t * d)).dot(r.wall_direction);
          }
          residuals_m.push_back(std::abs(r.form_error_m - shift));
        }
      });
  const toolpath::RobotPathSummary summary = along.finish();
  const Percentiles residual = percentiles(residuals_m);
  text = edited.text;
  nlohmann::json skipped_json = nlohmann::json::array();
  for (const auto& [line, reason] : skipped)
    if (skipped_json.size() < 50)
      skipped_json.push_back({{"line", line}, {"reason", reason}});
  if (!skipped.empty())
    message += fmt::format("  optimize: {} lines not compensated (first: line {}, {})\n",
                           skipped.size(), skipped.begin()->first, skipped.begin()->second);
  message += fmt::format(
      "  optimize: {} lines compensated ({} points added); the walls' largest error -> {:.1f} "
      "um (measured on the written program)\n",
      written.size(), added, residual.max * 1e6);
  return {
      {"floor", job.robot_path->compensation->floor},
      {"min_offset_um", job.robot_path->compensation->min_offset_m * 1e6},
      {"tolerance_um", job.robot_path->compensation->tolerance_m * 1e6},
      {"lines_compensated", written.size()},
      {"points_added", added},
      {"lines_skipped", skipped_json},
      {"max_offset_um", largest_m * 1e6},
      {"residual_um",
       {{"median", residual.median * 1e6},
        {"p90", residual.p90 * 1e6},
        {"max", residual.max * 1e6}}},
      {"max_residual_um", residual.max * 1e6},
      {"wall_samples", residuals_m.size()},
      {"compensated",
       {{"min_margin", summary.min_margin},
        {"chatter_samples", summary.chatter},
        {"at_risk_samples", summary.at_risk},
        {"max_force_N", analysis.max_force_n},
        {"cycle_time_s", analysis.cutting_time_s + analysis.air_time_s + analysis.dwell_time_s}}},
      {"note",
       "first order: every straight line moved against its samples' predicted error (form "
       "error towards the wall; floor error along the axis with floor) at the feeds and "
       "speeds chosen above, as a polyline within tolerance_um of it; 'after' is the program "
       "before this step, 'compensated' and max_residual_um the written program analysed "
       "again (the residual e' - (p' - p).w against the programmed line at every wall "
       "sample)"}};
}

// --optimize: the redundancy angle for the whole program, the spindle speed
// of each S word's stretch chosen for its postures, the feed of every line
// under the job's caps, the program written back with the changes named, and
// the whole analysis re-run on the written program (its own reader, a fresh
// stock, the samples where the first run put them), so that the
// after-numbers are measured.
nlohmann::json optimize_program(const io::Job& job, const toolpath::Program& program,
                                const toolpath::Tooling& tooling, const io::RobotPathSetup& setup,
                                const toolpath::RobotAlongPath& before,
                                const OptimizationRecord& record,
                                const toolpath::ProgramAnalysis& first_pass,
                                const std::filesystem::path& scratch, int threads,
                                CommandResult& result, std::string& message) {
  const io::ToolpathSettings& settings = *job.toolpath;
  const double cycle_time_before_s =
      first_pass.cutting_time_s + first_pass.air_time_s + first_pass.dwell_time_s;
  if (job.robot_path && job.robot_path->compensation &&
      settings.format == io::ToolpathSettings::Format::krl)
    throw InputError("robot_path.compensation", job.robot_path->compensation->line,
                     "the deflection compensation is written into G-code and APT programs; a KRL "
                     "program's points live in its .dat and FOR loops run them several times");
  // ψ first (it moves every posture), then the speeds at those postures.
  std::vector<toolpath::RecordedSample> recorded = record.recorded;
  toolpath::RobotPathSettings after_settings = setup.settings;
  nlohmann::json redundancy = nullptr;
  const bool oriented = std::any_of(program.moves.begin(), program.moves.end(),
                                    [](const toolpath::Move& m) { return m.oriented; });
  if (job.robot_path && !job.robot_path->redundancy_search_rad.empty() && oriented) {
    redundancy = {{"programmed_deg", nullptr},
                  {"note",
                   "the program's frames fix the tool's rotation about its axis (ψ per sample, "
                   "psi_deg): robot_path.redundancy_search is not applied"}};
    message += "  optimize: the program's frames fix ψ; redundancy_search not applied\n";
  } else if (job.robot_path && !job.robot_path->redundancy_search_rad.empty() &&
             job.robot_path->redundancy_per_line) {
    // ψ(s): one angle per program line, turning between lines within the
    // joint-speed bound.
    const double joint_speed_max =
        job.robot_path->redundancy_joint_speed_rad_s > 0.0
            ? job.robot_path->redundancy_joint_speed_rad_s
        : job.robot_path->feed_limits && job.robot_path->feed_limits->joint_speed_max_rad_s > 0.0
            ? job.robot_path->feed_limits->joint_speed_max_rad_s
            : 10.0 / kDegPerRad;
    const toolpath::RedundancySchedule schedule = toolpath::schedule_redundancy(
        before, program, recorded, job.robot_path->redundancy_search_rad, joint_speed_max, 0.02,
        threads);
    if (schedule.changed())
      after_settings.redundancy_by_move = schedule.by_move(program.moves.size());
    io::CsvTable table({"line", "first_move", "last_move", "from_deg", "to_deg", "turn",
                        "turn_joint_speed_deg_s", "min_margin", "samples"});
    nlohmann::json lines = nlohmann::json::array();
    for (const auto& line : schedule.lines) {
      const char* turn = line.from_rad != line.to_rad ? "during"
                         : line.turn_before           ? "before"
                                                      : "none";
      table.add_cells({static_cast<double>(line.line), static_cast<double>(line.first_move + 1),
                       static_cast<double>(line.last_move + 1), line.from_rad * kDegPerRad,
                       line.to_rad * kDegPerRad, std::string(turn),
                       line.turn_joint_speed_rad_s * kDegPerRad, line.min_margin,
                       static_cast<double>(line.samples)});
      if (lines.size() < 500)
        lines.push_back({{"line", line.line},
                         {"from_deg", line.from_rad * kDegPerRad},
                         {"to_deg", line.to_rad * kDegPerRad},
                         {"turn", turn},
                         {"turn_joint_speed_deg_s", line.turn_joint_speed_rad_s * kDegPerRad},
                         {"min_margin", line.min_margin}});
    }
    if (schedule.changed())
      result.tables.emplace_back("redundancy_schedule", std::move(table));
    redundancy = {{"per_line", true},
                  {"programmed_deg", schedule.programmed_rad * kDegPerRad},
                  {"joint_speed_max_deg_s", joint_speed_max * kDegPerRad},
                  {"turns", schedule.turns},
                  {"min_margin_before", schedule.min_margin_before},
                  {"min_margin_after", schedule.min_margin_after},
                  {"changed", schedule.changed()},
                  {"lines", lines},
                  {"note",
                   "ψ per program line, the cell's setting (the robot post's rotation about the "
                   "tool axis): the program has no word for it; redundancy_schedule.csv gives it "
                   "line by line, and the re-run uses it"}};
    if (schedule.changed())
      message += fmt::format(
          "  optimize: redundancy angle per line, {} turns (min margin {:.2f} -> {:.2f} at the "
          "programmed speeds)\n",
          schedule.turns, schedule.min_margin_before, schedule.min_margin_after);
  } else if (job.robot_path && !job.robot_path->redundancy_search_rad.empty()) {
    const toolpath::RedundancyChoice psi = toolpath::choose_redundancy_angle(
        before, recorded, job.robot_path->redundancy_search_rad, 0.02, threads);
    after_settings.redundancy_rad = psi.chosen_rad;
    nlohmann::json tried = nlohmann::json::array();
    for (const auto& c : psi.candidates)
      tried.push_back({{"redundancy_deg", c.redundancy_rad * kDegPerRad},
                       {"min_margin", c.min_margin},
                       {"at_risk", c.at_risk},
                       {"unreachable", c.unreachable},
                       {"joint_limit", c.joint_limit},
                       {"safe_samples_put_at_risk", c.newly_at_risk}});
    redundancy = {{"programmed_deg", psi.programmed_rad * kDegPerRad},
                  {"chosen_deg", psi.chosen_rad * kDegPerRad},
                  {"samples_judged", psi.samples},
                  {"min_margin_before", psi.min_margin_before},
                  {"min_margin_after", psi.min_margin_after},
                  {"candidates", tried},
                  {"note",
                   "ψ is the cell's setting (the robot post's rotation about the tool "
                   "axis): the program has no word for it"}};
    if (psi.changed())
      message += fmt::format(
          "  optimize: redundancy angle {:.0f} -> {:.0f} deg (min margin {:.2f} "
          "-> {:.2f} at the programmed speeds)\n",
          psi.programmed_rad * kDegPerRad, psi.chosen_rad * kDegPerRad, psi.min_margin_before,
          psi.min_margin_after);
  }
  const std::vector<toolpath::SpindleRegion> regions = toolpath::spindle_regions(program);
  std::vector<toolpath::SpindleChoice> choices;
  if (!setup.stability.advice_speeds_rad_s.empty())
    choices = toolpath::choose_spindle_speeds(before, regions, recorded,
                                              setup.stability.advice_speeds_rad_s, 0.02, threads);

  std::vector<io::SpindleEdit> edits;
  nlohmann::json changes = nlohmann::json::array();
  for (const toolpath::SpindleChoice& c : choices) {
    const toolpath::SpindleRegion& region = regions[c.region];
    const double from_rpm = std::abs(c.programmed_rad_s) * kRpmPerRadS;
    const double to_rpm = std::abs(c.chosen_rad_s) * kRpmPerRadS;
    nlohmann::json change = {{"lines", {region.first_line, region.last_line}},
                             {"tool", region.tool},
                             {"programmed_rpm", from_rpm},
                             {"chosen_rpm", to_rpm},
                             {"samples_judged", c.samples},
                             {"min_margin_before", c.min_margin_before},
                             {"min_margin_after", c.min_margin_after},
                             {"at_risk_before", c.at_risk_before},
                             {"at_risk_after", c.at_risk_after}};
    changes.push_back(change);
    if (!c.changed())
      continue;
    edits.push_back({region.first_line, c.chosen_rad_s,
                     fmt::format("robomill: S{:.0f} -> S{:.0f} for lines {}-{}, min stability "
                                 "margin {:.2f} -> {:.2f}",
                                 from_rpm, to_rpm, region.first_line, region.last_line,
                                 c.min_margin_before, c.min_margin_after)});
    edits.push_back({region.last_line + 1, c.programmed_rad_s,
                     fmt::format("robomill: back to the programmed S{:.0f}", from_rpm)});
  }
  nlohmann::json out = {{"spindle_choices", changes}, {"redundancy", redundancy}};
  if (!setup.stability.advice_speeds_rad_s.empty())
    out["speed_range_rpm"] = {setup.stability.advice_speeds_rad_s.front() * kRpmPerRadS,
                              setup.stability.advice_speeds_rad_s.back() * kRpmPerRadS};
  const bool psi_changed = after_settings.redundancy_rad != setup.settings.redundancy_rad ||
                           !after_settings.redundancy_by_move.empty();
  if (psi_changed && !edits.empty())
    edits.front().comment +=
        after_settings.redundancy_by_move.empty()
            ? fmt::format("; run with the redundancy angle {:.0f} deg",
                          after_settings.redundancy_rad * kDegPerRad)
            : std::string("; run with the redundancy angles of redundancy_schedule.csv");

  std::ifstream in(settings.file, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // KRL programs carry no spindle speed (the cell's PLC sets it): the
  // choices are reported, not written.
  const bool krl = settings.format == io::ToolpathSettings::Format::krl;
  const bool spindles_written = !edits.empty() && !krl;
  if (!edits.empty() && krl)
    out["note"] =
        "KRL programs carry no spindle speed (the cell's PLC sets it): set the chosen "
        "speeds there; the re-run shows the redundancy angle's and the feeds' effect only";
  if (!spindles_written)
    edits.clear();
  const std::string name = "program_optimized" + program_extension(settings);
  const std::filesystem::path scratch_file = scratch / (".robomill-" + name);
  toolpath::ProgramAnalysisSettings analysis_settings =
      program_analysis_settings(settings, threads, name);
  for (const toolpath::MoveTotals& move : first_pass.moves) {
    analysis_settings.move_spacing_m.push_back(move.spacing_m);
    analysis_settings.move_steps.push_back(move.steps);
  }

  // The feeds, on the program as it will run with the chosen speeds (the
  // spindle edits written and read back) at the chosen ψ.
  std::vector<io::FeedEdit> feeds;
  std::vector<double> feed_scale(program.moves.size(), 1.0);
  toolpath::Program with_speeds =
      spindles_written ? read_back(settings, io::write_spindle_edits(text, settings.format, edits),
                                   scratch_file, program.moves.size())
                       : program;
  // Its moves keep the original program's line numbers (the inserted S
  // blocks shift the written text's), which the feed edits and errors name.
  // Feeds are set per statement: a move on a line that continues an APT
  // record (a '$' continuation, a GOTO's further points) belongs to the
  // record's first line, where a FEDRAT can go.
  const std::vector<int> starts = io::statement_starts(text, settings.format);
  for (std::size_t m = 0; m < with_speeds.moves.size(); ++m) {
    const int line = program.moves[m].line;
    with_speeds.moves[m].line =
        line > 0 && static_cast<std::size_t>(line) < starts.size() ? starts[line] : line;
  }
  if (job.robot_path && job.robot_path->feed_limits) {
    const toolpath::FeedLimits limits = io::feed_limits(*job.robot_path->feed_limits);
    const toolpath::DexelStock stock = make_stock(job);
    toolpath::PathStabilitySettings no_limits = setup.stability;
    no_limits.enabled = false;  // the feed does not move the stable depth
    const auto make_robot = [&] {
      return std::make_unique<toolpath::RobotAlongPath>(*setup.model, setup.structure, tooling,
                                                        *job.cutting, no_limits, after_settings);
    };
    const toolpath::FeedSchedule schedule =
        toolpath::schedule_feeds(with_speeds, limits, [&](const std::vector<double>& scale) {
          return toolpath::measure_move_loads(with_speeds, scale, tooling, *job.cutting, stock,
                                              analysis_settings, make_robot);
        });
    feeds = feed_edits(with_speeds, schedule, limits);
    nlohmann::json lines = nlohmann::json::array();
    std::size_t changed = 0, slowed = 0;
    for (const toolpath::LineFeed& line : schedule.lines) {
      for (std::size_t m : line.moves)
        feed_scale[m] = line.scale;
      if (!line.changed())
        continue;
      ++changed;
      slowed += line.scale < 1.0 ? 1 : 0;
      if (lines.size() < 500)
        lines.push_back({{"line", line.line},
                         {"programmed_mm_min", line.programmed_m_s * 6e4},
                         {"chosen_mm_min", line.programmed_m_s * line.scale * 6e4},
                         {"binding", line.binding},
                         {"before", loads_json(line.before)},
                         {"after", loads_json(line.after)}});
    }
    out["feeds"] = {{"limits",
                     {{"force_max_N", limits.force_max_n},
                      {"torque_max_Nm", limits.torque_max_nm},
                      {"deflection_max_um", limits.deflection_max_m * 1e6},
                      {"joint_speed_max_deg_s", limits.joint_speed_max_rad_s * kDegPerRad},
                      {"feed_min_mm_min", limits.feed_min_m_s * 6e4},
                      {"feed_max_mm_min", limits.feed_max_m_s * 6e4}}},
                    {"runs", schedule.runs},
                    {"lines_with_feed", schedule.lines.size()},
                    {"lines_changed", changed},
                    {"lines_slowed", slowed},
                    {"lines_sped_up", changed - slowed},
                    {"max_before", loads_json(schedule.max_before)},
                    {"max_after", loads_json(schedule.max_after)},
                    {"changes", lines},
                    {"note",
                     "loads per line as measured on runs of the whole program at the chosen "
                     "spindle speeds and redundancy angle: 'before' at the programmed feed, "
                     "'after' at the chosen one; a line under every cap keeps its feed unless "
                     "feed_max lets it run faster"}};
    message += fmt::format(
        "  optimize: feeds of {} of {} lines changed ({} slowed, {} sped up) in {} runs of the "
        "program\n",
        changed, schedule.lines.size(), slowed, changed - slowed, schedule.runs);
  }

  const bool compensate = job.robot_path && job.robot_path->compensation;
  if (edits.empty() && feeds.empty() && !psi_changed && !compensate) {
    out["changed"] = false;
    out["note"] =
        "no speed in the range raises the smallest margin without putting a safe sample at "
        "risk, and every feed is within the limits: the program is kept";
    message += "  optimize: nothing to change; the program is kept\n";
    return out;
  }

  // The program written back in its dialect, read back by its reader (every
  // move's feed and speed checked against the schedule), and analysed again.
  bool written_changes = !edits.empty() || !feeds.empty();
  std::string written =
      written_changes ? io::write_program_edits(text, settings.format, edits, feeds) : text;
  toolpath::Program rewritten = read_back(settings, written, scratch_file, program.moves.size());
  for (std::size_t m = 0; m < rewritten.moves.size(); ++m) {
    const toolpath::Move& got = rewritten.moves[m];
    const toolpath::Move& want = with_speeds.moves[m];
    const double feed_m_s = want.feed_m_s * feed_scale[m];
    if (std::abs(got.feed_m_s - feed_m_s) > 1e-5 * feed_m_s + 1e-12 ||
        got.spindle_rad_s != want.spindle_rad_s)
      throw Error(fmt::format(
          "the written program's line {} (original line {}) reads back at {:.6g} mm/min and "
          "{:.6g} rpm, not the chosen {:.6g} mm/min and {:.6g} rpm; nothing was written",
          got.line, want.line, got.feed_m_s * 6e4, got.spindle_rad_s * kRpmPerRadS, feed_m_s * 6e4,
          want.spindle_rad_s * kRpmPerRadS));
  }

  toolpath::DexelStock stock = make_stock(job);
  toolpath::RobotAlongPath after(*setup.model, setup.structure, tooling, *job.cutting,
                                 setup.stability, after_settings);
  // The fastest joint along the re-run: between neighbouring samples of a move.
  double max_joint_speed_rad_s = 0.0;
  std::size_t last_move = SIZE_MAX;
  double last_t_s = 0.0;
  toolpath::RobotSample::Joints last_q;
  std::optional<toolpath::PathCorrections> corrections;
  std::vector<double> wall_errors_m;  // |form error| at the wall samples before compensation
  if (compensate) {
    toolpath::CompensationSettings c;
    c.floor = job.robot_path->compensation->floor;
    c.min_offset_m = job.robot_path->compensation->min_offset_m;
    c.tolerance_m = job.robot_path->compensation->tolerance_m;
    corrections.emplace(rewritten.moves.size(), c);
  }
  std::vector<toolpath::RobotSample> block_out;
  std::size_t index = 0, newly_at_risk = 0, relieved = 0;
  int first_newly_at_risk_line = 0;
  toolpath::MoveLoads loads_after;
  const toolpath::ProgramAnalysis analysis = toolpath::analyse_program(
      rewritten, tooling, *job.cutting, stock, analysis_settings,
      [&](std::span<const toolpath::PathSample> block) {
        block_out.resize(block.size());
        after.evaluate(block, block_out);
        for (std::size_t i = 0; i < block.size(); ++i, ++index) {
          const toolpath::RobotSample& r = block_out[i];
          if (r.reachable && block[i].kind != toolpath::MotionKind::rapid)
            loads_after.deflection_m = std::max(loads_after.deflection_m, r.deflection_m.norm());
          if (r.reachable && block[i].kind != toolpath::MotionKind::rapid) {
            if (block[i].move == last_move && block[i].t_s > last_t_s)
              max_joint_speed_rad_s =
                  std::max(max_joint_speed_rad_s,
                           (r.q_rad - last_q).cwiseAbs().maxCoeff() / (block[i].t_s - last_t_s));
            last_move = block[i].move;
            last_t_s = block[i].t_s;
            last_q = r.q_rad;
          } else {
            last_move = SIZE_MAX;
          }
          if (corrections) {
            corrections->add(block[i], r);
            if (r.wall && r.reachable && block[i].analysed &&
                block[i].kind != toolpath::MotionKind::rapid)
              wall_errors_m.push_back(std::abs(r.form_error_m));
          }
          const unsigned char was = index < record.at_risk.size() ? record.at_risk[index] : 2;
          if (!r.stability || was == 2)
            continue;
          if (r.at_risk && was == 0) {
            ++newly_at_risk;
            if (first_newly_at_risk_line == 0)
              first_newly_at_risk_line = block[i].line;
          }
          relieved += !r.at_risk && was == 1 ? 1 : 0;
        }
      });
  const toolpath::RobotPathSummary r = after.finish();
  const double cycle_after_s =
      analysis.cutting_time_s + analysis.air_time_s + analysis.dwell_time_s;
  out["changed"] = true;
  out["program"] = name;
  out["after"] = {
      {"min_margin", r.min_margin},
      {"min_margin_line", r.min_margin_line},
      {"chatter_samples", r.chatter},
      {"at_risk_samples", r.at_risk},
      {"fraction_at_risk",
       r.stability_samples > 0 ? static_cast<double>(r.at_risk) / r.stability_samples : 0.0},
      {"max_form_error_um", r.max_form_error_m * 1e6},
      {"max_force_N", analysis.max_force_n},
      {"max_torque_Nm", analysis.max_torque_nm},
      {"max_deflection_um", loads_after.deflection_m * 1e6},
      {"cycle_time_s", cycle_after_s}};
  out["cycle_time_before_s"] = cycle_time_before_s;
  out["samples_newly_at_risk"] = newly_at_risk;
  out["first_newly_at_risk_line"] = first_newly_at_risk_line;
  out["samples_relieved"] = relieved;
  out["samples_compared"] = index;
  out["samples_before"] = first_pass.samples;
  out["after"]["redundancy_deg"] = after_settings.redundancy_rad * kDegPerRad;
  out["after"]["max_joint_speed_deg_s"] = max_joint_speed_rad_s * kDegPerRad;
  if (corrections) {
    out["compensation"] =
        compensate_program(job, setup, tooling, after_settings, analysis_settings, *corrections,
                           rewritten, written, scratch_file, message);
    const Percentiles before = percentiles(wall_errors_m);
    out["compensation"]["form_error_before_um"] = {
        {"median", before.median * 1e6}, {"p90", before.p90 * 1e6}, {"max", before.max * 1e6}};
    out["compensation"]["max_form_error_before_um"] = r.max_form_error_m * 1e6;
    written_changes = written_changes || out["compensation"]["lines_compensated"] > 0;
  }
  if (!written_changes)
    out["program"] = nullptr;  // only ψ changed: the program itself is the same
  else
    result.texts.emplace_back(name, written);
  message += fmt::format(
      "  optimize: {}; chatter samples {} -> {}, min margin -> {:.2f}, {} samples no longer at "
      "risk, {} newly at risk; cycle time {:.1f} -> {:.1f} s\n",
      written_changes ? name + " written" : std::string("the program is kept"),
      before.summary().chatter, r.chatter, r.min_margin, relieved, newly_at_risk,
      cycle_time_before_s, cycle_after_s);
  return out;
}

nlohmann::json warnings_json(const toolpath::ProgramAnalysis& analysis) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& warning : analysis.warnings)
    list.push_back({{"line", warning.line}, {"text", warning.text}, {"count", warning.count}});
  return list;
}

}  // namespace

CommandResult compute_toolpath(const io::Job& job, int threads,
                               const std::filesystem::path& samples_file, const Progress& progress,
                               bool optimize) {
  io::require(job, {io::Section::cutting});
  if (!job.toolpath)
    throw InputError("toolpath", 0, "required section missing: the program (toolpath.file)");
  if (!job.stock)
    throw InputError("stock", 0, "required section missing: the stock box (stock.box: {min, max})");
  const auto start = std::chrono::steady_clock::now();
  const io::ToolpathSettings& settings = *job.toolpath;
  const toolpath::Program program = io::read_program(settings);
  const toolpath::Tooling tooling = make_tooling(job, program);
  toolpath::DexelStock stock = make_stock(job);

  const toolpath::ProgramAnalysisSettings analysis_settings =
      program_analysis_settings(settings, threads, settings.file.filename().string());

  // Samples stream to the file (or into a table for library callers); a
  // preview of at most kPreviewRows evenly spread rows goes to the report. The
  // stride is chosen from the program's length before the run.
  double path_length_m = 0.0;
  for (const toolpath::Move& move : program.moves)
    path_length_m += toolpath::path_length_m(move);
  const double expected_samples =
      path_length_m /
          std::max(settings.spacing_m > 0.0 ? settings.spacing_m : 0.5 * job.stock->resolution_m,
                   1e-6) +
      2.0 * static_cast<double>(program.moves.size());
  const std::size_t preview_stride = static_cast<std::size_t>(
      std::max(1.0, std::ceil(expected_samples / static_cast<double>(kPreviewRows))));

  // The robot along the program, when the job puts the part in a robot cell.
  std::optional<io::RobotPathSetup> robot_setup = io::robot_path_setup(job, threads);
  std::optional<toolpath::RobotAlongPath> robot;
  if (robot_setup)
    robot.emplace(*robot_setup->model, robot_setup->structure, tooling, *job.cutting,
                  robot_setup->stability, robot_setup->settings);
  const int dof = robot ? robot->model().dof() : 0;
  std::vector<toolpath::RobotSample> robot_block;
  if (optimize && !robot)
    throw InputError("toolpath", settings.line,
                     "--optimize needs the robot on the program: a robot: section and "
                     "workpiece.pose");
  if (optimize && robot_setup->stability.advice_speeds_rad_s.empty() &&
      !(job.robot_path && job.robot_path->feed_limits))
    throw InputError("stability.speeds", 0,
                     "--optimize needs the spindle range it may choose from (stability.speeds: "
                     "{from, to, count}) or the feed's caps (robot_path.feed_limits)");
  OptimizationRecord optimization;

  io::CsvTable samples = sample_table(dof);
  io::CsvTable preview = sample_table(dof);
  std::ofstream stream;
  if (!samples_file.empty()) {
    stream.open(samples_file, std::ios::binary | std::ios::trunc);
    if (!stream)
      throw Error("cannot write " + samples_file.string());
  }
  bool header_written = false;
  std::size_t seen = 0;
  std::size_t max_engagement_line = 0;
  double max_engagement_rad = 0.0;
  const toolpath::SampleSink sink = [&](std::span<const toolpath::PathSample> block) {
    io::CsvTable chunk = sample_table(dof);
    io::CsvTable& target = samples_file.empty() ? samples : chunk;
    if (robot) {
      robot_block.resize(block.size());
      robot->evaluate(block, robot_block);
    }
    for (std::size_t i = 0; i < block.size(); ++i) {
      const toolpath::PathSample& sample = block[i];
      const toolpath::RobotSample* r = robot ? &robot_block[i] : nullptr;
      if (optimize && r)
        record(optimization, sample, *r);
      add_sample(target, sample, r);
      if (seen++ % preview_stride == 0)
        add_sample(preview, sample, r);
      if (sample.engaged_rad > max_engagement_rad && sample.kind != toolpath::MotionKind::rapid) {
        max_engagement_rad = sample.engaged_rad;
        max_engagement_line = static_cast<std::size_t>(sample.line);
      }
    }
    if (!samples_file.empty()) {
      std::string text = chunk.to_string();
      if (header_written)
        text.erase(0, text.find('\n') + 1);
      header_written = true;
      stream.write(text.data(), static_cast<std::streamsize>(text.size()));
      if (!stream)
        throw Error("cannot write " + samples_file.string());
    }
  };
  const auto bar = [&](double fraction) {
    if (progress)
      progress("toolpath", fraction);
  };
  const toolpath::ProgramAnalysis analysis =
      toolpath::analyse_program(program, tooling, *job.cutting, stock, analysis_settings, sink,
                                [&](double fraction) { bar(fraction); });
  if (stream.is_open()) {
    stream.flush();
    if (!stream)
      throw Error("cannot write " + samples_file.string());
  }
  if (analysis.engaged_samples == 0) {
    throw InputError("toolpath.origin", settings.line,
                     fmt::format("no move of '{}' touches the stock: check toolpath.origin "
                                 "(where the program's zero sits in the workpiece frame) against "
                                 "stock.box",
                                 settings.file_text));
  }
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  nlohmann::json notes = nlohmann::json::array();
  for (const toolpath::ProgramNote& note : program.notes)
    notes.push_back({{"line", note.line}, {"text", note.text}});
  std::set<int> tools_used;
  for (const toolpath::Move& move : program.moves)
    tools_used.insert(move.tool);
  const io::StockSettings& stock_settings = *job.stock;
  const double cycle_time_s = analysis.cutting_time_s + analysis.air_time_s + analysis.dwell_time_s;
  nlohmann::json summary = {
      {"command", "toolpath"},
      {"job", job.source.string()},
      {"program", settings.file_text},
      {"dialect", program.dialect},
      {"lines", program.line_count},
      {"moves", program.moves.size()},
      {"tools", std::vector<int>(tools_used.begin(), tools_used.end())},
      {"samples", analysis.samples},
      {"engaged_samples", analysis.engaged_samples},
      {"cutting_time_s", analysis.cutting_time_s},
      {"air_time_s", analysis.air_time_s},
      {"dwell_time_s", analysis.dwell_time_s},
      {"cycle_time_s", cycle_time_s},
      {"volume_removed_mm3", analysis.volume_removed_m3 * 1e9},
      {"max_force_N", analysis.max_force_n},
      {"max_force_line", analysis.max_force_line},
      {"max_torque_Nm", analysis.max_torque_nm},
      {"max_torque_line", analysis.max_torque_line},
      {"max_power_W", analysis.max_power_w},
      {"max_power_line", analysis.max_power_line},
      {"max_engagement_deg", max_engagement_rad * kDegPerRad},
      {"max_engagement_line", max_engagement_line},
      {"warnings", warnings_json(analysis)},
      {"notes", notes},
      {"stock",
       {{"min_mm",
         {stock_settings.min_m.x() * 1e3, stock_settings.min_m.y() * 1e3,
          stock_settings.min_m.z() * 1e3}},
        {"max_mm",
         {stock_settings.max_m.x() * 1e3, stock_settings.max_m.y() * 1e3,
          stock_settings.max_m.z() * 1e3}},
        {"resolution_mm", stock_settings.resolution_m * 1e3},
        {"memory_MB", static_cast<double>(stock.memory_bytes()) / 1e6}}},
      {"frame", "workpiece frame; forces on the tool"},
      {"elapsed_s", elapsed_s},
  };
  if (!job.name.empty())
    summary["name"] = job.name;
  std::string robot_text;
  if (robot) {
    const toolpath::RobotPathSummary r = robot->finish();
    if (r.samples > 0 && r.unreachable == r.samples) {
      const Eigen::Vector3d table = job.workpiece->cell.table_origin_m * 1e3;
      throw InputError("workpiece.pose", job.robot_path ? job.robot_path->line : 0,
                       fmt::format("the robot reaches no sample of the program (from line {}) "
                                   "with the part on the table at [{:.0f}, {:.0f}, {:.0f}] mm: "
                                   "move the table or the pose within the robot's reach",
                                   r.first_unreachable_line, table.x(), table.y(), table.z()));
    }
    // A better program for a cell that cannot run this one would mislead:
    // --optimize stops here, naming where the robot falls short.
    if (optimize && r.unreachable > 0)
      throw InputError("workpiece.pose", job.robot_path ? job.robot_path->line : 0,
                       fmt::format("--optimize: the robot cannot reach {} samples of the program "
                                   "(the first at program line {}); no program is written: move "
                                   "the part within reach (workpiece.table, workpiece.pose) or "
                                   "run without --optimize to see every line out of reach",
                                   r.unreachable, r.first_unreachable_line));
    if (r.unreachable > 0) {
      std::string lines;
      for (std::size_t k = 0; k < std::min<std::size_t>(r.unreachable_lines.size(), 10); ++k)
        lines += (k ? ", " : "") + std::to_string(r.unreachable_lines[k]);
      robot_text += fmt::format(
          "  warning: the robot cannot reach {} samples (lines {}{}); their "
          "columns are the inverse kinematics' best attempt\n",
          r.unreachable, lines, r.unreachable_lines.size() > 10 ? ", ..." : "");
    }
    summary["robot_along_path"] = robot_summary(*robot_setup, *robot, r);
    robot_text += fmt::format(
        "  robot {}: {} samples unreachable, {} at a joint limit; chatter at {} of {} samples in "
        "the cut, min margin {:.2f} (line {}); largest form error {:.1f} um (line {})\n"
        "  stable depths: {} computed, the rest interpolated (checked {}, largest error {:.2g} "
        "%)\n",
        robot->model().name(), r.unreachable, r.joint_limit, r.chatter, r.stability_samples,
        r.min_margin, r.min_margin_line, r.max_form_error_m * 1e6, r.max_form_error_line,
        r.exact_limits, r.checked, r.shortcut_max_error * 100.0);
  }

  CommandResult result;
  if (optimize) {
    const std::filesystem::path scratch =
        samples_file.empty() ? std::filesystem::temp_directory_path() : samples_file.parent_path();
    summary["optimization"] =
        optimize_program(job, program, tooling, *robot_setup, *robot, optimization, analysis,
                         scratch, threads, result, robot_text);
  }
  if (samples_file.empty())
    result.tables.emplace_back("samples", std::move(samples));
  else
    result.streamed.emplace_back("samples.csv", samples_file);
  result.tables.emplace_back("samples_preview", std::move(preview));
  result.tables.emplace_back("moves", move_table(analysis));
  result.tables.emplace_back("stock", stock_table(stock));
  result.summary = std::move(summary);
  std::string warnings_text;
  for (const auto& warning : analysis.warnings)
    warnings_text += fmt::format(
        "  warning (line {}{}): {}\n", warning.line,
        warning.count > 1 ? fmt::format(", {} times", warning.count) : std::string(), warning.text);
  result.message = fmt::format(
      "toolpath: {} ({}), {} moves, {} samples ({} in the cut)\n"
      "  cutting {:.1f} s, air {:.1f} s, removed {:.6g} mm^3\n"
      "  max force {:.1f} N (line {}), torque {:.3f} N·m (line {}), power {:.0f} W (line {})\n{}",
      settings.file_text, program.dialect, program.moves.size(), analysis.samples,
      analysis.engaged_samples, analysis.cutting_time_s, analysis.air_time_s,
      analysis.volume_removed_m3 * 1e9, analysis.max_force_n, analysis.max_force_line,
      analysis.max_torque_nm, analysis.max_torque_line, analysis.max_power_w,
      analysis.max_power_line, warnings_text);
  result.message += robot_text;
  return result;
}

}  // namespace robomill::commands
