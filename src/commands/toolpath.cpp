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
#include <optional>
#include <set>

#include "robomill/analysis/program_run.hpp"
#include "robomill/analysis/robot_path_setup.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/output_bundle.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/io/program_writer.hpp"
#include "robomill/io/summary.hpp"
#include "toolpath_outputs.hpp"

namespace robomill::commands {
namespace {

using detail::add_improvement_files;
using detail::improvement_json;
using detail::improvement_message;
using detail::path_uncertainty_json;
using detail::path_uncertainty_message;

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

// The robot's columns (robot_along_path.hpp), after the program's; with
// draws of the uncertain inputs (issue 33), P(chatter) and the band of the
// limit last.
std::vector<std::string> sample_columns(int dof, bool drawn) {
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
    if (drawn)
      for (const char* c : {"p_chatter", "p_chatter_se", "ap_limit_q05_mm", "ap_limit_q95_mm"})
        columns.emplace_back(c);
  }
  return columns;
}

io::CsvTable sample_table(int dof = 0, bool drawn = false) {
  return io::CsvTable(sample_columns(dof, drawn));
}

// A row of cells for an in-memory table (the library's samples, the
// preview), with io::CsvText's interface: one formatting of each row for both.
class TableRow {
 public:
  explicit TableRow(io::CsvTable& table) : table_(table) {}
  void number(double value) { cells_.emplace_back(value); }
  void word(std::string_view text) { cells_.emplace_back(std::string(text)); }
  void blank() { cells_.emplace_back(std::string()); }
  void end_row() {
    table_.add_cells(cells_);
    cells_.clear();
  }

