// The draws of uncertain inputs along the program (issue 33; the draw
// members of RobotAlongPath, include/robomill/robot_path/robot_along_path.hpp;
// docs/uncertainty.md, "Along a program"): each draw's stable depths by the
// nominal run's shortcut at the nominal postures, and per sample the
// fraction of draws that chatter and the band of their limits; per program
// line, the highest probability.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

#include "robomill/core/parallel.hpp"
#include "robomill/robot_path/robot_along_path.hpp"
#include "robomill/uncertainty/sample_statistics.hpp"

namespace robomill::robot_path {

void RobotAlongPath::set_draws(std::vector<PathDraw> draws) {
  if (summary_.samples > 0)
    throw std::invalid_argument("robot along the path: draws are set before the first block");
  for (const PathDraw& d : draws)
    if (!d.structure || d.stability.enabled != stability_.enabled)
      throw std::invalid_argument("robot along the path: a draw without a structure");
  draws_ = std::move(draws);
  draw_a0_cache_.assign(draws_.size(), {});
  summary_.draws = draws_.size();
  summary_.draw_chatter_samples.assign(draws_.size(), 0.0);
}

void RobotAlongPath::draw_limits(std::span<const toolpath::PathSample> samples,
                                 std::span<RobotSample> out, ShortcutChecks& checks) const {
  // Each draw's limits by the nominal run's shortcut at the nominal postures
  // (the draws run in parallel, each on one thread), then per sample the
  // fraction of draws that chatter and the band of their limits.
  const std::size_t n = draws_.size();
  std::vector<std::size_t> judged;
  for (std::size_t i = 0; i < out.size(); ++i)
    if (out[i].stability)
      judged.push_back(i);
  checks.draw_chatter_samples.assign(n, 0.0);
  if (judged.empty())
    return;
  std::vector<double> limits(judged.size() * n);  // limits[j * n + d]
  std::vector<char> chatters(judged.size() * n);
  std::vector<ShortcutChecks> per_draw(n);
  core::parallel_for(n, settings_.threads, [&](std::size_t d) {
    std::vector<RobotSample> drawn(out.begin(), out.end());
    per_draw[d] = shortcut_limits(
        samples, drawn,
        [&](const toolpath::PathSample& s, const Eigen::VectorXd& q) {
          return draw_limit(d, s, q);
        },
        1);
    for (std::size_t j = 0; j < judged.size(); ++j) {
      limits[j * n + d] = drawn[judged[j]].depth_limit_m;
      chatters[j * n + d] = drawn[judged[j]].chatter ? 1 : 0;
      checks.draw_chatter_samples[d] += drawn[judged[j]].chatter ? 1.0 : 0.0;
    }
  });
  for (const ShortcutChecks& c : per_draw) {
    checks.draw_exact += c.exact;
    checks.draw_max_error = std::max(checks.draw_max_error, c.max_error);
  }
  const double draws = static_cast<double>(n);
  constexpr std::array<double, 2> kBand{0.05, 0.95};
  for (std::size_t j = 0; j < judged.size(); ++j) {
    RobotSample& r = out[judged[j]];
    // The draw's own verdict, ap ≥ its limit, as the nominal one's.
    const std::size_t chattering = static_cast<std::size_t>(
        std::count(chatters.begin() + static_cast<std::ptrdiff_t>(j * n),
                   chatters.begin() + static_cast<std::ptrdiff_t>((j + 1) * n), 1));
    r.drawn = true;
    r.p_chatter = static_cast<double>(chattering) / draws;
    r.p_chatter_se = std::sqrt(r.p_chatter * (1.0 - r.p_chatter) / draws);
    const auto band =
        uncertainty::empirical_quantiles(std::span<const double>(&limits[j * n], n), kBand);
    r.depth_limit_q05_m = band[0].value;
    r.depth_limit_q95_m = band[1].value;
    // P(chatter) = #(limit ≤ ap)/n ≤ p exactly where ap lies below the
    // (⌊p n⌋ + 1)-th smallest limit (0 < p < 1, checked by the constructor:
    // there is one).
    r.depth_limit_at_bound_m = *uncertainty::value_at_fraction_bound(
        std::span<const double>(&limits[j * n], n), settings_.max_chatter_probability);
    r.at_risk_drawn =
        samples[judged[j]].axial_depth_m * settings_.risk_margin >= r.depth_limit_at_bound_m;
  }
}

void RobotAlongPath::tally_draws(const toolpath::PathSample& s, const RobotSample& r) {
  if (r.p_chatter > summary_.max_p_chatter || summary_.max_p_chatter_line == 0) {
    summary_.max_p_chatter = r.p_chatter;
    summary_.max_p_chatter_se = r.p_chatter_se;
    summary_.max_p_chatter_line = s.line;
  }
  if (open_line_ && open_line_->first != s.line)
    close_line();
  if (!open_line_ || r.p_chatter > open_line_->second.p_chatter) {
    RiskyLine line;
    line.line = s.line;
    line.t_s = s.t_s;
    line.p_chatter = r.p_chatter;
    line.p_chatter_se = r.p_chatter_se;
    line.axial_depth_m = s.axial_depth_m;
    line.depth_limit_m = r.depth_limit_m;
    line.depth_limit_q05_m = r.depth_limit_q05_m;
    open_line_.emplace(s.line, line);
  }
}

void RobotAlongPath::close_line() {
  // A line returned to later (a repeated subprogram) is listed again: each
  // visit is its own stretch of the program.
  if (open_line_ && open_line_->second.p_chatter > settings_.max_chatter_probability)
    summary_.risky_lines.push_back(open_line_->second);
  open_line_.reset();
}

}  // namespace robomill::robot_path
