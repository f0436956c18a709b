// A better program (include/robomill/robot_path/program_optimization.hpp).

#include "robomill/robot_path/program_optimization.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include "robomill/core/parallel.hpp"

namespace robomill::robot_path {

std::vector<SpindleRegion> spindle_regions(const toolpath::Program& program) {
  std::vector<SpindleRegion> regions;
  for (std::size_t m = 0; m < program.moves.size(); ++m) {
    const toolpath::Move& move = program.moves[m];
    if (move.spindle_rad_s == 0.0)
      continue;
    const bool extends = !regions.empty() && regions.back().last_move + 1 == m &&
                         regions.back().tool == move.tool &&
                         regions.back().spindle_rad_s == move.spindle_rad_s;
    if (extends) {
      regions.back().last_move = m;
      regions.back().last_line = move.line;
    } else {
      regions.push_back({m, m, move.line, move.line, move.tool, move.spindle_rad_s});
    }
  }
  return regions;
}

std::vector<SpindleChoice> choose_spindle_speeds(const RobotAlongPath& along,
                                                 const std::vector<SpindleRegion>& regions,
                                                 std::span<const RecordedSample> samples,
                                                 const std::vector<double>& candidates_rad_s,
                                                 double min_gain, int threads) {
  if (candidates_rad_s.empty())
    throw std::invalid_argument("spindle optimization: no candidate speeds");
  const double risk = along.settings().risk_margin;
  // Margins of every recorded sample at every candidate, in parallel over
  // samples (each a solver at the sample's posture and engagement).
  const std::size_t n = samples.size(), c = candidates_rad_s.size();
  std::vector<double> margins(n * c, 0.0);
  core::parallel_for(n, threads, [&](std::size_t i) {
    const RecordedSample& r = samples[i];
    const auto limits = along.limits_at(r.sample, Eigen::VectorXd(r.q_rad), candidates_rad_s);
    for (std::size_t k = 0; k < c; ++k)
      margins[i * c + k] = r.bound_ratio * limits[k].depth_limit_m / r.sample.axial_depth_m;
  });

  std::vector<SpindleChoice> choices;
  for (std::size_t g = 0; g < regions.size(); ++g) {
    const SpindleRegion& region = regions[g];
    std::vector<std::size_t> members;
    for (std::size_t i = 0; i < n; ++i)
      if (samples[i].sample.move >= region.first_move && samples[i].sample.move <= region.last_move)
        members.push_back(i);
    if (members.empty())
      continue;
    SpindleChoice choice;
    choice.region = g;
    choice.programmed_rad_s = choice.chosen_rad_s = region.spindle_rad_s;
    choice.samples = members.size();
    choice.min_margin_before = std::numeric_limits<double>::infinity();
    for (const std::size_t i : members) {
      choice.min_margin_before = std::min(choice.min_margin_before, samples[i].margin);
      choice.at_risk_before += samples[i].margin <= risk ? 1 : 0;
    }
    choice.min_margin_after = choice.min_margin_before;
    choice.at_risk_after = choice.at_risk_before;
    for (std::size_t k = 0; k < c; ++k) {
      double smallest = std::numeric_limits<double>::infinity();
      std::size_t at_risk = 0;
      bool newly_at_risk = false;
      for (const std::size_t i : members) {
        const double m = margins[i * c + k];
        smallest = std::min(smallest, m);
        at_risk += m <= risk ? 1 : 0;
        newly_at_risk = newly_at_risk || (m <= risk && samples[i].margin > risk);
      }
      if (newly_at_risk || at_risk > choice.at_risk_before)
        continue;
      if (smallest > choice.min_margin_after &&
          smallest > choice.min_margin_before * (1.0 + min_gain)) {
        choice.min_margin_after = smallest;
        choice.at_risk_after = at_risk;
        choice.chosen_rad_s = std::copysign(candidates_rad_s[k], region.spindle_rad_s);
      }
    }
    choices.push_back(choice);
  }
  return choices;
}

RedundancyChoice choose_redundancy_angle(const RobotAlongPath& along,
                                         std::vector<RecordedSample>& samples,
                                         const std::vector<double>& candidates_rad, double min_gain,
                                         int threads) {
  const double risk = along.settings().risk_margin;
  RedundancyChoice choice;
  // A program whose frames set ψ (KRL) is turned as a whole: the candidates
  // are turns of its frames.
  const bool frames = !samples.empty() && samples.front().sample.oriented;
  choice.programmed_rad = choice.chosen_rad =
      frames ? along.settings().frame_turn_rad : along.settings().redundancy_rad;
  choice.samples = samples.size();
  choice.min_margin_before = std::numeric_limits<double>::infinity();
  for (const RecordedSample& r : samples) {
    choice.min_margin_before = std::min(choice.min_margin_before, r.margin);
    choice.at_risk_before += r.margin <= risk ? 1 : 0;
  }
  if (samples.empty())
    return choice;
  choice.min_margin_after = choice.min_margin_before;
  choice.at_risk_after = choice.at_risk_before;
  const std::size_t n = samples.size();
  std::vector<RecordedSample> best;
  for (const double psi : candidates_rad) {
    std::vector<RecordedSample> moved(samples.begin(), samples.end());
    std::vector<char> reachable(n, 0), limit(n, 0);
    core::parallel_for(n, threads, [&](std::size_t i) {
      const RobotSample robot =
          along.posture_at(samples[i].sample, psi, Eigen::VectorXd(samples[i].q_rad));
      reachable[i] = robot.reachable ? 1 : 0;
      limit[i] = robot.joint_limit ? 1 : 0;
      if (!robot.reachable)
        return;
      moved[i].q_rad = robot.q_rad;
      moved[i].margin =
          samples[i].bound_ratio *
          along.direct_limit(samples[i].sample, Eigen::VectorXd(robot.q_rad)).depth_limit_m /
          samples[i].sample.axial_depth_m;
    });
    RedundancyChoice::Candidate c;
    c.redundancy_rad = psi;
    c.min_margin = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
      c.unreachable += reachable[i] ? 0 : 1;
      c.joint_limit += limit[i];
      if (!reachable[i])
        continue;
      c.min_margin = std::min(c.min_margin, moved[i].margin);
      c.at_risk += moved[i].margin <= risk ? 1 : 0;
      c.newly_at_risk = c.newly_at_risk || (moved[i].margin <= risk && samples[i].margin > risk);
    }
    if (c.unreachable > 0)
      c.min_margin = 0.0;
    choice.candidates.push_back(c);
    const bool admissible = c.unreachable == 0 && c.joint_limit == 0 && !c.newly_at_risk &&
                            c.at_risk <= choice.at_risk_before;
    if (admissible && c.min_margin > choice.min_margin_after &&
        c.min_margin > choice.min_margin_before * (1.0 + min_gain)) {
      choice.min_margin_after = c.min_margin;
      choice.at_risk_after = c.at_risk;
      choice.chosen_rad = psi;
      best = std::move(moved);
    }
  }
  if (choice.changed())
    samples = std::move(best);
  return choice;
}

}  // namespace robomill::robot_path

