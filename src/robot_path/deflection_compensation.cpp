// The deflection compensation (include/robomill/robot_path/deflection_compensation.hpp).

#include "robomill/robot_path/deflection_compensation.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace robomill::robot_path {
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

// The in-plane unit radial r̂ of an arc at the fraction u.
Eigen::Vector3d radial_at(const toolpath::Move& arc, double u) {
  Eigen::Vector3d r = position_at(arc, u) - arc.centre_m;
  r -= r.dot(arc.normal) * arc.normal;
  return r.normalized();
}

// An arc moved: its centre by Δc, its radius by δ, where it starts and ends
// on the moved circle (offsets from the programmed points), and how far the
// moved arc's correction departs from the samples' (at u_k = k / (n − 1)).
struct ArcFit {
  Eigen::Vector3d centre_offset_m = Eigen::Vector3d::Zero();
  double radius_change_m = 0.0;
  Eigen::Vector3d start_offset_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d end_offset_m = Eigen::Vector3d::Zero();
  double residual_m = 0.0;
};

// A small ridge on Δc: over a short sweep r̂ hardly turns, Δc and δ r̂ say
// the same thing, and the radius is the physical reading of a wall error.
constexpr double kCentreRidge = 1e-3;

// The least-squares fit of p'(u) − p(u) = Δc + δ r̂(u) to the corrections
// c_k. With `start` (the offset the path arrives with, which the arc must
// keep) only Δc is free and the radius is the distance from the moved
// centre to that start. Either way the moved circle is then built exactly:
// centre c + Δc, radius the in-plane distance from it to the moved start,
// the programmed sweep from there, the helix's rise kept.
ArcFit fit_arc(const toolpath::Move& arc, const std::vector<Eigen::Vector3d>& c,
               const std::optional<Eigen::Vector3d>& start) {
  const std::size_t n = c.size();
  auto u_of = [&](std::size_t k) {
    return n > 1 ? static_cast<double>(k) / static_cast<double>(n - 1) : 0.0;
  };
  const double ridge = kCentreRidge * static_cast<double>(std::max<std::size_t>(n, 1));
  const Eigen::Vector3d rs = radial_at(arc, 0.0);
  ArcFit fit;
  if (!start) {
    Eigen::Matrix4d normal_matrix = Eigen::Matrix4d::Zero();
    Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
    for (std::size_t k = 0; k < n; ++k) {
      Eigen::Matrix<double, 3, 4> a;
      a << Eigen::Matrix3d::Identity(), radial_at(arc, u_of(k));
      normal_matrix += a.transpose() * a;
      rhs += a.transpose() * c[k];
    }
    normal_matrix.topLeftCorner<3, 3>() += ridge * Eigen::Matrix3d::Identity();
    const Eigen::Vector4d x = normal_matrix.ldlt().solve(rhs);
    fit.centre_offset_m = x.head<3>();
    fit.start_offset_m = x.head<3>() + x[3] * rs;
  } else {
    // The moved arc keeps the programmed sweep from the moved start, so
    // with P the projection on the plane, R_u the turn by u × sweep and
    // h = the normal, p'(u) − p(u) = P Δc + R_u P (start − Δc) + h (start·h
    // + u (Δc − start)·h): linear in Δc, and exactly what is built below.
    const Eigen::Matrix3d plane = Eigen::Matrix3d::Identity() - arc.normal * arc.normal.transpose();
    const Eigen::Matrix3d along = arc.normal * arc.normal.transpose();
    Eigen::Matrix3d normal_matrix = ridge * Eigen::Matrix3d::Identity();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < n; ++k) {
      const double u = u_of(k);
      const Eigen::Matrix3d turn =
          Eigen::AngleAxisd(u * arc.sweep_rad, arc.normal).toRotationMatrix();
      const Eigen::Matrix3d b = plane - turn * plane + u * along;
      const Eigen::Vector3d fixed = turn * plane * *start + (1.0 - u) * along * *start;
      normal_matrix += b.transpose() * b;
      rhs += b.transpose() * (c[k] - fixed);
    }
    fit.centre_offset_m = normal_matrix.ldlt().solve(rhs);
    fit.start_offset_m = *start;
  }
  // The moved circle: centre, radius and start direction in the arc's plane.
  const Eigen::Vector3d& normal = arc.normal;
  auto in_plane = [&](const Eigen::Vector3d& v) -> Eigen::Vector3d {
    return v - v.dot(normal) * normal;
  };
  const Eigen::Vector3d centre = arc.centre_m + fit.centre_offset_m;
  const Eigen::Vector3d moved_start = arc.start_m + fit.start_offset_m;
  const Eigen::Vector3d from_centre = in_plane(moved_start - centre);
  const double radius = from_centre.norm();
  fit.radius_change_m = radius - in_plane(arc.start_m - arc.centre_m).norm();
  const Eigen::Vector3d start_direction = radius > 0.0 ? Eigen::Vector3d(from_centre / radius) : rs;
  // Along the normal: from the moved start's height, rising as programmed
  // plus what the centre's and the start's offsets differ by.
  const double rise = (arc.end_m - arc.start_m).dot(normal) +
                      (fit.centre_offset_m - fit.start_offset_m).dot(normal);
  auto moved_at = [&](double u) -> Eigen::Vector3d {
    return in_plane(centre) +
           radius * (Eigen::AngleAxisd(u * arc.sweep_rad, normal) * start_direction) +
           (moved_start.dot(normal) + u * rise) * normal;
  };
  fit.end_offset_m = moved_at(1.0) - arc.end_m;
  for (std::size_t k = 0; k < n; ++k)
    fit.residual_m =
        std::max(fit.residual_m, (moved_at(u_of(k)) - position_at(arc, u_of(k)) - c[k]).norm());
  return fit;
}