 private:
  io::CsvTable& table_;
  std::vector<io::CsvTable::Cell> cells_;
};

template <class Row>
void add_sample(Row& row, const toolpath::PathSample& s,
                const robot_path::RobotSample* robot = nullptr, bool drawn = false) {
  for (const double value :
       {static_cast<double>(s.line), s.t_s, s.tip_m.x() * 1e3, s.tip_m.y() * 1e3, s.tip_m.z() * 1e3,
        s.axis.x(), s.axis.y(), s.axis.z(), static_cast<double>(s.tool)})
    row.number(value);
  row.word(motion_name(s.kind));
  for (const double value : {s.feed_m_s * 6e4,
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
                             s.plunge ? 1.0 : 0.0})
    row.number(value);
  if (robot) {
    const robot_path::RobotSample& r = *robot;
    const auto either = [&](bool present, double value) {
      if (present)
        row.number(value);
      else
        row.blank();
    };
    row.number(r.redundancy_rad * kDegPerRad);
    for (Eigen::Index j = 0; j < r.q_rad.size(); ++j)
      row.number(r.q_rad[j] * kDegPerRad);
    row.number(r.reachable ? 1.0 : 0.0);
    row.number(r.joint_margin_rad * kDegPerRad);
    row.number(r.singularity);
    const bool limit = r.stability;
    either(limit, r.depth_limit_m * 1e3);
    either(limit, r.margin);
    either(limit, r.chatter ? 1.0 : 0.0);
    either(limit, r.at_risk ? 1.0 : 0.0);
    either(limit && r.chatter_frequency_hz > 0.0, r.chatter_frequency_hz);
    const bool bent = r.reachable && s.analysed && s.kind != toolpath::MotionKind::rapid;
    for (int a = 0; a < 3; ++a)
      either(bent, r.deflection_m[a] * 1e6);
    either(bent, r.deflection_m.norm() * 1e6);
    either(bent && r.wall, r.form_error_m * 1e6);
    either(bent, r.floor_error_m * 1e6);
    either(limit, r.exact ? 1.0 : 0.0);
    either(bent, r.contact ? 1.0 : 0.0);
    either(r.has_offset, r.steady_offset_m * 1e6);
    if (drawn) {
      either(r.drawn, r.p_chatter);
      either(r.drawn, r.p_chatter_se);
      either(r.drawn, r.depth_limit_q05_m * 1e3);
      either(r.drawn, r.depth_limit_q95_m * 1e3);
    }
  }
  row.end_row();
}

// summary.json's robot_along_path: the worst lines with their advice, the
// robot drawn at the worst posture.
nlohmann::json robot_summary(const analysis::RobotPathSetup& setup,
                             const robot_path::RobotAlongPath& along,
                             const robot_path::RobotPathSummary& r) {
  nlohmann::json worst = nlohmann::json::array();
  for (const robot_path::WorstLine& w : r.worst_lines) {
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
    const robot_path::WorstLine& w = r.worst_lines.front();
    const analysis::RobotDrawing drawing = analysis::robot_drawing(along, w.q_rad);
    nlohmann::json origins = nlohmann::json::array();
    for (const Eigen::Vector3d& p : drawing.joint_origins_m)
      origins.push_back({p.x() * 1e3, p.y() * 1e3, p.z() * 1e3});
    std::vector<double> q_deg;
    for (Eigen::Index j = 0; j < w.q_rad.size(); ++j)
      q_deg.push_back(w.q_rad[j] * kDegPerRad);
    const Eigen::Isometry3d& tool = drawing.tool_pose;
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

std::vector<std::string> move_columns() {
  return {"line",        "move",
          "tool",        "motion",
          "length_mm",   "time_s",
          "feed_mm_min", "spindle_rpm",
          "samples",     "engaged_samples",
          "removed_mm3", "max_ap_mm",
          "max_ae_mm",   "max_engagement_deg",
          "max_force_N", "max_torque_Nm",
          "max_power_W", "tool_described",
          "unsampled_mm"};
}

template <class Row>
void add_moves(Row& row, const toolpath::ProgramAnalysis& analysis) {
  for (const toolpath::MoveTotals& m : analysis.moves) {
    for (const double value :
         {static_cast<double>(m.line), static_cast<double>(m.move), static_cast<double>(m.tool)})
      row.number(value);
    row.word(motion_name(m.kind));
    for (const double value :
         {m.length_m * 1e3, m.time_s, m.feed_m_s * 6e4, m.spindle_rad_s * kRpmPerRadS,
          static_cast<double>(m.samples), static_cast<double>(m.engaged_samples),
          m.removed_m3 * 1e9, m.max_axial_depth_m * 1e3, m.max_radial_width_m * 1e3,
          m.max_engaged_rad * kDegPerRad, m.max_force_n, m.max_torque_nm, m.max_power_w,
          m.tool_described ? 1.0 : 0.0, m.unsampled_length_m * 1e3})
      row.number(value);
    row.end_row();
  }
}

template <class Row>
void add_stock(Row& row, const toolpath::DexelStock& stock) {
  const std::vector<double> heights = stock.top_heights_m();
  const int nx = stock.counts()[0], ny = stock.counts()[1];
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      row.number(stock.cell_centre_m(0, i) * 1e3);
      row.number(stock.cell_centre_m(1, j) * 1e3);
      row.number(heights[static_cast<std::size_t>(j) * nx + i] * 1e3);
      row.end_row();
    }
}

nlohmann::json warnings_json(const toolpath::ProgramAnalysis& analysis) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& warning : analysis.warnings)
    list.push_back({{"line", warning.line}, {"text", warning.text}, {"count", warning.count}});
  return list;
}

// The stride of the preview's rows: at most kPreviewRows of the samples
// the program is expected to give.
std::size_t preview_stride_for(const job::Job& job, const analysis::ProgramRun& run) {
  const double expected = analysis::expected_samples(job, run);
  return static_cast<std::size_t>(
      std::max(1.0, std::ceil(expected / static_cast<double>(kPreviewRows))));
}

// summary.json without the robot's and the optimization's parts.
nlohmann::json toolpath_summary(const job::Job& job, const analysis::ProgramRun& run) {
  const job::ToolpathSettings& settings = *job.toolpath;
  const toolpath::Program& program = run.program;
  const toolpath::ProgramAnalysis& analysis = run.analysis;
  nlohmann::json notes = nlohmann::json::array();
  for (const toolpath::ProgramNote& note : program.notes)
    notes.push_back({{"line", note.line}, {"text", note.text}});
  std::set<int> tools_used;
  for (const toolpath::Move& move : program.moves)
    tools_used.insert(move.tool);
  const job::StockSettings& stock_settings = *job.stock;
  const double cycle_time_s = analysis.cutting_time_s + analysis.air_time_s + analysis.dwell_time_s;
  return {
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
      {"unsampled_length_mm", analysis.unsampled_length_m * 1e3},
      {"unsampled_time_s", analysis.unsampled_time_s},
      {"cycle_time_s", cycle_time_s},
      {"volume_removed_mm3", analysis.volume_removed_m3 * 1e9},
      {"max_force_N", analysis.max_force_n},
      {"max_force_line", analysis.max_force_line},
      {"max_torque_Nm", analysis.max_torque_nm},
      {"max_torque_line", analysis.max_torque_line},
      {"max_power_W", analysis.max_power_w},
      {"max_power_line", analysis.max_power_line},
      {"max_engagement_deg", run.max_engagement_rad * kDegPerRad},
      {"max_engagement_line", run.max_engagement_line},
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
        {"memory_MB", static_cast<double>(run.stock->memory_bytes()) / 1e6}}},
      {"frame", "workpiece frame; forces on the tool"},
      {"elapsed_s", run.elapsed_s},
  };
}

