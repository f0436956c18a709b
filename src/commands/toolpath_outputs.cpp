// What `robomill toolpath` writes about the draws of the uncertain inputs
// and about --optimize's better program (toolpath_outputs.hpp).

#include "toolpath_outputs.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "robomill/core/constants.hpp"
#include "robomill/io/csv.hpp"

namespace robomill::commands::detail {

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

namespace {

nlohmann::json loads_json(const robot_path::MoveLoads& loads) {
  return {{"force_peak_N", loads.force_peak_n},
          {"torque_peak_Nm", loads.torque_peak_nm},
          {"deflection_um", loads.deflection_m * 1e6},
          {"joint_speed_deg_s", loads.joint_speed_rad_s * kDegPerRad}};
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

}  // namespace

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

namespace {

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

}  // namespace

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

namespace {

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

}  // namespace

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

}  // namespace robomill::commands::detail