// What each move may become (PathCorrections::corrections and kept).
struct Roles {
  const toolpath::Program& program;
  const std::vector<std::vector<Eigen::Vector3d>>& samples;
  const std::set<int>& keep;
  const WritableMoves* writable;
  double min_offset_m;
  std::size_t moves;
  std::map<int, int> moves_on_line;

  Roles(const toolpath::Program& p, const std::vector<std::vector<Eigen::Vector3d>>& s,
        const std::set<int>& k, const WritableMoves* w, double min_offset)
      : program(p),
        samples(s),
        keep(k),
        writable(w),
        min_offset_m(min_offset),
        moves(std::min(p.moves.size(), s.size())) {
    for (const toolpath::Move& move : program.moves)
      ++moves_on_line[move.line];
  }
  // The move's end can be written on its own.
  bool alone(std::size_t m) const {
    if (keep.count(program.moves[m].line))
      return false;
    if (writable)
      return m < writable->end.size() && writable->end[m];
    return moves_on_line.at(program.moves[m].line) == 1;
  }
  bool points_allowed(std::size_t m) const {
    return !writable || (m < writable->points.size() && writable->points[m]);
  }
  double largest(std::size_t m) const {
    double out = 0.0;
    for (const Eigen::Vector3d& v : samples[m])
      out = std::max(out, v.norm());
    return out;
  }
  // An arc whose circle can be rewritten.
  bool arc_editable(std::size_t m) const {
    return m < moves && program.moves[m].kind == toolpath::MotionKind::arc && alone(m);
  }
  // An arc with an error of its own to correct: its free fit pins the end of
  // the straight line before it.
  bool arc_corrected(std::size_t m) const {
    return arc_editable(m) && samples[m].size() >= 2 && largest(m) >= min_offset_m;
  }
  // The next move that moves (dwells stay where the path is).
  std::size_t next(std::size_t m) const {
    std::size_t k = m + 1;
    while (k < moves && program.moves[k].kind == toolpath::MotionKind::dwell)
      ++k;
    return k;
  }
  // A straight line whose points may move: not before an arc that must stay
  // (its centre is programmed from its start).
  bool line_editable(std::size_t m) const {
    if (program.moves[m].kind != toolpath::MotionKind::linear || !alone(m) || samples[m].size() < 2)
      return false;
    const std::size_t k = next(m);
    return k >= moves || program.moves[k].kind != toolpath::MotionKind::arc || arc_editable(k);
  }
  bool pins_arc(std::size_t m) const { return m + 1 < moves && arc_corrected(m + 1); }
  bool line_corrected(std::size_t m) const {
    return line_editable(m) && (largest(m) >= min_offset_m || pins_arc(m));
  }
};

}  // namespace

