#include "robomill/toolpath/program_analysis.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <future>
#include <map>
#include <optional>

#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"
#include "robomill/core/parallel.hpp"
#include "robomill/cutting/milling_forces.hpp"

namespace robomill::toolpath {
namespace {

// A cutter ready for the program: the validated tool, its solid and its
// engagement grid on this stock.
struct Cutter {
  const tool::Tool* tool = nullptr;
  CutterShape shape;
  EngagementGrid grid;
};

// The geometry of one sample, kept until the block's forces are computed.
struct SampleGeometry {
  CutterEngagement engagement;
  Eigen::Matrix3d tool_to_workpiece = Eigen::Matrix3d::Identity();  // columns x, y, z
  double axial_feed_per_tooth_m = 0.0;
  const Cutter* cutter = nullptr;
};

// The local tool frame of cutter_engagement.hpp: z the axis, x the feed's part
// normal to it (any normal direction for a plunge), y = z × x.
Eigen::Matrix3d local_frame(const Eigen::Vector3d& axis, const Eigen::Vector3d& feed,
                            bool& plunge) {
  Eigen::Vector3d x = feed - feed.dot(axis) * axis;
  plunge = x.norm() < 1e-6;
  if (plunge)
    x = axis.unitOrthogonal();
  x.normalize();
  Eigen::Matrix3d frame;
  frame.col(0) = x;
  frame.col(1) = axis.cross(x);
  frame.col(2) = axis;
  return frame;
}

// Collects warnings by text: the first line and how often.
class Warnings {
 public:
  void add(int line, std::string text) {
    for (ProgramAnalysis::Warning& warning : list_) {
      if (warning.text == text) {
        ++warning.count;
        return;
      }
    }
    list_.push_back({line, std::move(text), 1});
  }
  std::vector<ProgramAnalysis::Warning> take() { return std::move(list_); }

