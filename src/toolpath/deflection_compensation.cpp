// The deflection compensation (include/robomill/toolpath/deflection_compensation.hpp).

#include "robomill/toolpath/deflection_compensation.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace robomill::toolpath {
namespace {

// Douglas-Peucker on the samples' corrections c_k at u_k = k / (n − 1): the
// interior samples kept so that the linear interpolation between kept ones
// lies within `tolerance` of every sample's, the first point fixed at
// `start` (where the line before ends).
void simplify(const std::vector<Eigen::Vector3d>& c, const Eigen::Vector3d& start,
              std::size_t first, std::size_t last, double tolerance,
              std::vector<std::size_t>& kept) {
  if (last <= first + 1)
    return;
  const Eigen::Vector3d a = first == 0 ? start : c[first];
  const Eigen::Vector3d b = c[last];
  double worst = 0.0;
  std::size_t at = first;
  for (std::size_t k = first + 1; k < last; ++k) {
    const double t = (static_cast<double>(k) - static_cast<double>(first)) /
                     (static_cast<double>(last) - static_cast<double>(first));
    const double error = (c[k] - (a + t * (b - a))).norm();
    if (error > worst) {
      worst = error;
      at = k;
    }
  }
  if (worst <= tolerance)
    return;
  simplify(c, start, first, at, tolerance, kept);
  kept.push_back(at);
  simplify(c, start, at, last, tolerance, kept);
}

// A running median over five samples, component by component: the dexel
// engagement can flip a near-slot sample between one wall and the other
// (or none) from one sample to the next, a single-sample spike the written
// path should not follow.
std::vector<Eigen::Vector3d> median5(const std::vector<Eigen::Vector3d>& c) {
  std::vector<Eigen::Vector3d> out = c;
  for (std::size_t k = 0; k < c.size(); ++k) {
    // A centred window, narrower at the ends (the line's own end samples).
    const std::size_t half = std::min<std::size_t>({2, k, c.size() - 1 - k});
    for (int a = 0; a < 3; ++a) {
      double window[5];
      for (std::size_t i = 0; i <= 2 * half; ++i)
        window[i] = c[k - half + i][a];
      std::nth_element(window, window + half, window + 2 * half + 1);
      out[k][a] = window[half];
    }
  }
  return out;
}

// The offset of a point that finishes two surfaces (a corner: the last
// sample of one line, the first of the next), each asking for its own
// correction a = e₁ w₁, b = e₂ w₂: the smallest o with o·w₁ = e₁ and
// o·w₂ = e₂ (perpendicular walls: a + b); nearly parallel ones share the
// mean.
Eigen::Vector3d combined(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double na = a.norm(), nb = b.norm();
  if (na < 1e-12 || nb < 1e-12)
    return na < 1e-12 ? b : a;
  const Eigen::Vector3d ua = a / na, ub = b / nb;
  const double c = ua.dot(ub);
  if (std::abs(c) > 0.95)
    return 0.5 * (a + b);
  const double alpha = (na - c * nb) / (1.0 - c * c), beta = (nb - c * na) / (1.0 - c * c);
  return alpha * ua + beta * ub;
}

}  // namespace

std::optional<Eigen::Vector3d> sample_correction(const PathSample& sample, const RobotSample& robot,
                                                 const CompensationSettings& settings) {
  if (!robot.reachable || !sample.analysed || sample.kind == MotionKind::rapid || sample.plunge)
    return std::nullopt;
  if (!robot.wall && !settings.floor)
    return std::nullopt;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  if (robot.wall)  // + form error: material left, so the point moves towards the wall
    offset += robot.form_error_m * robot.wall_direction;
  if (settings.floor)  // + floor error: the tool rode up, so the point moves down the axis
    offset -= robot.floor_error_m * sample.axis.normalized();
  return offset;
}

PathCorrections::PathCorrections(std::size_t moves, CompensationSettings settings)
    : settings_(settings), samples_(moves) {
  if (!(settings_.min_offset_m >= 0.0) || !(settings_.tolerance_m > 0.0) ||
      settings_.max_points < 0)
    throw std::invalid_argument("compensation: inconsistent settings");
}

void PathCorrections::add(const PathSample& sample, const RobotSample& robot) {
  if (sample.move < samples_.size())
    samples_[sample.move].push_back(
        sample_correction(sample, robot, settings_).value_or(Eigen::Vector3d::Zero()));
}