namespace robomill::robot_path {

bool RedundancySchedule::changed() const noexcept {
  for (const Line& line : lines)
    if (line.from_rad != programmed_rad || line.to_rad != programmed_rad)
      return true;
  return false;
}

std::vector<std::pair<double, double>> RedundancySchedule::by_move(std::size_t moves) const {
  double current = lines.empty() ? programmed_rad : lines.front().from_rad;
  std::vector<std::pair<double, double>> out(moves, {current, current});
  std::size_t next = 0;
  for (std::size_t m = 0; m < moves; ++m) {
    if (next < lines.size() && m >= lines[next].first_move && m <= lines[next].last_move) {
      // The turn spread evenly over the line's moves.
      const Line& line = lines[next];
      const double n = static_cast<double>(line.last_move - line.first_move + 1);
      const double i = static_cast<double>(m - line.first_move);
      out[m] = {line.from_rad + (line.to_rad - line.from_rad) * i / n,
                line.from_rad + (line.to_rad - line.from_rad) * (i + 1.0) / n};
      if (m == line.last_move) {
        current = line.to_rad;
        ++next;
      }
    } else if (next < lines.size() && lines[next].turn_before && next > 0) {
      // A turn on the moves between two lines, spread evenly over them.
      const double from = lines[next - 1].to_rad, to = lines[next].from_rad;
      const double n = static_cast<double>(lines[next].first_move - lines[next - 1].last_move - 1);
      const double i = static_cast<double>(m - lines[next - 1].last_move - 1);
      out[m] = {from + (to - from) * i / n, from + (to - from) * (i + 1.0) / n};
    } else {
      out[m] = {current, current};
    }
  }
  return out;
}

namespace {

// The lines of a redundancy schedule: runs of consecutive moves from one
// program line (a KRL loop runs a line again later: another run), their
// cutting time, and the recorded samples each holds.
struct ProgramLines {
  std::vector<RedundancySchedule::Line> lines;
  std::vector<double> line_time_s;
  std::vector<std::vector<std::size_t>> members;
};

ProgramLines program_lines(const toolpath::Program& program,
                           const std::vector<RecordedSample>& samples) {
  ProgramLines out;
  std::vector<RedundancySchedule::Line>& lines = out.lines;
  std::vector<double>& line_time_s = out.line_time_s;
  std::vector<std::size_t> line_of_move(program.moves.size(), SIZE_MAX);
  for (std::size_t m = 0; m < program.moves.size(); ++m) {
    const toolpath::Move& move = program.moves[m];
    if (lines.empty() || lines.back().last_move + 1 != m || lines.back().line != move.line) {
      lines.push_back({move.line, m, m, 0.0, 0.0, 0.0, 0.0, false, 0});
      line_time_s.push_back(0.0);
    }
    lines.back().last_move = m;
    line_time_s.back() += move.kind == toolpath::MotionKind::rapid ? 0.0 : duration_s(move, 1.0);
    line_of_move[m] = lines.size() - 1;
  }
  const std::size_t n = samples.size();
  out.members.resize(lines.size());
  for (std::size_t i = 0; i < n; ++i)
    if (samples[i].sample.move < line_of_move.size())
      out.members[line_of_move[samples[i].sample.move]].push_back(i);
  return out;
}

// A sample at a candidate: the posture from the recorded one, its margin at
// the sample's own speed.
struct At {
  bool ok = false;  // reachable, off the joint limits
  RobotSample::Joints q;
  double margin = 0.0;
};

// Every sample at every candidate, [sample * candidates + candidate].
std::vector<At> pose_candidates(const RobotAlongPath& along,
                                const std::vector<RecordedSample>& samples,
                                const std::vector<double>& candidates_rad, int threads) {
  const std::size_t n = samples.size(), c = candidates_rad.size();
  std::vector<At> at(n * c);
  core::parallel_for(n * c, threads, [&](std::size_t index) {
    const std::size_t i = index / c, k = index % c;
    const RecordedSample& r = samples[i];
    const RobotSample robot =
        along.posture_at(r.sample, candidates_rad[k], Eigen::VectorXd(r.q_rad));
    At& a = at[index];
    a.ok = robot.reachable && !robot.joint_limit;
    a.q = robot.q_rad;
    if (a.ok)
      a.margin = r.bound_ratio *
                 along.direct_limit(r.sample, Eigen::VectorXd(robot.q_rad)).depth_limit_m /
                 r.sample.axial_depth_m;
  });
  return at;
}

// What the schedule weighs, per line and candidate ([line * candidates +
// candidate]), and the joint speeds of its turns.
struct Weighing {
  const std::vector<RecordedSample>& samples;
  const ProgramLines& program;
  const std::vector<At>& at;
  std::size_t c = 0;             // candidates
  std::vector<char> admissible;  // no sample unreachable or newly at risk
  std::vector<double> margin;    // the smallest margin of the line's samples