 private:
  std::vector<ProgramAnalysis::Warning> list_;
};

// The loads of one engaged sample over a tooth period (a revolution with
// runout), with the force mechanism of `robomill forces`.
void compute_loads(const cutting::CuttingLaw& law, const SampleGeometry& geometry,
                   int steps_per_tooth, PathSample& sample) {
  const CutterEngagement& engagement = geometry.engagement;
  const tool::Tool& tool = *geometry.cutter->tool;
  cutting::GeneralEngagement general;
  general.spindle_rad_s = sample.spindle_rad_s;
  general.feed_per_tooth_m = sample.feed_per_tooth_m;
  general.axial_feed_per_tooth_m = geometry.axial_feed_per_tooth_m;
  general.axial_depth_m = std::min(engagement.axial_depth_m, tool.overhang_m());
  // The edge below the lowest engaged slice is in air (the tip below the
  // material): the elements start at that slice's bottom.
  for (const EngagementSlice& slice : engagement.slices) {
    if (slice.arc_count > 0) {
      general.edge_from_m = slice.height_m - 0.5 * slice.thickness_m;
      break;
    }
  }
  general.slice_top_m.reserve(engagement.slices.size());
  general.arcs.reserve(engagement.slices.size());
  for (const EngagementSlice& slice : engagement.slices) {
    general.slice_top_m.push_back(slice.height_m + 0.5 * slice.thickness_m);
    std::vector<cutting::Engagement>& arcs = general.arcs.emplace_back();
    for (int a = 0; a < slice.arc_count; ++a)
      arcs.push_back({slice.arcs[a].entry_rad, slice.arcs[a].exit_rad});
  }
  const cutting::MillingForceModel model(
      tool, law, general,
      cutting::default_axial_elements(tool, general.axial_depth_m - general.edge_from_m));
  const bool runout = tool.runout().offset_m > 0.0;
  const int steps = steps_per_tooth * (runout ? tool.teeth() : 1);
  const double period_rad = kTwoPi / (runout ? 1.0 : static_cast<double>(tool.teeth()));
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double peak = 0.0, torque_mean = 0.0, torque_peak = 0.0;
  for (int k = 0; k < steps; ++k) {
    const cutting::ToolLoad load = model.at(period_rad * k / steps);
    mean += load.force_n;
    peak = std::max(peak, load.force_n.norm());
    torque_mean += load.torque_nm;
    torque_peak = std::max(torque_peak, std::abs(load.torque_nm));
  }
  mean /= steps;
  torque_mean /= steps;
  sample.force_mean_n = geometry.tool_to_workpiece * mean;
  sample.force_mean_magnitude_n = mean.norm();
  sample.force_peak_n = peak;
  sample.torque_mean_nm = torque_mean;
  sample.torque_peak_nm = torque_peak;
  sample.power_w = torque_mean * sample.spindle_rad_s;
}

}  // namespace

double default_sample_spacing_m(double feed_per_tooth_m, double resolution_m) noexcept {
  return std::max(3.0 * feed_per_tooth_m, 0.5 * resolution_m);
}

double cutter_reach_m(const CutterShape& shape) noexcept {
  return std::hypot(shape.radius_m, shape.length_m);
}

MoveStretch move_near_box(const Move& move, const StockBox& box, double distance_m) noexcept {
  const Eigen::Vector3d lo = box.min_m.array() - distance_m;
  const Eigen::Vector3d hi = box.max_m.array() + distance_m;
  MoveStretch stretch;
  if (move.kind == MotionKind::arc) {
    // Every point of the arc lies within its radius of the centre in the
    // plane, and between the start's and the end's heights along the normal.
    const Eigen::Vector3d from_centre = move.start_m - move.centre_m;
    const double radius = (from_centre - from_centre.dot(move.normal) * move.normal).norm();
    const Eigen::Vector3d plane_centre = move.centre_m + from_centre.dot(move.normal) * move.normal;
    const Eigen::Vector3d rise = (move.end_m - move.start_m).dot(move.normal) * move.normal;
    const Eigen::Vector3d a = plane_centre.cwiseMin(plane_centre + rise).array() - radius;
    const Eigen::Vector3d b = plane_centre.cwiseMax(plane_centre + rise).array() + radius;
    if ((a.array() > hi.array()).any() || (b.array() < lo.array()).any())
      stretch.from_u = 2.0, stretch.to_u = -1.0;
    return stretch;
  }
  // A straight move (a dwell stays at its start): clipped slab by slab.
  const Eigen::Vector3d d = move.kind == MotionKind::dwell
                                ? Eigen::Vector3d::Zero()
                                : Eigen::Vector3d(move.end_m - move.start_m);
  for (int a = 0; a < 3; ++a) {
    const double s = move.start_m[a];
    if (d[a] == 0.0) {
      if (s < lo[a] || s > hi[a])
        return {2.0, -1.0};
      continue;
    }
    double t0 = (lo[a] - s) / d[a], t1 = (hi[a] - s) / d[a];
    if (t0 > t1)
      std::swap(t0, t1);
    stretch.from_u = std::max(stretch.from_u, t0);
    stretch.to_u = std::min(stretch.to_u, t1);
  }
  if (stretch.empty())
    return {2.0, -1.0};
  return stretch;
}

namespace {

// The cutters of the tooling, each with its engagement grid on this stock.
std::map<int, Cutter> make_cutters(const Tooling& tooling, const ProgramAnalysisSettings& settings,
                                   const DexelStock& stock) {
  std::map<int, Cutter> cutters;
  for (const auto& [number, tool] : tooling) {
    Cutter cutter;
    cutter.tool = &tool;
    cutter.shape = cutter_shape(tool);
    cutter.grid = settings.grid.slice_height_m > 0.0
                      ? settings.grid
                      : default_engagement_grid(cutter.shape, stock.resolution_m());
    cutters.emplace(number, cutter);
  }
  return cutters;
}

// The cutter of tool `number`, else of T0; null when neither is described.
const Cutter* cutter_of(const std::map<int, Cutter>& cutters, int number) {
  auto it = cutters.find(number);
  if (it == cutters.end())
    it = cutters.find(0);
  return it == cutters.end() ? nullptr : &it->second;
}

// Two blocks: this thread fills one with samples and their geometry (the
// engagement on the stock and the removal, which depend on every sample
// before) while a worker computes the other's forces (each sample
// independent once its engagement is known, in parallel), its per-move
// maxima and hands it to the sink, in program order. The results are those
// of doing it all in turn; only the sink runs on the worker's thread.
struct Block {
  std::vector<PathSample> samples;
  std::vector<SampleGeometry> geometry;
};

class BlockPipeline {
 public:
  BlockPipeline(const cutting::CuttingLaw& law, const ProgramAnalysisSettings& settings,
                const SampleSink& sink, ProgramAnalysis& result)
      : law_(law), settings_(settings), sink_(sink), result_(result) {
    for (Block& b : blocks_) {
      b.samples.reserve(settings.block_samples);
      b.geometry.reserve(settings.block_samples);
    }
  }