std::vector<LineCorrection> PathCorrections::corrections(const Program& program) const {
  std::map<int, int> moves_on_line;
  for (const Move& move : program.moves)
    ++moves_on_line[move.line];
  const std::size_t moves = std::min(program.moves.size(), samples_.size());
  auto eligible = [&](std::size_t m) {
    const Move& move = program.moves[m];
    const bool before_arc = m + 1 < moves && program.moves[m + 1].kind == MotionKind::arc;
    if (move.kind != MotionKind::linear || moves_on_line[move.line] != 1 || before_arc ||
        samples_[m].size() < 2)
      return false;
    double largest = 0.0;
    for (const Eigen::Vector3d& v : samples_[m])
      largest = std::max(largest, v.norm());
    return largest >= settings_.min_offset_m;
  };
  std::vector<LineCorrection> out;
  Eigen::Vector3d written_end = Eigen::Vector3d::Zero();  // the offset the path ends at so far
  for (std::size_t m = 0; m < moves; ++m) {
    const Move& move = program.moves[m];
    std::vector<Eigen::Vector3d> c = median5(samples_[m]);
    const Eigen::Vector3d start = written_end;
    if (move.kind != MotionKind::dwell)  // a dwell stays where the path ended
      written_end = Eigen::Vector3d::Zero();
    if (!eligible(m))
      continue;
    // A corner: the next line starts here and finishes a wall of its own.
    if (m + 1 < moves && eligible(m + 1))
      c.back() = combined(c.back(), median5(samples_[m + 1]).front());
    std::vector<std::size_t> kept;
    simplify(c, start, 0, c.size() - 1, settings_.tolerance_m, kept);
    if (kept.size() > static_cast<std::size_t>(settings_.max_points)) {  // evenly thinned
      std::vector<std::size_t> thinned;
      for (int i = 0; i < settings_.max_points; ++i)
        thinned.push_back(kept[i * kept.size() / static_cast<std::size_t>(settings_.max_points)]);
      kept = thinned;
    }
    LineCorrection line;
    line.move = m;
    line.line = move.line;
    line.offset_m = c.back();
    for (const std::size_t k : kept)
      line.points.push_back({static_cast<double>(k) / static_cast<double>(c.size() - 1), c[k]});
    out.push_back(std::move(line));
    written_end = c.back();
  }
  return out;
}

std::vector<PathCorrections::Kept> PathCorrections::kept(const Program& program) const {
  std::map<int, int> moves_on_line;
  for (const Move& move : program.moves)
    ++moves_on_line[move.line];
  const std::size_t moves = std::min(program.moves.size(), samples_.size());
  std::vector<Kept> out;
  for (std::size_t m = 0; m < moves; ++m) {
    const Move& move = program.moves[m];
    if (move.kind != MotionKind::linear && move.kind != MotionKind::arc)
      continue;
    double largest = 0.0;
    for (const Eigen::Vector3d& v : samples_[m])
      largest = std::max(largest, v.norm());
    if (largest < settings_.min_offset_m || (!out.empty() && out.back().line == move.line))
      continue;
    if (move.kind == MotionKind::arc)
      out.push_back({move.line, "an arc: kept as programmed"});
    else if (moves_on_line[move.line] != 1)
      out.push_back({move.line, "one of several moves on its line (a loop or a cycle)"});
    else if (m + 1 < moves && program.moves[m + 1].kind == MotionKind::arc)
      out.push_back({move.line, "before an arc, whose centre is programmed from its start"});
  }
  return out;
}

std::vector<Eigen::Vector3d> corrected_ends(const Program& program,
                                            const std::vector<LineCorrection>& corrections) {
  std::map<std::size_t, const LineCorrection*> by_move;
  for (const LineCorrection& c : corrections)
    by_move[c.move] = &c;
  std::vector<Eigen::Vector3d> ends;
  Eigen::Vector3d carried = Eigen::Vector3d::Zero();  // a dwell stays where the path ended
  for (std::size_t m = 0; m < program.moves.size(); ++m) {
    const Move& move = program.moves[m];
    const auto it = by_move.find(m);
    if (it == by_move.end()) {
      ends.push_back(move.end_m + (move.kind == MotionKind::dwell
                                       ? carried
                                       : Eigen::Vector3d(Eigen::Vector3d::Zero())));
      if (move.kind != MotionKind::dwell)
        carried.setZero();
      continue;
    }
    for (const CorrectionPoint& p : it->second->points)
      ends.push_back(move.start_m + p.u * (move.end_m - move.start_m) + p.offset_m);
    ends.push_back(move.end_m + it->second->offset_m);
    carried = it->second->offset_m;
  }
  return ends;
}

}  // namespace robomill::toolpath