  Weighing(const std::vector<RecordedSample>& samples_, const ProgramLines& program_,
           const std::vector<At>& at_, std::size_t candidates, double risk)
      : samples(samples_), program(program_), at(at_), c(candidates) {
    const std::vector<std::vector<std::size_t>>& members = program.members;
    const std::size_t L = program.lines.size();
    admissible.assign(L * c, 0);
    margin.assign(L * c, std::numeric_limits<double>::infinity());
    for (std::size_t l = 0; l < L; ++l)
      for (std::size_t k = 0; k < c; ++k) {
        bool ok = true;
        for (const std::size_t i : members[l]) {
          const At& a = at[i * c + k];
          ok = ok && a.ok && !(a.margin <= risk && samples[i].margin > risk);
          if (a.ok)
            margin[l * c + k] = std::min(margin[l * c + k], a.margin);
        }
        admissible[l * c + k] = ok ? 1 : 0;
      }
  }

  // The joint speed of turning from angle j to k over line l: the turn
  // itself (its first sample's postures) over the line's time, plus the
  // path's own (its first and last samples at k).
  double turn_speed(std::size_t l, std::size_t j, std::size_t k) const {
    const std::vector<std::vector<std::size_t>>& members = program.members;
    if (members[l].empty())
      return 0.0;
    const std::size_t first = members[l].front(), last = members[l].back();
    double path = 0.0;
    const double dt = samples[last].sample.t_s - samples[first].sample.t_s;
    if (dt > 0.0)
      path = (at[last * c + k].q - at[first * c + k].q).cwiseAbs().maxCoeff() / dt;
    if (j == k)
      return 0.0;
    if (!(program.line_time_s[l] > 0.0))
      return std::numeric_limits<double>::infinity();
    return (at[first * c + k].q - at[first * c + j].q).cwiseAbs().maxCoeff() /
               program.line_time_s[l] +
           path;
  }