  Block& filling() { return *filling_; }

  // Hands the filled block to the worker (or finishes it here) and fills
  // the other.
  void flush() {
    wait_pending();  // the other block is free again
    Block& full = *filling_;
    result_.samples += full.samples.size();
    if (settings_.overlap_blocks)
      pending_ = std::async(std::launch::async, [this, &full] { finish(full); });
    else
      finish(full);
    filling_ = filling_ == &blocks_[0] ? &blocks_[1] : &blocks_[0];
  }

  void wait_pending() {
    if (pending_.valid())
      pending_.get();  // rethrows what the worker threw
  }

 private:
  void finish(Block& full) {
    std::vector<PathSample>& block = full.samples;
    std::vector<SampleGeometry>& geometry = full.geometry;
    core::parallel_for(block.size(), settings_.threads, [&](std::size_t i) {
      PathSample& sample = block[i];
      if (sample.analysed && !geometry[i].engagement.empty() && sample.kind != MotionKind::rapid) {
        try {
          compute_loads(law_, geometry[i], settings_.force_steps_per_tooth, sample);
        } catch (const std::invalid_argument& error) {  // the law cannot take this cut
          throw InputError(settings_.source_name, sample.line,
                           fmt::format("the cut at this line: {}", error.what()));
        }
      }
    });
    ProgramAnalysis& result = result_;
    for (const PathSample& sample : block) {
      MoveTotals& totals = result.moves[sample.move];
      totals.max_force_n = std::max(totals.max_force_n, sample.force_peak_n);
      totals.max_torque_nm = std::max(totals.max_torque_nm, sample.torque_peak_nm);
      totals.max_power_w = std::max(totals.max_power_w, sample.power_w);
      if (sample.force_peak_n > result.max_force_n) {
        result.max_force_n = sample.force_peak_n;
        result.max_force_line = sample.line;
      }
      if (sample.torque_peak_nm > result.max_torque_nm) {
        result.max_torque_nm = sample.torque_peak_nm;
        result.max_torque_line = sample.line;
      }
      if (sample.power_w > result.max_power_w) {
        result.max_power_w = sample.power_w;
        result.max_power_line = sample.line;
      }
    }
    if (sink_ && !block.empty())
      sink_(std::span<const PathSample>(block.data(), block.size()));
    block.clear();
    geometry.clear();
  }

