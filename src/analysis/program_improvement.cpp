// `robomill toolpath --optimize` (analysis/program_improvement.hpp): ψ, the
// spindle speeds, the feeds and the compensation chosen from the first run,
// the program written back, read back and analysed again.

#include "robomill/analysis/program_improvement.hpp"
#include "robomill/analysis/program_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <set>

#include "robomill/analysis/program_run.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/krl_frame_turn.hpp"
#include "robomill/io/krl_point_edits.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/io/program_writer.hpp"

namespace robomill::analysis {
namespace {

std::string program_extension(const job::ToolpathSettings& settings) {
  const std::string extension = settings.file.extension().string();
  return extension.empty() ? ".nc" : extension;
}

// Writes `text` to a scratch file and reads it back with the program's own
// reader (the written program must parse as it will on the cell).
// With `dat`, a KRL program's .dat goes next to it.
toolpath::Program read_back(const job::ToolpathSettings& settings, const std::string& text,
                            const std::filesystem::path& scratch_file, std::size_t expected_moves,
                            const std::string* dat = nullptr) {
  const std::filesystem::path scratch_dat =
      std::filesystem::path(scratch_file).replace_extension(".dat");
  const auto write = [](const std::filesystem::path& file, const std::string& content) {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out << content;
    if (!out)
      throw Error("cannot write " + file.string());
  };
  const auto remove = [&] {
    std::error_code ignored;
    std::filesystem::remove(scratch_file, ignored);
    if (dat)
      std::filesystem::remove(scratch_dat, ignored);
  };
  job::ToolpathSettings again = settings;
  again.file = scratch_file;
  toolpath::Program program;
  try {
    write(scratch_file, text);
    if (dat) {
      write(scratch_dat, *dat);
      again.dat_file = scratch_dat;
    }
    program = analysis::read_program(again);
  } catch (...) {
    remove();
    throw;
  }
  remove();
  if (program.moves.size() != expected_moves)
    throw Error(fmt::format("the written program reads back as {} moves, the original as {}",
                            program.moves.size(), expected_moves));
  return program;
}

// The feed edits of a schedule: each changed line rescaled with a comment
// naming the binding cap and the loads before and after, and the restores
// (io::with_feed_restores).
std::vector<io::FeedEdit> feed_edits(const toolpath::Program& program,
                                     const robot_path::FeedSchedule& schedule,
                                     const robot_path::FeedLimits& limits) {
  std::vector<io::FeedEdit> changed;
  for (const robot_path::LineFeed& line : schedule.lines) {
    if (!line.changed())
      continue;
    const robot_path::MoveLoads& b = line.before;
    const robot_path::MoveLoads& a = line.after;
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

// A KRL program's frames turned for a schedule ψ(s), and the turn each move
// then ends at (what the written program runs).
struct FrameTurns {
  std::map<toolpath::FrameSite, io::KrlFrameEdit> edits;
  std::vector<double> end_turn_rad;  ///< per move
  /// (start, end) turn of every move: the schedule where it cuts.
  std::vector<std::pair<double, double>> by_move() const {
    std::vector<std::pair<double, double>> out(end_turn_rad.size());
    for (std::size_t m = 0; m < out.size(); ++m)
      out[m] = {m == 0 ? first_turn_rad : end_turn_rad[m - 1], end_turn_rad[m]};
    return out;
  }
  double first_turn_rad = 0.0;
};

// Each KRL frame's turn for a schedule ψ(s) (`by_move`: the turn at the
// start and the end of every move). Where it matters — the frames the cut
// lines end at and the frame before each (its start) — a frame takes the
// schedule's turn; the air moves' frames follow it where that conflicts with
// nothing (a home point used at the start and the end keeps its first
// turn). A frame written without all of A, B, C keeps the orientation before
// it, so it is completed only where its move must turn. nullopt, with `why`,
// where the points do not allow the schedule: one aggregate ending cut
// moves at different turns (a FOR loop over one point), or a cut move that
// turns with an end frame computed (a _REL move, a CIRC with CA).
std::optional<FrameTurns> frame_turns(const toolpath::Program& program,
                                      const robot_path::RedundancySchedule& schedule,
                                      std::string& why) {
  const std::size_t n = program.moves.size();
  const std::vector<std::pair<double, double>> by_move = schedule.by_move(n);
  std::vector<char> required(n, 0);
  for (const robot_path::RedundancySchedule::Line& line : schedule.lines) {
    for (std::size_t m = line.first_move; m <= line.last_move && m < n; ++m)
      required[m] = 1;
    if (line.first_move > 0 && line.first_move - 1 < n)
      required[line.first_move - 1] = 1;
  }
  auto source_of = [&](std::size_t m) -> const std::optional<toolpath::FrameSource>& {
    static const std::optional<toolpath::FrameSource> none;
    return m < program.frame_sources.size() ? program.frame_sources[m] : none;
  };
  FrameTurns out;
  auto assign = [&](const toolpath::FrameSource& source, double turn_rad, int line, bool must) {
    io::KrlFrameEdit edit{turn_rad, std::nullopt};
    if (!source.complete)
      edit.in_force_abc_deg = source.abc_deg;
    const auto [it, added] = out.edits.emplace(source.site, edit);
    if (!added && std::abs(it->second.turn_rad - turn_rad) > 1e-12 && must) {
      why = fmt::format("the point on {} line {} ends moves at {:.1f} and {:.1f} deg (line {})",
                        source.site.in_dat ? ".dat" : ".src", source.site.line,
                        it->second.turn_rad * kDegPerRad, turn_rad * kDegPerRad, line);
      return false;
    }
    return true;
  };
  // The cut's complete frames first, then the air moves' where free.
  for (const bool must : {true, false})
    for (std::size_t m = 0; m < n && m < by_move.size(); ++m)
      if (const auto& source = source_of(m);
          source && source->complete && static_cast<bool>(required[m]) == must &&
          !assign(*source, by_move[m].second, program.moves[m].line, must))
        return std::nullopt;
  if (program.first_frame && program.first_frame->complete && !by_move.empty())
    assign(*program.first_frame, by_move.front().first, 0, false);
  // What each move ends at, in program order; frames without all of A, B, C
  // completed where a cut move must turn.
  out.first_turn_rad = 0.0;
  if (program.first_frame && program.first_frame->complete)
    out.first_turn_rad = out.edits.at(program.first_frame->site).turn_rad;
  double previous = out.first_turn_rad;
  out.end_turn_rad.resize(n);
  for (std::size_t m = 0; m < n; ++m) {
    const auto& source = source_of(m);
    const double want = by_move[m].second;
    double end = previous;  // inherited: a partial frame, a _REL move, a dwell
    if (source && source->complete) {
      end = out.edits.at(source->site).turn_rad;
    } else if (source && (required[m] && std::abs(previous - want) > 1e-12)) {
      if (!assign(*source, want, program.moves[m].line, true))
        return std::nullopt;
      end = want;
    } else if (source && out.edits.count(source->site)) {
      end = out.edits.at(source->site).turn_rad;  // completed for an earlier run of it
    }
    if (required[m] && std::abs(end - want) > 1e-12) {
      why = fmt::format(
          "line {} turns ψ but its end frame is computed (a _REL move or a CIRC "
          "with CA)",
          program.moves[m].line);
      return std::nullopt;
    }
    out.end_turn_rad[m] = previous = end;
  }
  return out;
}

// A round's corrections as point edits in the program's frame (`to_program`
// turns workpiece offsets into it), each with its comment.
std::vector<io::PointEdit> point_edits_of(const std::vector<robot_path::LineCorrection>& all,
                                          const Eigen::Matrix3d& to_program) {
  std::vector<io::PointEdit> point_edits;
  for (const robot_path::LineCorrection& c : all) {
    io::PointEdit edit{c.line, to_program * c.offset_m, {}, "", std::nullopt};
    double largest = c.offset_m.norm();
    for (const robot_path::CorrectionPoint& p : c.points) {
      edit.points.push_back({p.u, to_program * p.offset_m});
      largest = std::max(largest, p.offset_m.norm());
    }
    if (c.arc) {
      edit.arc = io::PointEdit::Arc{to_program * c.arc->centre_offset_m, c.arc->radius_change_m};
      edit.comment = fmt::format(
          "robomill: compensated arc, radius {:+.1f} um, centre moved {:.1f} um, within {:.1f} "
          "um of the predicted error",
          c.arc->radius_change_m * 1e6, c.arc->centre_offset_m.norm() * 1e6,
          c.arc->fit_residual_m * 1e6);
    } else {
      edit.comment = fmt::format(
          "robomill: compensated, up to {:.1f} um against the predicted error", largest * 1e6);
    }
    point_edits.push_back(std::move(edit));
  }
  return point_edits;
}

// A KRL program's points moved where they are written, move by move
// (io/krl_point_edits.hpp), in the program frame: the .src into `edited`,
// the .dat into `dat_edited`.
void write_krl_edits(const std::string& text, const std::string* dat,
                     const toolpath::Program& in_program_frame,
                     const std::vector<robot_path::LineCorrection>& all,
                     const std::vector<io::PointEdit>& point_edits, io::PointEditResult& edited,
                     std::string& dat_edited) {
  std::vector<robot_path::LineCorrection> in_program;
  std::vector<std::string> comments;
  for (std::size_t i = 0; i < all.size(); ++i) {
    robot_path::LineCorrection c = all[i];
    c.offset_m = point_edits[i].offset_m;
    for (std::size_t k = 0; k < c.points.size(); ++k)
      c.points[k].offset_m = point_edits[i].points[k].offset_m;
    in_program.push_back(std::move(c));
    comments.push_back(point_edits[i].comment);
  }
  io::KrlPointEdits krl_edits =
      io::write_krl_point_edits(text, dat ? std::string_view(*dat) : std::string_view(),
                                in_program_frame, in_program, comments);
  edited.text = std::move(krl_edits.src);
  edited.skipped = std::move(krl_edits.skipped);
  dat_edited = std::move(krl_edits.dat);
}

// The lines written and the lines kept as programmed, with why, into the
// outcome.
void record_written(const robot_path::PathCorrections& collected, const toolpath::Program& program,
                    const std::set<int>& keep, const robot_path::WritableMoves* writable,
                    const std::map<int, std::string>& skipped,
                    const std::vector<robot_path::LineCorrection>& all,
                    CompensationOutcome& outcome) {
  // Lines with an error the compensation leaves as programmed, and why; a
  // line the writer skipped in an earlier round keeps that round's reason.
  std::map<int, std::string> kept;
  for (const robot_path::PathCorrections::Kept& k : collected.kept(program, keep, writable))
    kept.emplace(k.line, k.reason);
  kept.insert(skipped.begin(), skipped.end());  // a line both kept and skipped: one reason
  outcome.skipped.assign(kept.begin(), kept.end());
  for (const robot_path::LineCorrection& c : all) {
    outcome.written.push_back(c);
    outcome.points_added += c.points.size();
    outcome.max_offset_m = std::max(outcome.max_offset_m, c.offset_m.norm());
    for (const robot_path::CorrectionPoint& p : c.points)
      outcome.max_offset_m = std::max(outcome.max_offset_m, p.offset_m.norm());
    if (c.arc) {
      ++outcome.arcs_compensated;
      outcome.max_arc_fit_residual_m =
          std::max(outcome.max_arc_fit_residual_m, c.arc->fit_residual_m);
    }
  }
}

// The compensated program as read back checked move by move against the
// corrected path (`expected` ends, arcs' centres); returns which programmed
// move each written move stands for (a compensated line's added points and
// its end all stand for it).
std::vector<std::size_t> check_corrected(const toolpath::Program& program,
                                         const toolpath::Program& corrected,
                                         const std::vector<robot_path::LineCorrection>& written,
                                         const std::vector<Eigen::Vector3d>& expected) {
  std::map<std::size_t, const robot_path::LineCorrection*> correction_of;
  for (const robot_path::LineCorrection& c : written)
    correction_of[c.move] = &c;
  std::vector<std::size_t> original(corrected.moves.size());
  {
    std::size_t w = 0;
    for (std::size_t m = 0; m < program.moves.size(); ++m) {
      const auto it = correction_of.find(m);
      const std::size_t count = it == correction_of.end() ? 1 : it->second->points.size() + 1;
      for (std::size_t k = 0; k < count && w < original.size(); ++k)
        original[w++] = m;
    }
  }
  for (std::size_t m = 0; m < corrected.moves.size(); ++m) {
    const toolpath::Move& move = corrected.moves[m];
    if ((move.end_m - expected[m]).norm() > 1e-6)
      throw Error(fmt::format(
          "the compensated program's line {} ends at [{:.4f}, {:.4f}, {:.4f}] mm, not the "
          "intended [{:.4f}, {:.4f}, {:.4f}] mm; nothing was written",
          move.line, move.end_m.x() * 1e3, move.end_m.y() * 1e3, move.end_m.z() * 1e3,
          expected[m].x() * 1e3, expected[m].y() * 1e3, expected[m].z() * 1e3));
    // An arc's circle where it was meant to be (its centre in its plane):
    // moved by its correction, or as programmed.
    const toolpath::Move& nominal = program.moves[original[m]];
    if (move.kind != toolpath::MotionKind::arc || nominal.kind != toolpath::MotionKind::arc)
      continue;
    const auto it = correction_of.find(original[m]);
    Eigen::Vector3d miss =
        move.centre_m - nominal.centre_m -
        (it != correction_of.end() && it->second->arc ? it->second->arc->centre_offset_m
                                                      : Eigen::Vector3d(Eigen::Vector3d::Zero()));
    miss -= miss.dot(nominal.normal) * nominal.normal;
    if (miss.norm() > 1e-6)
      throw Error(fmt::format(
          "the compensated program's arc on line {} has its centre {:.4f} mm from the intended "
          "one; nothing was written",
          move.line, miss.norm() * 1e3));
  }
  return original;
}

// The robot settings of the compensated program. A redundancy schedule
// follows the moves a compensated line became (ψ linear along the programmed
// line: each part takes its stretch of it).
robot_path::RobotPathSettings corrected_robot_settings(
    const robot_path::RobotPathSettings& robot_settings, bool krl,
    const std::vector<robot_path::LineCorrection>& written, const toolpath::Program& program) {
  robot_path::RobotPathSettings corrected_settings = robot_settings;
  if (krl) {  // the written frames carry any turn of ψ already
    corrected_settings.frame_turn_rad = 0.0;
    corrected_settings.redundancy_by_move.clear();
  }
  if (!corrected_settings.redundancy_by_move.empty()) {
    std::map<std::size_t, std::vector<double>> cuts;  // 0, the points' u, 1
    for (const robot_path::LineCorrection& c : written) {
      std::vector<double>& u = cuts[c.move];
      u.push_back(0.0);
      for (const robot_path::CorrectionPoint& p : c.points)
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
  return corrected_settings;
}

// How far the written program moved a sample off the programmed move it
// stands for, along the wall's normal w': (p' − p)·w' with p the nearest
// point of a line, or an arc's point at the same fraction of its sweep.
double programmed_shift(const toolpath::Move& nominal, const toolpath::PathSample& sample,
                        const robot_path::RobotSample& r) {
  double shift = 0.0;
  if (nominal.kind == toolpath::MotionKind::arc) {
    shift =
        (sample.tip_m - toolpath::position_at(nominal, sample.move_fraction)).dot(r.wall_direction);
  } else if (nominal.kind == toolpath::MotionKind::linear) {
    const Eigen::Vector3d d = nominal.end_m - nominal.start_m;
    const double t =
        d.squaredNorm() > 0.0
            ? std::clamp((sample.tip_m - nominal.start_m).dot(d) / d.squaredNorm(), 0.0, 1.0)
            : 0.0;
    shift = (sample.tip_m - (nominal.start_m + t * d)).dot(r.wall_direction);
  }
  return shift;
}

// The deflection compensation (robot_path/deflection_compensation.hpp) of the
// program the improvement has written: the corrections collected on its
// analysis (the after-run), written in the program's own frame and units,
// read back and checked move by move against the corrected path, then
// analysed once more for the residual against the path the CAM wrote.
CompensationOutcome compensate_program(const job::Job& job, const analysis::RobotPathSetup& setup,
                                       const toolpath::Tooling& tooling,
                                       const robot_path::RobotPathSettings& robot_settings,
                                       const toolpath::ProgramAnalysisSettings& analysis_settings,
                                       const robot_path::PathCorrections& collected,
                                       const toolpath::Program& program, std::string& text,
                                       std::string* dat,
                                       const std::filesystem::path& scratch_file) {
  const job::ToolpathSettings& settings = *job.toolpath;
  CompensationOutcome outcome;
  // A KRL program: its points move where they are written, move by move
  // (io/krl_point_edits.hpp), in the program frame.
  const bool krl = settings.format == job::ToolpathSettings::Format::krl;
  std::optional<robot_path::WritableMoves> writable;
  toolpath::Program in_program_frame;
  if (krl) {
    writable = io::krl_writable_moves(program);
    in_program_frame = program;
    toolpath::apply_transform(in_program_frame, settings.program_to_workpiece.inverse());
  }
  // Workpiece frame → the program's own (the readers applied
  // toolpath.origin/orientation): offsets turn back by its rotation.
  const Eigen::Matrix3d to_program = settings.program_to_workpiece.linear().transpose();
  // Written, then the lines the writer could not edit kept as programmed and
  // the rest chosen again (a line's start is where the line before was
  // written to end, an arc's centre is programmed from its start), until
  // the writer edits every line asked.
  std::set<int> keep;
  std::map<int, std::string> skipped;  // line → the writer's reason, every round
  std::vector<robot_path::LineCorrection> all;
  io::PointEditResult edited;
  std::string dat_edited = dat ? *dat : std::string();
  for (;;) {
    all = collected.corrections(program, keep, writable ? &*writable : nullptr);
    std::vector<io::PointEdit> point_edits = point_edits_of(all, to_program);
    if (krl)
      write_krl_edits(text, dat, in_program_frame, all, point_edits, edited, dat_edited);
    else
      edited = io::write_point_edits(text, settings.format, point_edits, settings.units);
    if (edited.skipped.empty())
      break;
    for (const auto& s : edited.skipped) {
      keep.insert(s.line);
      skipped.emplace(s.line, s.reason);
    }
  }
  record_written(collected, program, keep, writable ? &*writable : nullptr, skipped, all, outcome);
  const std::vector<robot_path::LineCorrection>& written = outcome.written;
  const std::vector<Eigen::Vector3d> expected = robot_path::corrected_ends(program, written);
  const toolpath::Program corrected =
      read_back(settings, edited.text, scratch_file, expected.size(), dat ? &dat_edited : nullptr);
  const std::vector<std::size_t> original = check_corrected(program, corrected, written, expected);

  // The written program analysed: each wall sample's error against the
  // programmed move it stands for, e' − (p' − p)·w' (programmed_shift).
  toolpath::ProgramAnalysisSettings again = analysis_settings;
  again.move_spacing_m.clear();  // the written program has moves of its own
  again.move_steps.clear();
  const robot_path::RobotPathSettings corrected_settings =
      corrected_robot_settings(robot_settings, krl, written, program);
  robot_path::RobotAlongPath along(*setup.model, setup.structure, tooling, *job.cutting,
                                   setup.stability, corrected_settings);
  toolpath::DexelStock stock = job_stock(job);
  std::vector<robot_path::RobotSample> block_out;
  std::vector<double> residuals_m;  // |e' − (p' − p)·w'| at every wall sample
  const toolpath::ProgramAnalysis analysis = toolpath::analyse_program(
      corrected, tooling, *job.cutting, stock, again,
      [&](std::span<const toolpath::PathSample> block) {
        block_out.resize(block.size());
        along.evaluate(block, block_out);
        for (std::size_t i = 0; i < block.size(); ++i) {
          const robot_path::RobotSample& r = block_out[i];
          const toolpath::PathSample& sample = block[i];
          if (!r.wall || !r.reachable || !sample.analysed ||
              sample.kind == toolpath::MotionKind::rapid)
            continue;
          const toolpath::Move& nominal = program.moves[original[sample.move]];
          const double shift = programmed_shift(nominal, sample, r);
          residuals_m.push_back(std::abs(r.form_error_m - shift));
        }
      });
  outcome.compensated = along.finish();
  outcome.residual_m = percentiles(residuals_m);
  outcome.wall_samples = residuals_m.size();
  outcome.compensated_max_force_n = analysis.max_force_n;
  outcome.compensated_cycle_time_s =
      analysis.cutting_time_s + analysis.air_time_s + analysis.dwell_time_s;
  text = edited.text;
  if (dat)
    *dat = std::move(dat_edited);
  return outcome;
}

}  // namespace

void FirstRunRecord::add(const toolpath::PathSample& sample, const robot_path::RobotSample& robot) {
  // With draws the choices keep P(chatter) within the bound: the margin and
  // the risk are the draws' limit at the bound's (program_optimization.hpp).
  const bool risk = robot.at_risk_to_optimize();
  at_risk.push_back(robot.stability ? (risk ? 1 : 0) : 2);
  if (!robot.stability || !(robot.exact || risk) || recorded.size() >= kMaxRecorded)
    return;
  robot_path::RecordedSample r{sample, robot.q_rad, robot.margin};
  if (robot.drawn && robot.depth_limit_m > 0.0) {
    r.bound_ratio = robot.depth_limit_at_bound_m / robot.depth_limit_m;
    r.margin = robot.depth_limit_at_bound_m / sample.axial_depth_m;
  }
  recorded.push_back(r);
}

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

namespace {

std::string read_whole_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The bound on every turn of a schedule.
double joint_speed_max_rad_s(const job::Job& job) {
  return job.robot_path->redundancy_joint_speed_rad_s > 0.0
             ? job.robot_path->redundancy_joint_speed_rad_s
         : job.robot_path->feed_limits && job.robot_path->feed_limits->joint_speed_max_rad_s > 0.0
             ? job.robot_path->feed_limits->joint_speed_max_rad_s
             : 10.0 / kDegPerRad;
}

// ψ: kept, one angle, or one per line (robot_path.redundancy_search), set in
// `after_settings`; a KRL program's frames turned where they all can be.
// The recorded samples are re-posed at the chosen ψ.
void choose_redundancy(const job::Job& job, const toolpath::Program& program,
                       const robot_path::RobotAlongPath& before, const std::string& text,
                       const std::string& dat_text, int threads,
                       std::vector<robot_path::RecordedSample>& recorded,
                       robot_path::RobotPathSettings& after_settings, RedundancyDecision& psi) {
  const job::ToolpathSettings& settings = *job.toolpath;
  const bool oriented = std::any_of(program.moves.begin(), program.moves.end(),
                                    [](const toolpath::Move& m) { return m.oriented; });
  const bool search = job.robot_path && !job.robot_path->redundancy_search_rad.empty();
  const bool krl = settings.format == job::ToolpathSettings::Format::krl;
  if (search && oriented) {
    // The frames set ψ: a KRL program's can be turned, each Cartesian
    // point's A, B, C (io/krl_frame_turn.hpp), where every one of them can.
    const io::KrlFrameTurn trial =
        krl ? io::turn_krl_frames(text, dat_text, 0.0, settings.tool_direction)
            : io::KrlFrameTurn{};
    if (!krl || !trial.refused.empty()) {
      psi.kind = RedundancyDecision::Kind::program_frames;
      if (!trial.refused.empty())
        psi.frames_refused =
            fmt::format("{} line {}: {}",
                        trial.refused.front().file == "dat" ? settings.dat_file.filename().string()
                                                            : settings.file.filename().string(),
                        trial.refused.front().line, trial.refused.front().reason);
    } else {
      psi.turns_frames = true;
      if (job.robot_path->redundancy_per_line) {
        // ψ(s) per line, each point's frame turned by the angle of the line
        // that ends at it, where the points allow (one point, one angle).
        std::vector<robot_path::RecordedSample> posed = recorded;
        robot_path::RedundancySchedule schedule = robot_path::schedule_redundancy(
            before, program, posed, job.robot_path->redundancy_search_rad,
            joint_speed_max_rad_s(job), 0.02, threads);
        const std::optional<FrameTurns> turns =
            schedule.changed() ? frame_turns(program, schedule, psi.per_line_refused)
                               : FrameTurns{};
        if (turns) {
          psi.kind = RedundancyDecision::Kind::per_line;
          psi.joint_speed_max_rad_s = joint_speed_max_rad_s(job);
          psi.frame_turns = turns->edits;
          if (schedule.changed()) {
            after_settings.redundancy_by_move = turns->by_move();
            recorded = std::move(posed);
          }
          psi.schedule = std::move(schedule);
        }
      }
      if (!psi.schedule) {
        psi.kind = RedundancyDecision::Kind::single;
        psi.choice = robot_path::choose_redundancy_angle(
            before, recorded, job.robot_path->redundancy_search_rad, 0.02, threads);
        after_settings.frame_turn_rad = psi.choice->chosen_rad;
      }
    }
  } else if (search && job.robot_path->redundancy_per_line) {
    // ψ(s): one angle per program line, turning between lines within the
    // joint-speed bound.
    psi.kind = RedundancyDecision::Kind::per_line;
    psi.joint_speed_max_rad_s = joint_speed_max_rad_s(job);
    psi.schedule = robot_path::schedule_redundancy(before, program, recorded,
                                                   job.robot_path->redundancy_search_rad,
                                                   psi.joint_speed_max_rad_s, 0.02, threads);
    if (psi.schedule->changed())
      after_settings.redundancy_by_move = psi.schedule->by_move(program.moves.size());
  } else if (search) {
    psi.kind = RedundancyDecision::Kind::single;
    psi.choice = robot_path::choose_redundancy_angle(
        before, recorded, job.robot_path->redundancy_search_rad, 0.02, threads);
    after_settings.redundancy_rad = psi.choice->chosen_rad;
  }
}

// The spindle speeds chosen at the postures of ψ, and their edits (none
// where they are not written: a KRL program carries no spindle speed, the
// cell's PLC sets it, so the choices are reported, not written).
std::vector<io::SpindleEdit> choose_spindles(const toolpath::Program& program,
                                             const analysis::RobotPathSetup& setup,
                                             const robot_path::RobotAlongPath& before,
                                             std::vector<robot_path::RecordedSample>& recorded,
                                             const robot_path::RobotPathSettings& after_settings,
                                             bool redundancy_changed, bool krl, int threads,
                                             SpindleDecision& spindles) {
  spindles.regions = robot_path::spindle_regions(program);
  if (!setup.stability.advice_speeds_rad_s.empty())
    spindles.choices = robot_path::choose_spindle_speeds(
        before, spindles.regions, recorded, setup.stability.advice_speeds_rad_s, 0.02, threads);
  std::vector<io::SpindleEdit> edits;
  for (const robot_path::SpindleChoice& c : spindles.choices) {
    if (!c.changed())
      continue;
    const robot_path::SpindleRegion& region = spindles.regions[c.region];
    const double from_rpm = std::abs(c.programmed_rad_s) * kRpmPerRadS;
    const double to_rpm = std::abs(c.chosen_rad_s) * kRpmPerRadS;
    edits.push_back({region.first_line, c.chosen_rad_s,
                     fmt::format("robomill: S{:.0f} -> S{:.0f} for lines {}-{}, min stability "
                                 "margin {:.2f} -> {:.2f}",
                                 from_rpm, to_rpm, region.first_line, region.last_line,
                                 c.min_margin_before, c.min_margin_after)});
    edits.push_back({region.last_line + 1, c.programmed_rad_s,
                     fmt::format("robomill: back to the programmed S{:.0f}", from_rpm)});
  }
  if (redundancy_changed && !edits.empty())
    edits.front().comment +=
        after_settings.redundancy_by_move.empty()
            ? fmt::format("; run with the redundancy angle {:.0f} deg",
                          after_settings.redundancy_rad * kDegPerRad)
            : std::string("; run with the redundancy angles of redundancy_schedule.csv");

  // KRL programs carry no spindle speed (the cell's PLC sets it): the
  // choices are reported, not written.
  spindles.unwritable = !edits.empty() && krl;
  spindles.written = !edits.empty() && !krl;
  if (!spindles.written)
    edits.clear();
  return edits;
}

// The program as it will run with the chosen speeds (the spindle edits
// written and read back). Its moves keep the original program's line
// numbers (the inserted S blocks shift the written text's), which the feed
// edits and errors name. Feeds are set per statement: a move on a line that
// continues an APT record (a '$' continuation, a GOTO's further points)
// belongs to the record's first line, where a FEDRAT can go.
toolpath::Program program_with_speeds(const job::ToolpathSettings& settings,
                                      const toolpath::Program& program, const std::string& text,
                                      const std::vector<io::SpindleEdit>& edits, bool written,
                                      const std::filesystem::path& scratch_file) {
  toolpath::Program with_speeds =
      written ? read_back(settings, io::write_spindle_edits(text, settings.format, edits),
                          scratch_file, program.moves.size())
              : program;
  const std::vector<int> starts = io::statement_starts(text, settings.format);
  for (std::size_t m = 0; m < with_speeds.moves.size(); ++m) {
    const int line = program.moves[m].line;
    with_speeds.moves[m].line =
        line > 0 && static_cast<std::size_t>(line) < starts.size() ? starts[line] : line;
  }
  return with_speeds;
}

// The feeds (robot_path.feed_limits), on the program with the chosen speeds
// at the chosen ψ: the decision, each move's feed scale and the edits.
std::vector<io::FeedEdit> choose_feeds(const job::Job& job, const analysis::RobotPathSetup& setup,
                                       const toolpath::Tooling& tooling,
                                       const robot_path::RobotPathSettings& after_settings,
                                       const toolpath::ProgramAnalysisSettings& analysis_settings,
                                       const toolpath::Program& with_speeds,
                                       std::optional<FeedDecision>& feed_decision,
                                       std::vector<double>& feed_scale) {
  std::vector<io::FeedEdit> feeds;
  if (job.robot_path && job.robot_path->feed_limits) {
    FeedDecision& decision = feed_decision.emplace();
    decision.limits = *job.robot_path->feed_limits;
    const toolpath::DexelStock stock = job_stock(job);
    robot_path::PathStabilitySettings no_limits = setup.stability;
    no_limits.enabled = false;  // the feed does not move the stable depth
    const auto make_robot = [&] {
      return std::make_unique<robot_path::RobotAlongPath>(*setup.model, setup.structure, tooling,
                                                          *job.cutting, no_limits, after_settings);
    };
    decision.schedule =
        robot_path::schedule_feeds(with_speeds, decision.limits, [&](const std::vector<double>& s) {
          return robot_path::measure_move_loads(with_speeds, s, tooling, *job.cutting, stock,
                                                analysis_settings, make_robot);
        });
    feeds = feed_edits(with_speeds, decision.schedule, decision.limits);
    for (const robot_path::LineFeed& line : decision.schedule.lines) {
      for (std::size_t m : line.moves)
        feed_scale[m] = line.scale;
      if (!line.changed())
        continue;
      ++decision.lines_changed;
      decision.lines_slowed += line.scale < 1.0 ? 1 : 0;
    }
  }
  return feeds;
}

// Every move of the written program read back at the chosen feed and speed.
void check_read_back(const toolpath::Program& rewritten, const toolpath::Program& with_speeds,
                     const std::vector<double>& feed_scale) {
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
}

// The written program analysed again (a fresh stock, the samples where the
// first run put them) at the chosen ψ: the after-run, compared sample by
// sample with the first run's record; with compensation, the corrections
// collected along it and the wall samples' form errors before it.
void run_after(const job::Job& job, const analysis::RobotPathSetup& setup,
               const toolpath::Tooling& tooling,
               const robot_path::RobotPathSettings& after_settings,
               const toolpath::ProgramAnalysisSettings& analysis_settings,
               const toolpath::Program& rewritten, const FirstRunRecord& record,
               const std::vector<robot_path::PathDraw>& draws, bool compensate,
               ProgramImprovement& out, robot_path::CompensationSettings& compensation,
               std::optional<robot_path::PathCorrections>& corrections,
               std::vector<double>& wall_errors_m) {
  toolpath::DexelStock stock = job_stock(job);
  robot_path::RobotAlongPath after(*setup.model, setup.structure, tooling, *job.cutting,
                                   setup.stability, after_settings);
  // With draws the re-run measures P(chatter) with every one of them.
  after.set_draws(draws);
  AfterRun& rerun = out.after.emplace();
  // The fastest joint along the re-run: between neighbouring samples of a move.
  std::size_t last_move = SIZE_MAX;
  double last_t_s = 0.0;
  robot_path::RobotSample::Joints last_q;
  if (compensate) {
    compensation.floor = job.robot_path->compensation->floor;
    compensation.min_offset_m = job.robot_path->compensation->min_offset_m;
    compensation.tolerance_m = job.robot_path->compensation->tolerance_m;
    corrections.emplace(rewritten.moves.size(), compensation);
  }
  std::vector<robot_path::RobotSample> block_out;
  std::size_t index = 0;
  const toolpath::ProgramAnalysis analysis = toolpath::analyse_program(
      rewritten, tooling, *job.cutting, stock, analysis_settings,
      [&](std::span<const toolpath::PathSample> block) {
        block_out.resize(block.size());
        after.evaluate(block, block_out);
        for (std::size_t i = 0; i < block.size(); ++i, ++index) {
          const robot_path::RobotSample& r = block_out[i];
          if (r.reachable && block[i].kind != toolpath::MotionKind::rapid) {
            rerun.max_deflection_m = std::max(rerun.max_deflection_m, r.deflection_m.norm());
            if (block[i].move == last_move && block[i].t_s > last_t_s)
              rerun.max_joint_speed_rad_s =
                  std::max(rerun.max_joint_speed_rad_s,
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
          const bool risk = r.at_risk_to_optimize();
          if (risk && was == 0) {
            ++rerun.newly_at_risk;
            if (rerun.first_newly_at_risk_line == 0)
              rerun.first_newly_at_risk_line = block[i].line;
          }
          rerun.relieved += !risk && was == 1 ? 1 : 0;
        }
      });
  rerun.robot = after.finish();
  if (corrections)
    corrections->complete(analysis.moves);
  rerun.compared = index;
  rerun.max_force_n = analysis.max_force_n;
  rerun.max_torque_nm = analysis.max_torque_nm;
  rerun.cycle_time_s = analysis.cutting_time_s + analysis.air_time_s + analysis.dwell_time_s;
  rerun.redundancy_rad = after_settings.redundancy_rad;
}

// A turn of a KRL program's frames, written into its Cartesian points (all
// by one angle, or each by its line's), read back: the same points, each
// move's tool x at its end turned about its axis as chosen. `written` and
// the outcome's .dat take the turned program.
void write_turned_frames(const job::ToolpathSettings& settings, const RedundancyDecision& psi,
                         bool turn_all, const robot_path::RobotPathSettings& after_settings,
                         const std::string& text, const std::string& dat_text,
                         const std::vector<io::SpindleEdit>& edits,
                         const std::vector<io::FeedEdit>& feeds, bool written_changes,
                         const std::filesystem::path& scratch_file,
                         const toolpath::Program& rewritten, std::string& written,
                         ProgramImprovement& out) {
  const std::vector<std::pair<double, double>>& by_move = after_settings.redundancy_by_move;
  const double turn_rad = turn_all ? psi.choice->chosen_rad - psi.choice->programmed_rad : 0.0;
  // Turned in the program as read (the sites' lines), then the feed
  // statements inserted as before.
  io::KrlFrameTurn turned =
      turn_all ? io::turn_krl_frames(text, dat_text, turn_rad, settings.tool_direction)
               : io::turn_krl_frames(text, dat_text, psi.frame_turns, settings.tool_direction);
  if (written_changes)
    turned.src = io::write_program_edits(turned.src, settings.format, edits, feeds);
  if (!turned.refused.empty())
    throw Error(fmt::format("the frame on {} line {} cannot be turned: {}; nothing was written",
                            turned.refused.front().file, turned.refused.front().line,
                            turned.refused.front().reason));
  const toolpath::Program check =
      read_back(settings, turned.src, scratch_file, rewritten.moves.size(), &turned.dat);
  for (std::size_t m = 0; m < check.moves.size(); ++m) {
    const toolpath::Move& got = check.moves[m];
    const toolpath::Move& was = rewritten.moves[m];
    const double want_rad = turn_all ? turn_rad : by_move[m].second;
    const Eigen::Vector3d want_x =
        Eigen::AngleAxisd(want_rad, was.axis_end.normalized()) * was.tool_x_end;
    if ((got.end_m - was.end_m).norm() > 1e-9 || (got.axis_end - was.axis_end).norm() > 1e-9 ||
        (got.tool_x_end - want_x).norm() > 1e-7)
      throw Error(
          fmt::format("the turned frames of line {} read back as another pose than the "
                      "program's turned by {:.3f} deg; nothing was written",
                      got.line, want_rad * kDegPerRad));
  }
  written = std::move(turned.src);
  out.dat_text = std::move(turned.dat);
  out.frames_turned = turned.frames;
}

}  // namespace

// ψ first (it moves every posture), then the speeds at those postures, the
// feeds at both, the program written back and the whole analysis re-run on
// it (its own reader, a fresh stock, the samples where the first run put
// them), so that the after-numbers are measured.
ProgramImprovement improve_program(const job::Job& job, const toolpath::Program& program,
                                   const toolpath::Tooling& tooling,
                                   const analysis::RobotPathSetup& setup,
                                   const robot_path::RobotAlongPath& before,
                                   const FirstRunRecord& record,
                                   const toolpath::ProgramAnalysis& first_pass,
                                   const std::filesystem::path& scratch_dir, int threads) {
  const job::ToolpathSettings& settings = *job.toolpath;
  ProgramImprovement out;
  out.cycle_time_before_s =
      first_pass.cutting_time_s + first_pass.air_time_s + first_pass.dwell_time_s;
  out.samples_before = first_pass.samples;
  out.chatter_before = before.summary().chatter;
  // The searches re-pose the recorded samples at the chosen ψ: a copy.
  std::vector<robot_path::RecordedSample> recorded = record.recorded;
  robot_path::RobotPathSettings after_settings = setup.settings;
  RedundancyDecision& psi = out.redundancy;
  const bool krl = settings.format == job::ToolpathSettings::Format::krl;
  const std::string text = read_whole_file(settings.file);
  const std::string dat_text = krl ? read_whole_file(settings.dat_file) : std::string();
  choose_redundancy(job, program, before, text, dat_text, threads, recorded, after_settings, psi);
  out.redundancy_changed = after_settings.redundancy_rad != setup.settings.redundancy_rad ||
                           after_settings.frame_turn_rad != setup.settings.frame_turn_rad ||
                           !after_settings.redundancy_by_move.empty();

  SpindleDecision& spindles = out.spindles;
  std::vector<io::SpindleEdit> edits =
      choose_spindles(program, setup, before, recorded, after_settings, out.redundancy_changed, krl,
                      threads, spindles);
  out.name = "program_optimized" + program_extension(settings);
  const std::filesystem::path scratch_file =
      (scratch_dir.empty() ? std::filesystem::temp_directory_path() : scratch_dir) /
      (".robomill-" + out.name);
  toolpath::ProgramAnalysisSettings analysis_settings =
      program_analysis_settings(settings, threads, out.name);
  for (const toolpath::MoveTotals& move : first_pass.moves) {
    analysis_settings.move_spacing_m.push_back(move.spacing_m);
    analysis_settings.move_steps.push_back(move.steps);
  }

  // The feeds, on the program as it will run with the chosen speeds (the
  // spindle edits written and read back) at the chosen ψ.
  std::vector<double> feed_scale(program.moves.size(), 1.0);
  const toolpath::Program with_speeds =
      program_with_speeds(settings, program, text, edits, spindles.written, scratch_file);
  const std::vector<io::FeedEdit> feeds = choose_feeds(
      job, setup, tooling, after_settings, analysis_settings, with_speeds, out.feeds, feed_scale);

  const bool compensate = job.robot_path && job.robot_path->compensation;
  if (edits.empty() && feeds.empty() && !out.redundancy_changed && !compensate)
    return out;  // nothing to change: the program is kept
  out.changed = true;

  // The program written back in its dialect, read back by its reader (every
  // move's feed and speed checked against the schedule), and analysed again.
  bool written_changes = !edits.empty() || !feeds.empty();
  std::string written =
      written_changes ? io::write_program_edits(text, settings.format, edits, feeds) : text;
  toolpath::Program rewritten = read_back(settings, written, scratch_file, program.moves.size());
  check_read_back(rewritten, with_speeds, feed_scale);

  std::optional<robot_path::PathCorrections> corrections;
  std::vector<double> wall_errors_m;  // |form error| at the wall samples before compensation
  robot_path::CompensationSettings compensation;
  run_after(job, setup, tooling, after_settings, analysis_settings, rewritten, record,
            before.draws(), compensate, out, compensation, corrections, wall_errors_m);
  const AfterRun& rerun = *out.after;
  const bool turn_all = psi.turns_frames && psi.choice && psi.choice->changed();
  const bool turn_each = psi.turns_frames && psi.schedule && psi.schedule->changed();
  if (turn_all || turn_each) {
    write_turned_frames(settings, psi, turn_all, after_settings, text, dat_text, edits, feeds,
                        written_changes, scratch_file, rewritten, written, out);
    written_changes = true;
  }
  if (corrections) {
    // A KRL program's points may live in its .dat (turned above, or as read).
    std::string compensated_dat = out.dat_text ? *out.dat_text : dat_text;
    CompensationOutcome& c = out.compensation.emplace(
        compensate_program(job, setup, tooling, after_settings, analysis_settings, *corrections,
                           rewritten, written, krl ? &compensated_dat : nullptr, scratch_file));
    c.settings = compensation;
    c.before_m = percentiles(wall_errors_m);
    c.max_form_error_before_m = rerun.robot.max_form_error_m;
    written_changes = written_changes || !c.written.empty();
    if (krl && !c.written.empty())
      out.dat_text = std::move(compensated_dat);
  }
  if (written_changes)
    out.text = std::move(written);  // else only ψ changed: the program itself is the same
  return out;
}

}  // namespace robomill::analysis