  // A turn between two lines, on the moves between them (a link, a retract):
  // from the last sample of one at angle j to the first of the next at k.
  double gap_speed(std::size_t before, std::size_t after, std::size_t j, std::size_t k) const {
    const std::vector<RedundancySchedule::Line>& lines = program.lines;
    if (lines[after].first_move == lines[before].last_move + 1)
      return std::numeric_limits<double>::infinity();  // no move between them
    const std::size_t last = program.members[before].back(), first = program.members[after].front();
    const double dt = samples[first].sample.t_s - samples[last].sample.t_s;
    if (!(dt > 0.0))
      return std::numeric_limits<double>::infinity();
    return (at[first * c + k].q - at[last * c + j].q).cwiseAbs().maxCoeff() / dt;
  }
};

// Dynamic programming over the lines with samples, in program order:
// value = the smallest margin so far, then the fewest turns.
struct State {
  double value = -std::numeric_limits<double>::infinity();
  std::size_t turns = 0;
  std::size_t from = SIZE_MAX;
  bool in_gap = false;  // the turn from `from` happens on the moves before the line
};

bool better(double v, std::size_t t, const State& s) {
  return v > s.value * (1.0 + 1e-12) || (v >= s.value * (1.0 - 1e-12) && t < s.turns);
}

// The states [judged line * candidates + candidate] over the judged lines.
std::vector<State> best_turns(const Weighing& w, const std::vector<std::size_t>& judged,
                              double joint_speed_max_rad_s) {
  const std::size_t c = w.c;
  const std::vector<char>& admissible = w.admissible;
  const std::vector<double>& margin = w.margin;
  std::vector<State> dp(judged.size() * c);
  for (std::size_t g = 0; g < judged.size(); ++g) {
    const std::size_t l = judged[g];
    for (std::size_t k = 0; k < c; ++k) {
      if (!admissible[l * c + k])
        continue;
      State& state = dp[g * c + k];
      if (g == 0) {
        state.value = margin[l * c + k];
        continue;
      }
      for (std::size_t j = 0; j < c; ++j) {
        const State& previous = dp[(g - 1) * c + j];
        if (!std::isfinite(previous.value) || !admissible[l * c + j])
          continue;
        // Turn between the lines where the moves between them allow it (the
        // line then runs at k alone), else over the line itself.
        const bool in_gap = j != k && w.gap_speed(judged[g - 1], l, j, k) <= joint_speed_max_rad_s;
        if (j != k && !in_gap && w.turn_speed(l, j, k) > joint_speed_max_rad_s)
          continue;
        const double line_value =
            j == k || in_gap ? margin[l * c + k] : std::min(margin[l * c + k], margin[l * c + j]);
        const double value = std::min(previous.value, line_value);
        const std::size_t turns = previous.turns + (j == k ? 0 : 1);
        if (better(value, turns, state)) {
          state.value = value;
          state.turns = turns;
          state.from = j;
          state.in_gap = in_gap;
        }
      }
    }
  }
  return dp;
}

}  // namespace

RedundancySchedule schedule_redundancy(const RobotAlongPath& along,
                                       const toolpath::Program& program,
                                       std::vector<RecordedSample>& samples,
                                       const std::vector<double>& candidates_rad,
                                       double joint_speed_max_rad_s, double min_gain, int threads) {
  if (candidates_rad.empty() || !(joint_speed_max_rad_s > 0.0))
    throw std::invalid_argument("redundancy schedule: no candidates or no joint speed bound");
  const double risk = along.settings().risk_margin;
  RedundancySchedule schedule;
  // A program whose frames set ψ (KRL): the candidates turn its frames.
  const bool frames = !samples.empty() && samples.front().sample.oriented;
  schedule.programmed_rad =
      frames ? along.settings().frame_turn_rad : along.settings().redundancy_rad;
  schedule.min_margin_before = std::numeric_limits<double>::infinity();
  for (const RecordedSample& r : samples) {
    schedule.min_margin_before = std::min(schedule.min_margin_before, r.margin);
    schedule.at_risk_before += r.margin <= risk ? 1 : 0;
  }
  if (samples.empty()) {
    schedule.min_margin_before = 0.0;
    return schedule;
  }

  const ProgramLines split = program_lines(program, samples);
  const std::vector<RedundancySchedule::Line>& lines = split.lines;
  const std::vector<std::vector<std::size_t>>& members = split.members;
  const std::size_t c = candidates_rad.size();
  const std::vector<At> at = pose_candidates(along, samples, candidates_rad, threads);
  const Weighing weighing(samples, split, at, c, risk);
  const std::vector<double>& margin = weighing.margin;

  const std::size_t L = lines.size();
  std::vector<std::size_t> judged;  // lines with samples
  for (std::size_t l = 0; l < L; ++l)
    if (!members[l].empty())
      judged.push_back(l);
  const std::vector<State> dp = best_turns(weighing, judged, joint_speed_max_rad_s);
  std::size_t best = SIZE_MAX;
  for (std::size_t k = 0; k < c && !judged.empty(); ++k) {
    const State& s = dp[(judged.size() - 1) * c + k];
    if (std::isfinite(s.value) &&
        (best == SIZE_MAX || better(s.value, s.turns, dp[(judged.size() - 1) * c + best])))
      best = k;
  }
  schedule.min_margin_after = schedule.min_margin_before;
  schedule.at_risk_after = schedule.at_risk_before;
  for (const std::size_t l : judged) {
    RedundancySchedule::Line line = lines[l];
    line.from_rad = line.to_rad = schedule.programmed_rad;
    line.samples = members[l].size();
    line.min_margin = std::numeric_limits<double>::infinity();
    for (const std::size_t i : members[l])
      line.min_margin = std::min(line.min_margin, samples[i].margin);
    schedule.lines.push_back(line);
  }
  if (best == SIZE_MAX ||
      !(dp[(judged.size() - 1) * c + best].value > schedule.min_margin_before * (1.0 + min_gain)))
    return schedule;  // the programmed ψ stays

  // Back along the choices.
  std::vector<std::size_t> chosen(judged.size());
  chosen.back() = best;
  for (std::size_t g = judged.size() - 1; g > 0; --g)
    chosen[g - 1] = dp[g * c + chosen[g]].from;
  schedule.min_margin_after = dp[(judged.size() - 1) * c + best].value;
  schedule.turns = dp[(judged.size() - 1) * c + best].turns;
  schedule.at_risk_after = 0;
  for (std::size_t g = 0; g < judged.size(); ++g) {
    const std::size_t l = judged[g], k = chosen[g];
    const bool in_gap = g > 0 && dp[g * c + k].in_gap;
    const std::size_t j = g == 0 || in_gap ? k : chosen[g - 1];
    RedundancySchedule::Line& line = schedule.lines[g];
    line.from_rad = candidates_rad[j];
    line.to_rad = candidates_rad[k];
    line.min_margin = j == k ? margin[l * c + k] : std::min(margin[l * c + k], margin[l * c + j]);
    line.turn_joint_speed_rad_s = in_gap ? weighing.gap_speed(judged[g - 1], l, chosen[g - 1], k)
                                         : weighing.turn_speed(l, j, k);
    line.turn_before = in_gap;
    for (const std::size_t i : members[l])
      schedule.at_risk_after +=
          (at[i * c + k].margin <= risk || at[i * c + j].margin <= risk) ? 1 : 0;
  }
  // The samples at their line's angle, for the spindle choice that follows.
  for (std::size_t g = 0; g < judged.size(); ++g)
    for (const std::size_t i : members[judged[g]]) {
      samples[i].q_rad = at[i * c + chosen[g]].q;
      samples[i].margin = at[i * c + chosen[g]].margin;
    }
  return schedule;
}

}  // namespace robomill::robot_path