  const cutting::CuttingLaw& law_;
  const ProgramAnalysisSettings& settings_;
  const SampleSink& sink_;
  ProgramAnalysis& result_;
  Block blocks_[2];
  Block* filling_ = &blocks_[0];
  std::future<void> pending_;  // the worker's block
};

// One move as it is sampled: its cutter, speeds and the steps near the stock.
struct MoveSampling {
  const Move* move = nullptr;
  std::size_t m = 0;
  const Cutter* cutter = nullptr;
  bool feed_move = false;
  double move_start_s = 0.0;
  double spindle_rad_s = 0.0;
  double feed_per_tooth_m = 0.0;
  double spacing_m = 0.0;
  std::size_t steps = 0;
  double step_m = 0.0;
  double lookahead_m = 0.0;
  std::size_t first = 1, last = 0;  // the near steps; none
};

// A move's totals from the program alone (length, time) and the program's
// times; returns the move's start time.
double open_move(const Move& move, std::size_t m, const ProgramAnalysisSettings& settings,
                 MoveTotals& totals, ProgramAnalysis& result, Warnings& warnings, double& time_s) {
  totals.move = m;
  totals.line = move.line;
  totals.tool = move.tool;
  totals.kind = move.kind;
  totals.length_m = path_length_m(move);
  totals.time_s = duration_s(move, settings.rapid_speed_m_s);
  totals.feed_m_s = move.feed_m_s;
  totals.spindle_rad_s = move.spindle_rad_s;
  if (totals.length_m > kImplausibleMoveM)
    warnings.add(move.line,
                 fmt::format("a move {:.6g} km long: no machine travels that far in one block "
                             "(a mistyped coordinate or unit?); its stretch away from the "
                             "stock is timed, not sampled",
                             totals.length_m * 1e-3));
  const double move_start_s = time_s;
  time_s += totals.time_s;
  switch (move.kind) {
    case MotionKind::rapid:
      result.air_time_s += totals.time_s;
      break;
    case MotionKind::dwell:
      result.dwell_time_s += totals.time_s;
      break;
    default:
      result.cutting_time_s += totals.time_s;
  }
  return move_start_s;
}

// The move's spindle speed, feed per tooth and sample spacing.
void move_speeds(const ProgramAnalysisSettings& settings, const DexelStock& stock,
                 Warnings& warnings, MoveSampling& s) {
  const Move& move = *s.move;
  const tool::Tool& tool = *s.cutter->tool;
  const std::size_t m = s.m;
  double spindle_rad_s = std::abs(move.spindle_rad_s);
  if (spindle_rad_s == 0.0)
    spindle_rad_s = settings.default_spindle_rad_s;
  if (move.spindle_rad_s < 0.0)
    warnings.add(move.line,
                 "counter-clockwise spindle (M4/CCW): forces computed for clockwise rotation");
  const double revolutions_per_s = spindle_rad_s / kTwoPi;
  const double feed_per_tooth_m =
      spindle_rad_s > 0.0 ? move.feed_m_s / (tool.teeth() * revolutions_per_s) : 0.0;
  const double move_spacing_m =
      m < settings.move_spacing_m.size() ? settings.move_spacing_m[m] : 0.0;
  const double spacing_m = move_spacing_m > 0.0 ? move_spacing_m
                           : settings.sample_spacing_m > 0.0
                               ? settings.sample_spacing_m
                               : default_sample_spacing_m(feed_per_tooth_m, stock.resolution_m());
  s.spindle_rad_s = spindle_rad_s;
  s.feed_per_tooth_m = feed_per_tooth_m;
  s.spacing_m = spacing_m;
}

// The move's steps, the probe's lookahead and the steps near the stock (the
// rest is air, timed and left out); where the cutter is left before the
// first near step.
void near_steps(const ProgramAnalysisSettings& settings, const DexelStock& stock,
                MoveTotals& totals, ProgramAnalysis& result, MoveSampling& s,
                std::optional<Eigen::Vector3d>& last_tip,
                std::optional<Eigen::Vector3d>& last_axis) {
  const Move& move = *s.move;
  const Cutter* cutter = s.cutter;
  const std::size_t m = s.m;
  totals.spacing_m = s.spacing_m;
  const std::size_t steps =
      m < settings.move_steps.size() && settings.move_steps[m] > 0
          ? settings.move_steps[m]
          : std::max<std::size_t>(
                1, static_cast<std::size_t>(std::ceil(totals.length_m / s.spacing_m - 1e-9)));
  totals.steps = steps;
  const double step_m = totals.length_m / static_cast<double>(steps);
  const double inset_m = surface_inset_m(cutter->grid, cutter->shape, stock.resolution_m());
  const double lookahead_m =
      std::max(0.5 * step_m, std::sqrt(4.0 * cutter->shape.radius_m * inset_m) - step_m);

  // The steps near the stock. A step whose tip is farther from the box
  // than the cutter reaches, plus the probe's lookahead, a step and a
  // cell, neither engages material (its probe is beyond the cutter's reach
  // too) nor removes any (nor does the sweep to it from a neighbour, which
  // is a step away): it is air, and left out. Along a straight move the
  // near steps are consecutive, [first, last].
  const MoveStretch near = settings.sample_air
                               ? MoveStretch{}
                               : move_near_box(move, stock.box(),
                                               cutter_reach_m(cutter->shape) + lookahead_m +
                                                   step_m + stock.resolution_m());
  const double steps_d = static_cast<double>(steps);
  std::size_t first = 1, last = 0;  // none
  if (!near.empty()) {
    first = static_cast<std::size_t>(std::max(0.0, std::ceil(near.from_u * steps_d - 1e-6)));
    last = static_cast<std::size_t>(
        std::min(steps_d, std::max(0.0, std::floor(near.to_u * steps_d + 1e-6))));
  }
  const std::size_t sampled_steps = first <= last ? last - first : 0;
  totals.unsampled_length_m =
      first <= last ? totals.length_m * static_cast<double>(steps - sampled_steps) / steps_d
                    : totals.length_m;
  result.unsampled_length_m += totals.unsampled_length_m;
  if (totals.length_m > 0.0)
    result.unsampled_time_s += totals.time_s * totals.unsampled_length_m / totals.length_m;
  // The sweep into the first near step starts where the air step before
  // it would have left the cutter.
  if (first > 0 && first <= last) {
    const double u = static_cast<double>(first - 1) / steps_d;
    last_tip = position_at(move, u);
    last_axis = axis_at(move, u);
  }
  s.steps = steps;
  s.step_m = step_m;
  s.lookahead_m = lookahead_m;
  s.first = first;
  s.last = last;
}

// The sample at step k (u = k / steps) from the program: its place, pose,
// feed and frame. True for a plunge along the axis.
bool start_sample(const MoveSampling& s, const MoveTotals& totals, std::size_t k, double u,
                  PathSample& sample, SampleGeometry& geo) {
  const Move& move = *s.move;
  sample.move = s.m;
  sample.move_fraction = u;
  sample.step = k;
  sample.line = move.line;
  sample.tool = move.tool;
  sample.kind = move.kind;
  sample.t_s = s.move_start_s + u * totals.time_s;
  sample.tip_m = position_at(move, u);
  sample.axis = axis_at(move, u);
  sample.feed_direction = tangent_at(move, u);
  sample.oriented = move.oriented;
  if (move.oriented)
    sample.tool_x = tool_x_at(move, u);
  sample.feed_m_s = move.feed_m_s;
  sample.spindle_rad_s = s.spindle_rad_s;

  bool plunge = false;
  geo.tool_to_workpiece = local_frame(sample.axis, sample.feed_direction, plunge);
  geo.cutter = s.cutter;
  sample.plunge = plunge && totals.length_m > 0.0;
  const double along_axis = sample.feed_direction.dot(sample.axis);
  sample.feed_per_tooth_m =
      s.feed_per_tooth_m * std::sqrt(std::max(0.0, 1.0 - along_axis * along_axis));
  geo.axial_feed_per_tooth_m = s.feed_per_tooth_m * along_axis;
  return plunge;
}

// Where the engagement is looked up: the tip, axis and feed direction.
struct Probe {
  Eigen::Vector3d tip_m, axis, feed;
};

// The engagement is looked up a little ahead along the lateral feed.
// The sides of a slot (φ near 0 and π) border material only a sliver
// thick beyond the previous sample's envelope: at φ = 0, a probe s
// ahead of a sample one step f after the previous clears that envelope
// by (s + f)² / (2R), which must exceed the engagement's surface inset
// (cutter_engagement.hpp) or the sides read as air. s = √(4 R inset) − f
// (at least f / 2) clears it by twice the inset. Walls along the feed (a
// side cut's entry), the floor and ap are unchanged by a shift along x;
// a wall across the feed is seen s early (a resampling error, reported
// in docs/toolpath.md). A plunge has no lateral direction: no shift.
// The probe follows the path itself (an arc's probe stays on the arc, so
// the wall an earlier turn of a helix left is not crossed), straight on
// past the move's end; its engagement is taken in its own frame.
Probe probe_ahead(const Program& program, const MoveSampling& s, const MoveTotals& totals, double u,
                  bool plunge, const PathSample& sample, SampleGeometry& geo) {
  const Move& move = *s.move;
  const std::size_t m = s.m;
  Probe probe{sample.tip_m, sample.axis, sample.feed_direction};
  Eigen::Vector3d& probe_m = probe.tip_m;
  Eigen::Vector3d& probe_axis = probe.axis;
  Eigen::Vector3d& probe_feed = probe.feed;
  if (!plunge && totals.length_m > 0.0) {
    const double ahead_u = u + s.lookahead_m / totals.length_m;
    if (ahead_u <= 1.0) {
      probe_m = position_at(move, ahead_u);
      probe_axis = axis_at(move, ahead_u);
      probe_feed = tangent_at(move, ahead_u);
    } else {
      // Into the next move where the cut goes on (a feed move that starts
      // here), else the move's end.
      const Move* next = m + 1 < program.moves.size() ? &program.moves[m + 1] : nullptr;
      const double beyond_m = (ahead_u - 1.0) * totals.length_m;
      const double next_length_m = next ? toolpath::path_length_m(*next) : 0.0;
      if (next && next->kind != MotionKind::rapid && next->kind != MotionKind::dwell &&
          next_length_m > 0.0 && (next->start_m - move.end_m).norm() < 1e-9) {
        const double next_u = std::min(1.0, beyond_m / next_length_m);
        probe_m = position_at(*next, next_u);
        probe_axis = axis_at(*next, next_u);
        probe_feed = tangent_at(*next, next_u);
      } else {
        probe_m = move.end_m;
        probe_axis = axis_at(move, 1.0);
        probe_feed = tangent_at(move, 1.0);
      }
    }
    bool probe_plunge = false;
    geo.tool_to_workpiece = local_frame(probe_axis, probe_feed, probe_plunge);
    if (probe_plunge) {  // the path turns into the axis within s: stay put
      probe_m = sample.tip_m;
      probe_axis = sample.axis;
      probe_feed = sample.feed_direction;
      geo.tool_to_workpiece = local_frame(probe_axis, probe_feed, probe_plunge);
    }
  }
  return probe;
}

// The engagement's figures into the sample and the totals; false when the
// sample is in air.
bool take_engagement(const MoveSampling& s, std::size_t k, const CutterEngagement& engagement,
                     PathSample& sample, MoveTotals& totals, ProgramAnalysis& result) {
  const tool::Tool& tool = *s.cutter->tool;
  ++totals.samples;
  if (engagement.empty())
    return false;
  ++totals.engaged_samples;
  ++result.engaged_samples;
  sample.axial_depth_m = engagement.axial_depth_m;
  sample.radial_width_m = engagement.radial_width_m;
  sample.engaged_rad = engagement.engaged_rad;
  sample.entry_rad = engagement.entry_rad;
  sample.exit_rad = engagement.exit_rad;
  sample.section_m2 = engagement.section_m2;
  for (const EngagementSlice& slice : engagement.slices) {
    if (slice.engaged_rad() >= sample.engaged_rad - 1e-12)
      sample.arcs = std::max(sample.arcs, slice.arc_count);
    // Mean Σ h b over a tooth period: h db = fz sin φ sin κ dz / sin κ,
    // integrated over each arc and averaged over 2π/N.
    for (int a = 0; a < slice.arc_count; ++a)
      sample.chip_area_m2 +=
          tool.teeth() * sample.feed_per_tooth_m / kTwoPi *
          (std::cos(slice.arcs[a].entry_rad) - std::cos(slice.arcs[a].exit_rad)) *
          slice.thickness_m;
  }
  sample.chip_area_m2 = std::max(0.0, sample.chip_area_m2);
  totals.max_axial_depth_m = std::max(totals.max_axial_depth_m, sample.axial_depth_m);
  totals.max_radial_width_m = std::max(totals.max_radial_width_m, sample.radial_width_m);
  totals.max_engaged_rad = std::max(totals.max_engaged_rad, sample.engaged_rad);
  if (k > 0)
    totals.removed_m3 += sample.section_m2 * s.step_m;
  return true;
}

// An engaged sample: analysed where a feed move cuts with the spindle on;
// warned about where the cut is not what the model computes.
void accept_cut(const ProgramAnalysisSettings& settings, const MoveSampling& s, PathSample& sample,
                Warnings& warnings) {
  const Move& move = *s.move;
  if (!s.feed_move) {
    warnings.add(move.line, "a rapid move cuts material (the program would crash the tool)");
    return;
  }
  if (s.spindle_rad_s == 0.0) {
    throw InputError(settings.source_name, move.line,
                     "a feed move cuts material with the spindle off and no spindle speed "
                     "in the program; give S (M3) in the program or toolpath.spindle in "
                     "the job");
  }
  sample.analysed = true;
  if (sample.plunge && !s.cutter->shape.has_corner())
    warnings.add(move.line,
                 "a flat end mill plunges along its axis: the end teeth's cut is not "
                 "modelled (side-edge forces only)");
  else if (sample.plunge && s.cutter->shape.is_bull())
    warnings.add(move.line,
                 "a bull-nose end mill plunges along its axis: its corner's cut is "
                 "modelled, the flat end's inside R - r is not");
}

}  // namespace

ProgramAnalysis analyse_program(const Program& program, const Tooling& tooling,
                                const cutting::CuttingLaw& law, DexelStock& stock,
                                const ProgramAnalysisSettings& settings, const SampleSink& sink,
                                const ProgressSink& progress) {
  if (settings.force_steps_per_tooth < 1 || settings.block_samples < 1 ||
      !(settings.sample_spacing_m >= 0.0) || !(settings.rapid_speed_m_s > 0.0))
    throw std::invalid_argument("program analysis: inconsistent settings");

  const std::map<int, Cutter> cutters = make_cutters(tooling, settings, stock);

  ProgramAnalysis result;
  Warnings warnings;
  const double volume_before = stock.volume_m3();
  // Every move's totals exist from the start: the worker below fills in the
  // maxima of a block's moves while this thread appends to later ones.
  result.moves.resize(program.moves.size());
  BlockPipeline pipeline(law, settings, sink, result);

  // On an error, the worker's block (earlier in the program) is finished
  // first, and its error, if any, is the one reported.
  try {
    double time_s = 0.0;
    std::optional<Eigen::Vector3d> last_tip, last_axis;  // where the cutter was last placed
    bool approached = false;                             // a feed move was seen
    for (std::size_t m = 0; m < program.moves.size(); ++m) {
      const Move& move = program.moves[m];
      MoveTotals& totals = result.moves[m];
      MoveSampling s;
      s.move = &move;
      s.m = m;
      s.move_start_s = open_move(move, m, settings, totals, result, warnings, time_s);
      if (move.kind == MotionKind::dwell)
        continue;

      s.cutter = cutter_of(cutters, move.tool);
      totals.tool_described = s.cutter != nullptr;
      if (!s.cutter) {
        warnings.add(move.line,
                     fmt::format("tool T{} is not described in toolpath.tools: its moves "
                                 "are listed, not analysed, and remove no material",
                                 move.tool));
        last_tip.reset();
        continue;
      }
      const Cutter* cutter = s.cutter;
      s.feed_move = move.kind != MotionKind::rapid;
      move_speeds(settings, stock, warnings, s);
      // Until the first feed move the cutter's position is not known: a program
      // starts wherever the machine happened to be (the readers start at the
      // program zero, as LinuxCNC does), and a post's first rapids (G0 X Y, then
      // G43 Z) move one axis at a time from there. The approach rapids are taken
      // as the safe moves CAM made them: they are listed, not sampled, and the
      // cutter first appears where the first feed move starts.
      if (!approached && move.kind == MotionKind::rapid)
        continue;
      approached = true;
      near_steps(settings, stock, totals, result, s, last_tip, last_axis);

      for (std::size_t k = s.first; k <= s.last; ++k) {
        if (pipeline.filling().samples.size() >= settings.block_samples) {
          pipeline.flush();
          if (progress)
            progress(static_cast<double>(m) / static_cast<double>(program.moves.size()));
        }
        const double u = static_cast<double>(k) / static_cast<double>(s.steps);
        PathSample& sample = pipeline.filling().samples.emplace_back();
        SampleGeometry& geo = pipeline.filling().geometry.emplace_back();
        const bool plunge = start_sample(s, totals, k, u, sample, geo);

        // The engagement on the stock as the samples before left it (looked
        // up a little ahead, probe_ahead); then this sample's sweep is
        // removed (from where the cutter was last placed).
        const Probe probe = probe_ahead(program, s, totals, u, plunge, sample, geo);
        geo.engagement =
            engagement_at(stock, cutter->shape, probe.tip_m, probe.axis, probe.feed, cutter->grid);
        if (last_tip)
          stock.remove_sweep(cutter->shape, *last_tip, *last_axis, sample.tip_m, sample.axis);
        else
          stock.remove(cutter->shape, sample.tip_m, sample.axis);
        last_tip = sample.tip_m;
        last_axis = sample.axis;

        if (take_engagement(s, k, geo.engagement, sample, totals, result))
          accept_cut(settings, s, sample, warnings);
      }
      // Air at the move's end: the cutter is left where its last step would be.
      if (s.last < s.steps || s.first > s.last) {
        last_tip = position_at(move, 1.0);
        last_axis = axis_at(move, 1.0);
      }
    }
    pipeline.flush();
    pipeline.wait_pending();
  } catch (...) {
    pipeline.wait_pending();
    throw;
  }
  if (progress)
    progress(1.0);
  result.volume_removed_m3 = std::max(0.0, volume_before - stock.volume_m3());
  result.warnings = warnings.take();
  return result;
}

}  // namespace robomill::toolpath