// The message's warning when the robot cannot reach some samples (empty
// when it reaches them all).
std::string unreachable_warning(const robot_path::RobotPathSummary& r) {
  if (r.unreachable == 0)
    return std::string();
  std::string lines;
  for (std::size_t k = 0; k < std::min<std::size_t>(r.unreachable_lines.size(), 10); ++k)
    lines += (k ? ", " : "") + std::to_string(r.unreachable_lines[k]);
  return fmt::format(
      "  warning: the robot cannot reach {} samples (lines {}{}); their "
      "columns are the inverse kinematics' best attempt\n",
      r.unreachable, lines, r.unreachable_lines.size() > 10 ? ", ..." : "");
}

// The message's lines on the robot along the path.
std::string robot_path_message(const std::string& robot_name,
                               const robot_path::RobotPathSummary& r) {
  return fmt::format(
      "  robot {}: {} samples unreachable, {} at a joint limit; chatter at {} of {} samples in "
      "the cut, min margin {:.2f} (line {}); largest form error {:.1f} um (line {})\n"
      "  stable depths: {} computed, the rest interpolated (checked {}, largest error {:.2g} "
      "%)\n",
      robot_name, r.unreachable, r.joint_limit, r.chatter, r.stability_samples, r.min_margin,
      r.min_margin_line, r.max_form_error_m * 1e6, r.max_form_error_line, r.exact_limits, r.checked,
      r.shortcut_max_error * 100.0);
}

// moves.csv and stock.csv. A long program's moves and a fine stock are
// millions of cells: the command (`as_text`) writes them as text (a tenth
// of the memory); library callers get tables.
void add_moves_and_stock(const job::Job& job, const analysis::ProgramRun& run, bool as_text,
                         CommandResult& result) {
  const toolpath::ProgramAnalysis& analysis = run.analysis;
  if (!as_text) {
    io::CsvTable moves(move_columns()), stock({"x_mm", "y_mm", "z_mm"});
    TableRow move_row(moves), stock_row(stock);
    add_moves(move_row, analysis);
    add_stock(stock_row, *run.stock);
    result.tables.emplace_back("moves", std::move(moves));
    result.tables.emplace_back("stock", std::move(stock));
  } else if (job.output.csv) {
    io::CsvText moves(move_columns()), stock({"x_mm", "y_mm", "z_mm"});
    add_moves(moves, analysis);
    add_stock(stock, *run.stock);
    result.texts.emplace_back("moves.csv", moves.take());
    result.texts.emplace_back("stock.csv", stock.take());
  }
}

// The message's lines on the program: its totals, its warnings and the
// path away from the stock.
std::string program_message(const job::ToolpathSettings& settings, const toolpath::Program& program,
                            const toolpath::ProgramAnalysis& analysis) {
  std::string warnings_text;
  for (const auto& warning : analysis.warnings)
    warnings_text += fmt::format(
        "  warning (line {}{}): {}\n", warning.line,
        warning.count > 1 ? fmt::format(", {} times", warning.count) : std::string(), warning.text);
  std::string message = fmt::format(
      "toolpath: {} ({}), {} moves, {} samples ({} in the cut)\n"
      "  cutting {:.1f} s, air {:.1f} s, removed {:.6g} mm^3\n"
      "  max force {:.1f} N (line {}), torque {:.3f} N·m (line {}), power {:.0f} W (line {})\n{}",
      settings.file_text, program.dialect, program.moves.size(), analysis.samples,
      analysis.engaged_samples, analysis.cutting_time_s, analysis.air_time_s,
      analysis.volume_removed_m3 * 1e9, analysis.max_force_n, analysis.max_force_line,
      analysis.max_torque_nm, analysis.max_torque_line, analysis.max_power_w,
      analysis.max_power_line, warnings_text);
  // Retracts and approaches leave some path away from the stock in most
  // programs (summary.json has it); the message says so when it is long.
  if (analysis.unsampled_length_m > 1.0)
    message +=
        fmt::format("  {:.1f} m of path away from the stock ({:.1f} s): timed, not sampled\n",
                    analysis.unsampled_length_m, analysis.unsampled_time_s);
  return message;
}

}  // namespace

