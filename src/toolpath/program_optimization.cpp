// A better program (include/robomill/toolpath/program_optimization.hpp).

#include "robomill/toolpath/program_optimization.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "robomill/core/parallel.hpp"

namespace robomill::toolpath {

std::vector<SpindleRegion> spindle_regions(const Program& program) {
  std::vector<SpindleRegion> regions;
  for (std::size_t m = 0; m < program.moves.size(); ++m) {
    const Move& move = program.moves[m];
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
      margins[i * c + k] = limits[k].depth_limit_m / r.sample.axial_depth_m;
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
  choice.programmed_rad = choice.chosen_rad = along.settings().redundancy_rad;
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

}  // namespace robomill::toolpath