std::optional<Eigen::Vector3d> sample_correction(const toolpath::PathSample& sample,
                                                 const RobotSample& robot,
                                                 const CompensationSettings& settings) {
  if (!robot.reachable || !sample.analysed || sample.kind == toolpath::MotionKind::rapid ||
      sample.plunge)
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

void PathCorrections::add(const toolpath::PathSample& sample, const RobotSample& robot) {
  if (sample.move >= samples_.size())
    return;
  std::vector<Eigen::Vector3d>& c = samples_[sample.move];
  if (c.size() < sample.step)  // the air steps before it
    c.resize(sample.step, Eigen::Vector3d::Zero());
  c.push_back(sample_correction(sample, robot, settings_).value_or(Eigen::Vector3d::Zero()));
}

void PathCorrections::complete(const std::vector<toolpath::MoveTotals>& moves) {
  for (std::size_t m = 0; m < std::min(moves.size(), samples_.size()); ++m)
    if (moves[m].steps > 0 && samples_[m].size() < moves[m].steps + 1)
      samples_[m].resize(moves[m].steps + 1, Eigen::Vector3d::Zero());
}

std::vector<LineCorrection> PathCorrections::corrections(const toolpath::Program& program,
                                                         const std::set<int>& keep,
                                                         const WritableMoves* writable) const {
  const Roles roles(program, samples_, keep, writable, settings_.min_offset_m);
  const std::size_t moves = roles.moves;
  std::vector<LineCorrection> out;
  Eigen::Vector3d written_end = Eigen::Vector3d::Zero();  // the offset the path ends at so far
  bool start_pinned = false;  // the line before this arc was written to end on its free fit
  for (std::size_t m = 0; m < moves; ++m) {
    const toolpath::Move& move = program.moves[m];
    const std::vector<Eigen::Vector3d> c = median5(samples_[m]);
    const Eigen::Vector3d start = written_end;
    const bool pinned = start_pinned;
    start_pinned = false;
    if (move.kind != toolpath::MotionKind::dwell)  // a dwell stays where the path ended
      written_end = Eigen::Vector3d::Zero();
    if (move.kind == toolpath::MotionKind::arc) {
      const bool moved_start = start.squaredNorm() > 0.0;
      if (!roles.arc_corrected(m) && !(roles.arc_editable(m) && moved_start))
        continue;
      const ArcFit fit =
          fit_arc(move, c, pinned ? std::nullopt : std::optional<Eigen::Vector3d>(start));
      LineCorrection arc;
      arc.move = m;
      arc.line = move.line;
      arc.offset_m = fit.end_offset_m;
      arc.arc = ArcCorrection{fit.centre_offset_m, fit.radius_change_m, fit.residual_m};
      out.push_back(std::move(arc));
      written_end = fit.end_offset_m;
      continue;
    }
    if (!roles.line_corrected(m))
      continue;
    std::vector<Eigen::Vector3d> ends = c;
    if (roles.pins_arc(m)) {  // the moved arc starts here
      ends.back() =
          fit_arc(program.moves[m + 1], median5(samples_[m + 1]), std::nullopt).start_offset_m;
      start_pinned = true;
    } else if (m + 1 < moves && program.moves[m + 1].kind == toolpath::MotionKind::linear &&
               roles.line_corrected(m + 1)) {
      // A corner: the next line starts here and finishes a wall of its own.
      ends.back() = combined(ends.back(), median5(samples_[m + 1]).front());
    }
    std::vector<std::size_t> kept;
    simplify(ends, start, 0, ends.size() - 1, settings_.tolerance_m, kept);
    if (!roles.points_allowed(m)) {
      kept.clear();  // the end alone moves: a straight line from the moved start
      if (ends.back().norm() < settings_.min_offset_m)
        continue;  // its end stays: nothing to write
    }
    if (kept.size() > static_cast<std::size_t>(settings_.max_points)) {  // evenly thinned
      std::vector<std::size_t> thinned;
      for (int i = 0; i < settings_.max_points; ++i)
        thinned.push_back(kept[i * kept.size() / static_cast<std::size_t>(settings_.max_points)]);
      kept = thinned;
    }
    LineCorrection line;
    line.move = m;
    line.line = move.line;
    line.offset_m = ends.back();
    for (const std::size_t k : kept)
      line.points.push_back(
          {static_cast<double>(k) / static_cast<double>(ends.size() - 1), ends[k]});
    out.push_back(std::move(line));
    written_end = ends.back();
  }
  return out;
}

std::vector<PathCorrections::Kept> PathCorrections::kept(const toolpath::Program& program,
                                                         const std::set<int>& keep,
                                                         const WritableMoves* writable) const {
  const Roles roles(program, samples_, keep, writable, settings_.min_offset_m);
  std::vector<Kept> out;
  for (std::size_t m = 0; m < roles.moves; ++m) {
    const toolpath::Move& move = program.moves[m];
    if (move.kind != toolpath::MotionKind::linear && move.kind != toolpath::MotionKind::arc)
      continue;
    if (roles.largest(m) < settings_.min_offset_m || keep.count(move.line) ||
        (!out.empty() && out.back().line == move.line))
      continue;
    if (writable && !roles.alone(m))
      out.push_back({move.line, m < writable->reason.size() && !writable->reason[m].empty()
                                    ? writable->reason[m]
                                    : std::string("its end point cannot be written on its own")});
    else if (!writable && roles.moves_on_line.at(move.line) != 1)
      out.push_back(
          {move.line, "one of several moves on its line (a loop, a cycle, an arc in pieces)"});
    else if (move.kind == toolpath::MotionKind::linear && !roles.line_editable(m))
      out.push_back({move.line,
                     "before an arc that stays as programmed, whose centre is programmed from "
                     "its start"});
  }
  return out;
}

std::vector<Eigen::Vector3d> corrected_ends(const toolpath::Program& program,
                                            const std::vector<LineCorrection>& corrections) {
  std::map<std::size_t, const LineCorrection*> by_move;
  for (const LineCorrection& c : corrections)
    by_move[c.move] = &c;
  std::vector<Eigen::Vector3d> ends;
  Eigen::Vector3d carried = Eigen::Vector3d::Zero();  // a dwell stays where the path ended
  for (std::size_t m = 0; m < program.moves.size(); ++m) {
    const toolpath::Move& move = program.moves[m];
    const auto it = by_move.find(m);
    if (it == by_move.end()) {
      ends.push_back(move.end_m + (move.kind == toolpath::MotionKind::dwell
                                       ? carried
                                       : Eigen::Vector3d(Eigen::Vector3d::Zero())));
      if (move.kind != toolpath::MotionKind::dwell)
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

}  // namespace robomill::robot_path