CommandResult compute_toolpath(const job::Job& job, int threads,
                               const std::filesystem::path& samples_file, const Progress& progress,
                               bool optimize, const analysis::BlockSharing* sharing) {
  // Samples stream to the file (or into a table for library callers); a
  // preview of at most kPreviewRows evenly spread rows goes to the report,
  // the stride chosen from the program's length before the run.
  int dof = 0;
  bool drawn = false;
  std::size_t preview_stride = 1, seen = 0;
  io::CsvTable samples = sample_table(), preview = sample_table();
  std::ofstream stream;
  std::optional<io::CsvText> streamed;  // samples.csv's rows, written block by block
  analysis::ProgramRunOptions options;
  options.threads = threads;
  options.optimize = optimize;
  options.sharing = sharing;
  options.scratch_dir = samples_file.empty() ? std::filesystem::path() : samples_file.parent_path();
  if (progress)
    options.progress = [&](double fraction) { progress("toolpath", fraction); };
  options.on_start = [&](const analysis::ProgramRun& run) {
    dof = run.robot ? run.robot->model().dof() : 0;
    drawn = run.robot && run.robot->draw_count() > 0;
    samples = sample_table(dof, drawn);
    preview = sample_table(dof, drawn);
    preview_stride = preview_stride_for(job, run);
    if (!samples_file.empty()) {
      stream.open(samples_file, std::ios::binary | std::ios::trunc);
      if (!stream)
        throw Error("cannot write " + samples_file.string());
      streamed.emplace(sample_columns(dof, drawn));
    }
  };
  options.on_samples = [&](std::span<const toolpath::PathSample> block,
                           std::span<const robot_path::RobotSample> robot) {
    TableRow in_memory(samples), preview_row(preview);
    for (std::size_t i = 0; i < block.size(); ++i) {
      const robot_path::RobotSample* r = robot.empty() ? nullptr : &robot[i];
      if (streamed)
        add_sample(*streamed, block[i], r, drawn);
      else
        add_sample(in_memory, block[i], r, drawn);
      if (seen++ % preview_stride == 0)
        add_sample(preview_row, block[i], r, drawn);
    }
    if (streamed) {
      const std::string text = streamed->take();
      stream.write(text.data(), static_cast<std::streamsize>(text.size()));
      if (!stream)
        throw Error("cannot write " + samples_file.string());
    }
  };
  const analysis::ProgramRun run = analysis::run_program(job, options);
  if (stream.is_open()) {
    stream.flush();
    if (!stream)
      throw Error("cannot write " + samples_file.string());
  }

  nlohmann::json summary = toolpath_summary(job, run);
  if (!job.name.empty())
    summary["name"] = job.name;
  std::string robot_text;
  if (run.robot) {
    const robot_path::RobotPathSummary& r = *run.robot_summary;
    robot_text += unreachable_warning(r);
    summary["robot_along_path"] = robot_summary(*run.robot_setup, *run.robot, r);
    robot_text += robot_path_message(run.robot->model().name(), r);
    const double bound = run.robot->settings().max_chatter_probability;
    if (run.draws) {
      summary["robot_along_path"]["uncertainty"] =
          path_uncertainty_json(run.draws->draws, bound, r);
      robot_text += path_uncertainty_message(bound, r);
    }
  }

  CommandResult result;
  if (run.improvement) {
    const analysis::JobDraws* draws = run.draws ? &run.draws->draws : nullptr;
    summary["optimization"] = improvement_json(*run.improvement, *run.robot_setup, draws);
    add_improvement_files(*run.improvement, result);
    robot_text += improvement_message(*run.improvement, *run.robot_setup, draws);
  }
  if (samples_file.empty())
    result.tables.emplace_back("samples", std::move(samples));
  else
    result.streamed.emplace_back("samples.csv", samples_file);
  result.tables.emplace_back("samples_preview", std::move(preview));
  add_moves_and_stock(job, run, !samples_file.empty(), result);
  result.summary = std::move(summary);
  result.message = program_message(*job.toolpath, run.program, run.analysis) + robot_text;
  return result;
}

}  // namespace robomill::commands
