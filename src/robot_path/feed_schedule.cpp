#include "robomill/robot_path/feed_schedule.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"

namespace robomill::robot_path {
namespace {

bool feeds(const toolpath::Move& move) {
  return (move.kind == toolpath::MotionKind::linear || move.kind == toolpath::MotionKind::arc) &&
         move.feed_m_s > 0.0;
}

void merge(MoveLoads& into, const MoveLoads& loads) {
  into.measured = into.measured || loads.measured;
  into.force_peak_n = std::max(into.force_peak_n, loads.force_peak_n);
  into.torque_peak_nm = std::max(into.torque_peak_nm, loads.torque_peak_nm);
  into.deflection_m = std::max(into.deflection_m, loads.deflection_m);
  into.joint_speed_rad_s = std::max(into.joint_speed_rad_s, loads.joint_speed_rad_s);
}

// The worst of the load caps (joint speeds are a bound on s, not a ratio).
struct Ratio {
  double value = 0.0;
  const char* cap = "";
};

Ratio load_ratio(const MoveLoads& loads, const FeedLimits& limits) {
  Ratio worst;
  if (!loads.measured)
    return worst;
  auto consider = [&](double load, double cap, const char* name) {
    if (cap > 0.0 && load / cap > worst.value)
      worst = {load / cap, name};
  };
  consider(loads.force_peak_n, limits.force_max_n, "force");
  consider(loads.torque_peak_nm, limits.torque_max_nm, "torque");
  consider(loads.deflection_m, limits.deflection_max_m, "deflection");
  return worst;
}

bool load_capped(const FeedLimits& limits) {
  return limits.force_max_n > 0.0 || limits.torque_max_nm > 0.0 || limits.deflection_max_m > 0.0;
}

std::string load_text(const MoveLoads& loads, const char* cap, const FeedLimits& limits) {
  const std::string name = cap;
  if (name == "force")
    return fmt::format("the peak force {:.1f} N exceeds force_max {:.1f} N", loads.force_peak_n,
                       limits.force_max_n);
  if (name == "torque")
    return fmt::format("the peak torque {:.3f} N*m exceeds torque_max {:.3f} N*m",
                       loads.torque_peak_nm, limits.torque_max_nm);
  return fmt::format("the tool-tip deflection {:.1f} um exceeds deflection_max {:.1f} um",
                     loads.deflection_m * 1e6, limits.deflection_max_m * 1e6);
}

// Per line, the search's state.
struct LineState {
  double low = 0.0, high = 1.0;  // the feed scale's range
  const char* high_bound = "";   // what sets `high`: "feed_max", "joint_speed" or none
  double previous_scale = 0.0, previous_ratio = 0.0;
  bool has_previous = false;
  double measured_scale = 1.0;  // the scale of the latest measurement, and what it gave
  MoveLoads measured;
  Ratio measured_ratio;
  bool done = false;
};

// The lines to schedule: each program line's feed moves, at the slowest
// feed programmed on it.
void collect_lines(const toolpath::Program& program, FeedSchedule& schedule) {
  std::unordered_map<int, std::size_t> line_index;
  for (std::size_t m = 0; m < program.moves.size(); ++m) {
    const toolpath::Move& move = program.moves[m];
    if (!feeds(move))
      continue;
    auto [it, added] = line_index.try_emplace(move.line, schedule.lines.size());
    if (added) {
      LineFeed& line = schedule.lines.emplace_back();
      line.line = move.line;
      line.programmed_m_s = move.feed_m_s;
    }
    LineFeed& line = schedule.lines[it->second];
    line.moves.push_back(m);
    line.programmed_m_s = std::min(line.programmed_m_s, move.feed_m_s);
  }
}

MoveLoads line_loads(const std::vector<MoveLoads>& loads, const LineFeed& line) {
  MoveLoads total;
  for (std::size_t m : line.moves)
    if (m < loads.size())
      merge(total, loads[m]);
  return total;
}

void set_scale(std::vector<double>& scale, const LineFeed& line, double s) {
  for (std::size_t m : line.moves)
    scale[m] = s;
}

[[noreturn]] void infeasible(const FeedLimits& limits, const LineFeed& line, const LineState& state,
                             const std::string& why) {
  throw InputError(
      "robot_path.feed_limits", limits.job_line,
      fmt::format("program line {}: {} at {:.1f} mm/min, the slowest feed allowed there ({}); "
                  "no feed satisfies the limits: raise the cap, lower feed_min, or change the "
                  "line's depth or width",
                  line.line, why, line.programmed_m_s * state.low * 6e4,
                  limits.feed_min_m_s > 0.0
                      ? fmt::format("feed_min {:.1f} mm/min", limits.feed_min_m_s * 6e4)
                      : fmt::format("{:g} % of the programmed {:.1f} mm/min",
                                    limits.min_scale * 100.0, line.programmed_m_s * 6e4)));
}

// A line after the first run (the programmed feeds): its range of scales,
// and either done or its first guess set in `scale`.
void start_line(const std::vector<MoveLoads>& loads, const FeedLimits& limits, LineFeed& line,
                LineState& state, FeedSchedule& schedule, std::vector<double>& scale) {
  line.before = line_loads(loads, line);
  const Ratio ratio = load_ratio(line.before, limits);
  line.ratio_before = ratio.value;
  merge(schedule.max_before, line.before);
  state.measured = line.before;
  state.measured_ratio = ratio;
  state.low = limits.feed_min_m_s > 0.0 ? std::min(1.0, limits.feed_min_m_s / line.programmed_m_s)
                                        : limits.min_scale;
  state.high = 1.0;
  if (limits.feed_max_m_s > 0.0) {
    // A line programmed faster than feed_max comes down to it.
    state.high = limits.feed_max_m_s / line.programmed_m_s;
    state.high_bound = "feed_max";
  }
  // Joint speeds scale exactly with the feed: the same path in s times
  // less time.
  if (limits.joint_speed_max_rad_s > 0.0 && line.before.joint_speed_rad_s > 0.0) {
    const double joint_scale = limits.joint_speed_max_rad_s / line.before.joint_speed_rad_s;
    if (joint_scale < state.high) {
      state.high = joint_scale;
      state.high_bound = "joint_speed";
    }
  }
  if (state.high < state.low)
    infeasible(limits, line, state,
               fmt::format("a joint turns at {:.1f} deg/s, over joint_speed_max {:.1f} deg/s",
                           line.before.joint_speed_rad_s * state.low * kDegPerRad,
                           limits.joint_speed_max_rad_s * kDegPerRad));
  if (!line.before.measured || !load_capped(limits)) {
    // Nothing to weigh but the joint speed: a bound, met exactly.
    set_scale(scale, line, std::min(1.0, state.high));
    state.done = true;
    return;
  }
  // Under the caps with nothing to gain (no faster feed allowed, or close
  // to the caps already): kept, or slowed to the joint-speed bound, which
  // only lowers the loads.
  if (ratio.value <= 1.0 &&
      (state.high <= 1.0 || ratio.value >= limits.target - limits.tolerance)) {
    set_scale(scale, line, std::min(1.0, state.high));
    state.done = true;
    return;
  }
  state.previous_scale = 1.0;
  state.previous_ratio = ratio.value;
  state.has_previous = true;
  const double guess = ratio.value > 0.0 ? limits.target / ratio.value : state.high;
  set_scale(scale, line, std::clamp(guess, state.low, state.high));
}

// One open line after a run: done, or its next secant step set in `scale`.
void step_line(const std::vector<MoveLoads>& loads, const FeedLimits& limits, const LineFeed& line,
               LineState& state, std::vector<double>& scale) {
  const double s = scale[line.moves.front()];
  state.measured = line_loads(loads, line);
  state.measured_ratio = load_ratio(state.measured, limits);
  state.measured_scale = s;
  const double r = state.measured_ratio.value;
  if (r <= 1.0 && (s >= state.high * (1.0 - 1e-12) || r >= limits.target - limits.tolerance)) {
    state.done = true;
    return;
  }
  if (r > 1.0 && s <= state.low * (1.0 + 1e-12))
    infeasible(limits, line, state, load_text(state.measured, state.measured_ratio.cap, limits));
  double next = s * limits.target / std::max(r, 1e-12);
  if (state.has_previous && r != state.previous_ratio && s != state.previous_scale) {
    const double slope = (r - state.previous_ratio) / (s - state.previous_scale);
    if (slope > 0.0 && std::isfinite(slope))
      next = s + (limits.target - r) / slope;
  }
  if (r > 1.0 && !(next < s))
    next = s * limits.target / r;  // an over-cap line always slows
  state.previous_scale = s;
  state.previous_ratio = r;
  state.has_previous = true;
  set_scale(scale, line, std::clamp(next, state.low, state.high));
}

// A line at the scale its latest measurement was made at; a line still over
// its cap after max_runs is reported, never passed.
void finish_line(const FeedLimits& limits, LineFeed& line, LineState& state, FeedSchedule& schedule,
                 std::vector<double>& scale) {
  if (!state.done) {
    if (state.measured_ratio.value > 1.0)
      throw InputError(
          "robot_path.feed_limits", limits.job_line,
          fmt::format("program line {}: no feed found within {} runs of the program: at "
                      "{:.1f} mm/min {}",
                      line.line, limits.max_runs, line.programmed_m_s * state.measured_scale * 6e4,
                      load_text(state.measured, state.measured_ratio.cap, limits)));
    set_scale(scale, line, state.measured_scale);
  }
  line.scale = scale[line.moves.front()];
  line.after = state.measured;
  line.ratio_after = state.measured_ratio.value;
  if (line.scale != state.measured_scale || !line.before.measured || !load_capped(limits)) {
    // Bounded by the joint speed alone, or slowed to it without a
    // measurement: the loads scale down with the feed, so the first run's
    // bound them from above; the joint speed scales exactly.
    line.after = line.before;
    line.after.joint_speed_rad_s = line.before.joint_speed_rad_s * line.scale;
    line.ratio_after = line.ratio_before;
  }
  if (line.changed()) {
    const bool at_high = line.scale >= state.high * (1.0 - 1e-12) && state.high != 1.0;
    line.binding = at_high ? state.high_bound : state.measured_ratio.cap;
    if (line.binding.empty())
      line.binding = state.high_bound;
  }
  merge(schedule.max_after, line.after);
}

}  // namespace

FeedSchedule schedule_feeds(const toolpath::Program& program, const FeedLimits& limits,
                            const FeedMeasurement& measure) {
  if (!limits.any_cap())
    throw std::invalid_argument("feed schedule: no cap (force, torque, deflection, joint speed)");
  if (!(limits.feed_min_m_s >= 0.0) || !(limits.feed_max_m_s >= 0.0) ||
      (limits.feed_max_m_s > 0.0 && limits.feed_max_m_s < limits.feed_min_m_s) ||
      !(limits.target > 0.0 && limits.target <= 1.0) ||
      !(limits.tolerance >= 0.0 && limits.tolerance < limits.target) || limits.max_runs < 2 ||
      !(limits.min_scale > 0.0 && limits.min_scale <= 1.0))
    throw std::invalid_argument("feed schedule: inconsistent limits");

  FeedSchedule schedule;
  collect_lines(program, schedule);
  std::vector<double> scale(program.moves.size(), 1.0);

  // The first run: the programmed feeds.
  std::vector<MoveLoads> loads = measure(scale);
  schedule.runs = 1;
  std::vector<LineState> states(schedule.lines.size());
  for (std::size_t i = 0; i < schedule.lines.size(); ++i)
    start_line(loads, limits, schedule.lines[i], states[i], schedule, scale);

  // Secant steps on every open line, each run measuring them all.
  auto open_lines = [&] {
    for (std::size_t i = 0; i < states.size(); ++i)
      if (!states[i].done)
        return true;
    return false;
  };
  while (open_lines() && schedule.runs < limits.max_runs) {
    loads = measure(scale);
    ++schedule.runs;
    for (std::size_t i = 0; i < schedule.lines.size(); ++i) {
      LineState& state = states[i];
      if (state.done)
        continue;
      step_line(loads, limits, schedule.lines[i], state, scale);
    }
  }

  // Every line at the scale its latest measurement was made at.
  for (std::size_t i = 0; i < schedule.lines.size(); ++i)
    finish_line(limits, schedule.lines[i], states[i], schedule, scale);
  return schedule;
}

std::vector<MoveLoads> measure_move_loads(
    const toolpath::Program& program, const std::vector<double>& feed_scale,
    const toolpath::Tooling& tooling, const cutting::CuttingLaw& law, toolpath::DexelStock stock,
    const toolpath::ProgramAnalysisSettings& settings,
    const std::function<std::unique_ptr<RobotAlongPath>()>& make_robot) {
  toolpath::Program scaled = program;
  for (std::size_t m = 0; m < scaled.moves.size() && m < feed_scale.size(); ++m)
    scaled.moves[m].feed_m_s *= feed_scale[m];
  std::vector<MoveLoads> loads(program.moves.size());
  std::unique_ptr<RobotAlongPath> robot = make_robot ? make_robot() : nullptr;
  std::vector<RobotSample> robot_block;
  // The previous sample of the same move, for the joint speeds.
  std::size_t last_move = static_cast<std::size_t>(-1);
  double last_t_s = 0.0;
  RobotSample::Joints last_q;
  bool last_reachable = false;
  const auto sink = [&](std::span<const toolpath::PathSample> block) {
    if (robot) {
      robot_block.resize(block.size());
      robot->evaluate(block, robot_block);
    }
    for (std::size_t i = 0; i < block.size(); ++i) {
      const toolpath::PathSample& sample = block[i];
      MoveLoads& move = loads[sample.move];
      if (sample.analysed && sample.axial_depth_m > 0.0 &&
          sample.kind != toolpath::MotionKind::rapid) {
        move.measured = true;
        move.force_peak_n = std::max(move.force_peak_n, sample.force_peak_n);
        move.torque_peak_nm = std::max(move.torque_peak_nm, sample.torque_peak_nm);
      }
      if (!robot)
        continue;
      const RobotSample& r = robot_block[i];
      if (r.reachable && sample.kind != toolpath::MotionKind::rapid)
        move.deflection_m = std::max(move.deflection_m, r.deflection_m.norm());
      if (r.reachable && last_reachable && last_move == sample.move && sample.t_s > last_t_s &&
          sample.kind != toolpath::MotionKind::rapid) {
        const double joint_step = (r.q_rad - last_q).cwiseAbs().maxCoeff();
        move.joint_speed_rad_s =
            std::max(move.joint_speed_rad_s, joint_step / (sample.t_s - last_t_s));
      }
      last_move = sample.move;
      last_t_s = sample.t_s;
      last_q = r.q_rad;
      last_reachable = r.reachable;
    }
  };
  analyse_program(scaled, tooling, law, stock, settings, sink);
  return loads;
}

}  // namespace robomill::robot_path
