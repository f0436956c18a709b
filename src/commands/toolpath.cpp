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

namespace robomill::commands {
namespace {

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

// summary.json's robot_along_path.uncertainty (issue 33): the draws, the
// expected number of chattering samples, the most probable chatter and the
// lines over the bound.
nlohmann::json path_uncertainty_json(const analysis::JobDraws& draws,
                                     double max_chatter_probability,
                                     const robot_path::RobotPathSummary& r) {
  constexpr std::size_t kListed = 200;
  nlohmann::json lines = nlohmann::json::array();
  for (std::size_t k = 0; k < std::min(kListed, r.risky_lines.size()); ++k) {
    const robot_path::RiskyLine& l = r.risky_lines[k];
    lines.push_back({{"line", l.line},
                     {"t_s", l.t_s},
                     {"p_chatter", l.p_chatter},
                     {"p_chatter_se", l.p_chatter_se},
                     {"ap_mm", l.axial_depth_m * 1e3},
                     {"ap_limit_mm", l.depth_limit_m * 1e3},
                     {"ap_limit_q05_mm", l.depth_limit_q05_m * 1e3}});
  }
  return {{"draws", r.draws},
          {"source", draws.source},
          {"variables", draws.names},
          {"max_chatter_probability", max_chatter_probability},
          {"expected_chatter_samples", r.expected_chatter_samples},
          {"expected_chatter_samples_se", r.expected_chatter_samples_se},
          {"nominal_chatter_samples", r.chatter},
          {"max_p_chatter", r.max_p_chatter},
          {"max_p_chatter_se", r.max_p_chatter_se},
          {"max_p_chatter_line", r.max_p_chatter_line},
          {"lines_over_bound_count", r.risky_lines.size()},
          {"lines_over_bound", lines},
          {"draw_dynamics_recomputations", r.draw_exact_limits},
          {"draw_shortcut_max_error", r.draw_shortcut_max_error}};
}

std::string path_uncertainty_message(double max_chatter_probability,
                                     const robot_path::RobotPathSummary& r) {
  std::string text = fmt::format(
      "  uncertainty: {} draws, expected chattering samples {:.1f} ± {:.1f} (nominal {}); "
      "highest P(chatter) {:.1f} % ± {:.1f} (line {}); {} lines over {:.3g} %",
      r.draws, r.expected_chatter_samples, r.expected_chatter_samples_se, r.chatter,
      r.max_p_chatter * 100.0, r.max_p_chatter_se * 100.0, r.max_p_chatter_line,
      r.risky_lines.size(), max_chatter_probability * 100.0);
  if (!r.risky_lines.empty()) {
    text += " (";
    for (std::size_t k = 0; k < std::min<std::size_t>(8, r.risky_lines.size()); ++k)
      text += fmt::format("{}{}", k ? ", " : "", r.risky_lines[k].line);
    text += r.risky_lines.size() > 8 ? ", …)" : ")";
  }
  return text + "\n";
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

nlohmann::json loads_json(const robot_path::MoveLoads& loads) {
  return {{"force_peak_N", loads.force_peak_n},
          {"torque_peak_Nm", loads.torque_peak_nm},
          {"deflection_um", loads.deflection_m * 1e6},
          {"joint_speed_deg_s", loads.joint_speed_rad_s * kDegPerRad}};
}

nlohmann::json warnings_json(const toolpath::ProgramAnalysis& analysis) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& warning : analysis.warnings)
    list.push_back({{"line", warning.line}, {"text", warning.text}, {"count", warning.count}});
  return list;
}

// summary.json's `optimization`, the files and the message's optimize lines
// are built apart, each from the typed improvement
// (analysis/program_improvement.hpp): improvement_json,
// add_improvement_files and improvement_message.

// How a line's schedule turns ψ: during the line, before it, or not at all.
const char* redundancy_turn(const robot_path::RedundancySchedule::Line& line) {
  return line.from_rad != line.to_rad ? "during" : line.turn_before ? "before" : "none";
}

// A KRL program: the angles are turns of its frames, written into them.
void add_frames_turned(nlohmann::json& redundancy, const analysis::ProgramImprovement& im,
                       const char* how) {
  redundancy["frames"] = true;
  redundancy["frames_turned"] = im.frames_turned;
  redundancy["note"] = fmt::format(
      "the program's frames set ψ at every sample (psi_deg): the angles are turns of its frames "
      "about the tool axis, {}, written into the A, B, C of its Cartesian points in "
      "program_optimized.src and .dat; S and T bits are kept",
      how);
}

nlohmann::json program_frames_json(const analysis::RedundancyDecision& psi) {
  std::string note =
      "the program's frames fix the tool's rotation about its axis (ψ per sample, psi_deg): "
      "robot_path.redundancy_search is not applied";
  if (!psi.frames_refused.empty())
    note += "; its frames cannot all be turned: " + psi.frames_refused;
  return {{"programmed_deg", nullptr}, {"note", note}};
}

nlohmann::json per_line_redundancy_json(const analysis::ProgramImprovement& im) {
  const analysis::RedundancyDecision& psi = im.redundancy;
  const robot_path::RedundancySchedule& schedule = *psi.schedule;
  nlohmann::json lines = nlohmann::json::array();
  for (const auto& line : schedule.lines) {
    if (lines.size() < 500)
      lines.push_back({{"line", line.line},
                       {"from_deg", line.from_rad * kDegPerRad},
                       {"to_deg", line.to_rad * kDegPerRad},
                       {"turn", redundancy_turn(line)},
                       {"turn_joint_speed_deg_s", line.turn_joint_speed_rad_s * kDegPerRad},
                       {"min_margin", line.min_margin}});
  }
  nlohmann::json redundancy = {
      {"per_line", true},
      {"programmed_deg", schedule.programmed_rad * kDegPerRad},
      {"joint_speed_max_deg_s", psi.joint_speed_max_rad_s * kDegPerRad},
      {"turns", schedule.turns},
      {"min_margin_before", schedule.min_margin_before},
      {"min_margin_after", schedule.min_margin_after},
      {"changed", schedule.changed()},
      {"lines", lines},
      {"note",
       "ψ per program line, the cell's setting (the robot post's rotation about the "
       "tool axis): the program has no word for it; redundancy_schedule.csv gives it "
       "line by line, and the re-run uses it"}};
  if (psi.turns_frames)
    add_frames_turned(redundancy, im,
                      "each Cartesian point turned by the angle of the line that ends at it "
                      "(from_deg/to_deg)");
  return redundancy;
}

nlohmann::json single_redundancy_json(const analysis::ProgramImprovement& im) {
  const analysis::RedundancyDecision& psi = im.redundancy;
  const robot_path::RedundancyChoice& choice = *psi.choice;
  nlohmann::json tried = nlohmann::json::array();
  for (const auto& c : choice.candidates)
    tried.push_back({{"redundancy_deg", c.redundancy_rad * kDegPerRad},
                     {"min_margin", c.min_margin},
                     {"at_risk", c.at_risk},
                     {"unreachable", c.unreachable},
                     {"joint_limit", c.joint_limit},
                     {"safe_samples_put_at_risk", c.newly_at_risk}});
  nlohmann::json redundancy = {{"programmed_deg", choice.programmed_rad * kDegPerRad},
                               {"chosen_deg", choice.chosen_rad * kDegPerRad},
                               {"samples_judged", choice.samples},
                               {"min_margin_before", choice.min_margin_before},
                               {"min_margin_after", choice.min_margin_after},
                               {"candidates", tried},
                               {"note",
                                "ψ is the cell's setting (the robot post's rotation about the tool "
                                "axis): the program has no word for it"}};
  if (psi.turns_frames) {
    add_frames_turned(redundancy, im, "one turn of all of them for the whole program");
    if (!psi.per_line_refused.empty())
      redundancy["per_line_refused"] = psi.per_line_refused;
  }
  return redundancy;
}

// `optimization.redundancy`: null when ψ was not searched.
nlohmann::json redundancy_decision_json(const analysis::ProgramImprovement& im) {
  using Kind = analysis::RedundancyDecision::Kind;
  switch (im.redundancy.kind) {
    case Kind::program_frames:
      return program_frames_json(im.redundancy);
    case Kind::per_line:
      return per_line_redundancy_json(im);
    case Kind::single:
      return single_redundancy_json(im);
    case Kind::none:
      break;
  }
  return nullptr;
}

nlohmann::json spindle_choices_json(const analysis::SpindleDecision& spindles) {
  nlohmann::json changes = nlohmann::json::array();
  for (const robot_path::SpindleChoice& c : spindles.choices) {
    const robot_path::SpindleRegion& region = spindles.regions[c.region];
    changes.push_back({{"lines", {region.first_line, region.last_line}},
                       {"tool", region.tool},
                       {"programmed_rpm", std::abs(c.programmed_rad_s) * kRpmPerRadS},
                       {"chosen_rpm", std::abs(c.chosen_rad_s) * kRpmPerRadS},
                       {"samples_judged", c.samples},
                       {"min_margin_before", c.min_margin_before},
                       {"min_margin_after", c.min_margin_after},
                       {"at_risk_before", c.at_risk_before},
                       {"at_risk_after", c.at_risk_after}});
  }
  return changes;
}

nlohmann::json feeds_json(const analysis::FeedDecision& f) {
  nlohmann::json lines = nlohmann::json::array();
  for (const robot_path::LineFeed& line : f.schedule.lines) {
    if (!line.changed() || lines.size() >= 500)
      continue;
    lines.push_back({{"line", line.line},
                     {"programmed_mm_min", line.programmed_m_s * 6e4},
                     {"chosen_mm_min", line.programmed_m_s * line.scale * 6e4},
                     {"binding", line.binding},
                     {"before", loads_json(line.before)},
                     {"after", loads_json(line.after)}});
  }
  return {{"limits",
           {{"force_max_N", f.limits.force_max_n},
            {"torque_max_Nm", f.limits.torque_max_nm},
            {"deflection_max_um", f.limits.deflection_max_m * 1e6},
            {"joint_speed_max_deg_s", f.limits.joint_speed_max_rad_s * kDegPerRad},
            {"feed_min_mm_min", f.limits.feed_min_m_s * 6e4},
            {"feed_max_mm_min", f.limits.feed_max_m_s * 6e4}}},
          {"runs", f.schedule.runs},
          {"lines_with_feed", f.schedule.lines.size()},
          {"lines_changed", f.lines_changed},
          {"lines_slowed", f.lines_slowed},
          {"lines_sped_up", f.lines_changed - f.lines_slowed},
          {"max_before", loads_json(f.schedule.max_before)},
          {"max_after", loads_json(f.schedule.max_after)},
          {"changes", lines},
          {"note",
           "loads per line as measured on runs of the whole program at the chosen "
           "spindle speeds and redundancy angle: 'before' at the programmed feed, "
           "'after' at the chosen one; a line under every cap keeps its feed unless "
           "feed_max lets it run faster"}};
}

// `optimization.after`: the re-run of the improved program.
nlohmann::json after_json(const analysis::AfterRun& a) {
  const robot_path::RobotPathSummary& r = a.robot;
  return {{"min_margin", r.min_margin},
          {"min_margin_line", r.min_margin_line},
          {"chatter_samples", r.chatter},
          {"at_risk_samples", r.at_risk},
          {"fraction_at_risk",
           r.stability_samples > 0 ? static_cast<double>(r.at_risk) / r.stability_samples : 0.0},
          {"max_form_error_um", r.max_form_error_m * 1e6},
          {"max_force_N", a.max_force_n},
          {"max_torque_Nm", a.max_torque_nm},
          {"max_deflection_um", a.max_deflection_m * 1e6},
          {"cycle_time_s", a.cycle_time_s}};
}

nlohmann::json compensation_json(const analysis::CompensationOutcome& c) {
  nlohmann::json skipped = nlohmann::json::array();
  for (const auto& [line, reason] : c.skipped)
    if (skipped.size() < 50)
      skipped.push_back({{"line", line}, {"reason", reason}});
  return {{"floor", c.settings.floor},
          {"min_offset_um", c.settings.min_offset_m * 1e6},
          {"tolerance_um", c.settings.tolerance_m * 1e6},
          {"lines_compensated", c.written.size()},
          {"points_added", c.points_added},
          {"arcs_compensated", c.arcs_compensated},
          {"max_arc_fit_residual_um", c.max_arc_fit_residual_m * 1e6},
          {"lines_skipped", skipped},
          {"max_offset_um", c.max_offset_m * 1e6},
          {"residual_um",
           {{"median", c.residual_m.median * 1e6},
            {"p90", c.residual_m.p90 * 1e6},
            {"max", c.residual_m.max * 1e6}}},
          {"max_residual_um", c.residual_m.max * 1e6},
          {"wall_samples", c.wall_samples},
          {"compensated",
           {{"min_margin", c.compensated.min_margin},
            {"chatter_samples", c.compensated.chatter},
            {"at_risk_samples", c.compensated.at_risk},
            {"max_force_N", c.compensated_max_force_n},
            {"cycle_time_s", c.compensated_cycle_time_s}}},
          {"note",
           "first order: every straight line moved against its samples' predicted error (form "
           "error towards the wall; floor error along the axis with floor) at the feeds and "
           "speeds chosen above, as a polyline within tolerance_um of it; every arc's centre and "
           "radius fitted to its samples' (max_arc_fit_residual_um: what the circle could not "
           "follow); 'after' is the program "
           "before this step, 'compensated' and max_residual_um the written program analysed "
           "again (the residual e' - (p' - p).w against the programmed line at every wall "
           "sample)"},
          {"form_error_before_um",
           {{"median", c.before_m.median * 1e6},
            {"p90", c.before_m.p90 * 1e6},
            {"max", c.before_m.max * 1e6}}},
          {"max_form_error_before_um", c.max_form_error_before_m * 1e6}};
}

// summary.json's `optimization`.
nlohmann::json improvement_json(const analysis::ProgramImprovement& im,
                                const analysis::RobotPathSetup& setup,
                                const analysis::JobDraws* draws) {
  nlohmann::json out = {{"spindle_choices", spindle_choices_json(im.spindles)},
                        {"redundancy", redundancy_decision_json(im)}};
  if (!setup.stability.advice_speeds_rad_s.empty())
    out["speed_range_rpm"] = {setup.stability.advice_speeds_rad_s.front() * kRpmPerRadS,
                              setup.stability.advice_speeds_rad_s.back() * kRpmPerRadS};
  if (im.spindles.unwritable)
    out["note"] =
        "KRL programs carry no spindle speed (the cell's PLC sets it): set the chosen "
        "speeds there; the re-run shows the redundancy angle's and the feeds' effect only";
  if (im.feeds)
    out["feeds"] = feeds_json(*im.feeds);
  if (draws)
    out["risk_note"] =
        "with uncertainty the margins and the samples at risk are the draws': a sample's "
        "margin is the draws' limit at robot_path.max_chatter_probability over ap (at risk: "
        "P(chatter) over the bound), and a candidate speed's or angle's limit the nominal one "
        "there times the ratio of bounded to nominal limit at the programmed point; "
        "'after.uncertainty' is the written program analysed with every draw";

  if (!im.changed) {
    out["changed"] = false;
    out["note"] =
        "no speed in the range raises the smallest margin without putting a safe sample at "
        "risk, and every feed is within the limits: the program is kept";
    return out;
  }
  const analysis::AfterRun& a = *im.after;
  out["changed"] = true;
  out["program"] = im.name;
  out["after"] = after_json(a);
  out["cycle_time_before_s"] = im.cycle_time_before_s;
  out["samples_newly_at_risk"] = a.newly_at_risk;
  out["first_newly_at_risk_line"] = a.first_newly_at_risk_line;
  out["samples_relieved"] = a.relieved;
  out["samples_compared"] = a.compared;
  out["samples_before"] = im.samples_before;
  out["after"]["redundancy_deg"] = a.redundancy_rad * kDegPerRad;
  out["after"]["max_joint_speed_deg_s"] = a.max_joint_speed_rad_s * kDegPerRad;
  if (draws) {
    // The written program with every draw: P(chatter) measured, and the
    // lines still over the bound where no speed or ψ could bring them under.
    out["after"]["uncertainty"] =
        path_uncertainty_json(*draws, setup.settings.max_chatter_probability, a.robot);
  }
  if (im.compensation)
    out["compensation"] = compensation_json(*im.compensation);
  if (!im.text)
    out["program"] = nullptr;  // only ψ changed: the program itself is the same
  return out;
}

io::CsvTable redundancy_schedule_table(const robot_path::RedundancySchedule& schedule) {
  io::CsvTable table({"line", "first_move", "last_move", "from_deg", "to_deg", "turn",
                      "turn_joint_speed_deg_s", "min_margin", "samples"});
  for (const auto& line : schedule.lines) {
    table.add_cells({static_cast<double>(line.line), static_cast<double>(line.first_move + 1),
                     static_cast<double>(line.last_move + 1), line.from_rad * kDegPerRad,
                     line.to_rad * kDegPerRad, std::string(redundancy_turn(line)),
                     line.turn_joint_speed_rad_s * kDegPerRad, line.min_margin,
                     static_cast<double>(line.samples)});
  }
  return table;
}

// The improvement's files: redundancy_schedule.csv when ψ changes per line,
// the written program (and its .dat) when the program changed.
void add_improvement_files(const analysis::ProgramImprovement& im, CommandResult& result) {
  using Kind = analysis::RedundancyDecision::Kind;
  if (im.redundancy.kind == Kind::per_line) {
    // Built whether or not ψ changed: its rows are checked (finite) either way.
    io::CsvTable table = redundancy_schedule_table(*im.redundancy.schedule);
    if (im.redundancy.schedule->changed())
      result.tables.emplace_back("redundancy_schedule", std::move(table));
  }
  if (!im.changed)
    return;
  if (im.text)
    result.texts.emplace_back(im.name, *im.text);
  if (im.dat_text)
    result.texts.emplace_back("program_optimized.dat", *im.dat_text);
}

std::string redundancy_message(const analysis::RedundancyDecision& psi) {
  using Kind = analysis::RedundancyDecision::Kind;
  std::string message;
  if (psi.kind == Kind::program_frames) {
    message += "  optimize: the program's frames fix ψ; redundancy_search not applied" +
               (psi.frames_refused.empty() ? std::string() : " (" + psi.frames_refused + ")") +
               "\n";
  } else if (psi.kind == Kind::per_line) {
    const robot_path::RedundancySchedule& schedule = *psi.schedule;
    if (schedule.changed())
      message += fmt::format(
          "  optimize: {} per line, {} turns (min margin {:.2f} -> {:.2f} at the programmed "
          "speeds)\n",
          psi.turns_frames ? "the program's frames turned about the tool axis" : "redundancy angle",
          schedule.turns, schedule.min_margin_before, schedule.min_margin_after);
  } else if (psi.kind == Kind::single) {
    const robot_path::RedundancyChoice& choice = *psi.choice;
    if (psi.turns_frames && !psi.per_line_refused.empty())
      message +=
          "  optimize: one turn of all frames instead of one per line: " + psi.per_line_refused +
          "\n";
    if (choice.changed())
      message += fmt::format(
          "  optimize: {} {:.0f} -> {:.0f} deg (min margin {:.2f} "
          "-> {:.2f} at the programmed speeds)\n",
          psi.turns_frames ? "the program's frames turned about the tool axis,"
                           : "redundancy angle",
          choice.programmed_rad * kDegPerRad, choice.chosen_rad * kDegPerRad,
          choice.min_margin_before, choice.min_margin_after);
  }
  return message;
}

std::string compensation_message(const analysis::CompensationOutcome& c) {
  std::string message;
  if (!c.skipped.empty())
    message += fmt::format("  optimize: {} lines not compensated (first: line {}, {})\n",
                           c.skipped.size(), c.skipped.front().first, c.skipped.front().second);
  message += fmt::format(
      "  optimize: {} lines compensated ({} arcs, {} points added); the walls' largest error "
      "-> {:.1f} um (measured on the written program)\n",
      c.written.size(), c.arcs_compensated, c.points_added, c.residual_m.max * 1e6);
  return message;
}

// The message's optimize lines.
std::string improvement_message(const analysis::ProgramImprovement& im,
                                const analysis::RobotPathSetup& setup,
                                const analysis::JobDraws* draws) {
  std::string message = redundancy_message(im.redundancy);
  if (im.feeds) {
    const analysis::FeedDecision& f = *im.feeds;
    message += fmt::format(
        "  optimize: feeds of {} of {} lines changed ({} slowed, {} sped up) in {} runs of the "
        "program\n",
        f.lines_changed, f.schedule.lines.size(), f.lines_slowed, f.lines_changed - f.lines_slowed,
        f.schedule.runs);
  }
  if (!im.changed)
    return message + "  optimize: nothing to change; the program is kept\n";
  const analysis::AfterRun& a = *im.after;
  const robot_path::RobotPathSummary& r = a.robot;
  if (im.compensation)
    message += compensation_message(*im.compensation);
  message += fmt::format(
      "  optimize: {}; chatter samples {} -> {}, min margin -> {:.2f}, {} samples no longer at "
      "risk, {} newly at risk; cycle time {:.1f} -> {:.1f} s\n",
      im.text ? im.name + " written" : std::string("the program is kept"), im.chatter_before,
      r.chatter, r.min_margin, a.relieved, a.newly_at_risk, im.cycle_time_before_s, a.cycle_time_s);
  if (draws) {
    message +=
        "  after:" + path_uncertainty_message(setup.settings.max_chatter_probability, r).substr(1);
  }
  return message;
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
