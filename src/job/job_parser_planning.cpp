// The planning sections of a job (docs/job-reference.md, "workpiece",
// "path", "optimize", "advise"): 004 §4.1's table, part and groove, the pose
// search of 004 Eq 9, and the cutting-parameter advice (issue 9 item 4). Units are converted here,
// once: lengths in mm and angles in deg unless written.

#include "job_parser_planning.hpp"
#include "quantity_fields.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "robomill/stability/lobes.hpp"

namespace robomill::job::detail {
namespace {

Eigen::Vector3d vector3(SectionReader& r, std::string_view key, const Eigen::Vector3d& fallback) {
  const auto v = r.quantities(key, length_mm({}), 3);
  return v ? Eigen::Vector3d((*v)[0], (*v)[1], (*v)[2]) : fallback;
}

/// `{x, y, theta}`: a workpiece pose (mm, mm, deg).
planning::WorkpiecePose read_pose(SectionReader& r, std::string_view schema_section) {
  r.allow_schema(schema_section);
  planning::WorkpiecePose pose;
  pose.x_m = r.quantity_or("x", length_mm({}), 0.0);
  pose.y_m = r.quantity_or("y", length_mm({}), 0.0);
  pose.theta_rad = r.quantity_or("theta", angle_deg(), 0.0);
  r.finish();
  return pose;
}

WorkpieceSettings read_workpiece(SectionReader& r) {
  r.allow_schema("workpiece");
  WorkpieceSettings settings;
  const auto table = r.quantities("table", length_mm({}), 3);
  if (!table)
    r.fail("table", "required: the table origin p_c [x, y, z] in the cell frame (mm)");
  settings.cell.table_origin_m = Eigen::Vector3d((*table)[0], (*table)[1], (*table)[2]);
  settings.cell.workpiece_height_m = r.quantity_or("height", length_mm({}), 0.0);
  settings.cell.tilt_axis =
      r.choice("tilt_axis", {"x", "y"}, "y") == "x" ? planning::TiltAxis::x : planning::TiltAxis::y;
  if (auto pose = r.section("pose"))
    settings.pose = read_pose(*pose, "workpiece.pose");
  r.finish();
  return settings;
}

std::vector<planning::PathPoint> read_path(SectionReader& r) {
  r.allow_schema("path");
  r.choice("shape", {"rectangle"}, "rectangle");
  const Eigen::Vector3d start = vector3(r, "start", Eigen::Vector3d::Zero());
  const double length = r.quantity("length", length_mm(kPositive));
  const double width = r.quantity("width", length_mm(kPositive));
  const int points = r.integer("points", 1, 100000);
  const bool ccw = r.choice("direction", {"ccw", "cw"}, "ccw") == "ccw";
  r.finish();
  return planning::rectangular_path(start, length, width, points, ccw);
}

/// `[lower, upper]` of one pose variable; the bound must be increasing.
void read_range(SectionReader& r, std::string_view key, const QuantityField& field, double& lower,
                double& upper) {
  const auto range = r.quantities(key, field, 2);
  if (!range)
    r.fail(key, "required: [lower, upper]");
  lower = (*range)[0];
  upper = (*range)[1];
  if (!(upper > lower))
    r.fail(key, fmt::format("upper bound must exceed the lower bound, got [{}, {}] {}",
                            lower / field.unit_si, upper / field.unit_si, field.unit));
}

OptimizeSettings read_optimize(SectionReader& r) {
  r.allow_schema("optimize");
  OptimizeSettings s;
  auto bounds = r.section("bounds");
  if (!bounds)
    r.fail("bounds", "required: {x: [lower, upper], y: [...], theta: [...]} (004 Eq 9)");
  bounds->allow_schema("optimize.bounds");
  read_range(*bounds, "x", length_mm({}), s.bounds.lower.x_m, s.bounds.upper.x_m);
  read_range(*bounds, "y", length_mm({}), s.bounds.lower.y_m, s.bounds.upper.y_m);
  read_range(*bounds, "theta", angle_deg(), s.bounds.lower.theta_rad, s.bounds.upper.theta_rad);
  bounds->finish();
  if (auto variables = r.texts("variables")) {
    s.bounds.free = {false, false, false};
    for (const auto& item : *variables) {
      if (item.text == "x")
        s.bounds.free[0] = true;
      else if (item.text == "y")
        s.bounds.free[1] = true;
      else if (item.text == "theta")
        s.bounds.free[2] = true;
      else
        throw InputError(item.path, item.line,
                         "'" + item.text + "' is not a pose variable; expected x, y or theta");
    }
  }
  const std::string algorithm = r.choice("algorithm", {"direct_l", "crs2", "mlsl"}, "direct_l");
  s.options.global = algorithm == "crs2"   ? planning::GlobalMethod::crs2
                     : algorithm == "mlsl" ? planning::GlobalMethod::mlsl
                                           : planning::GlobalMethod::direct_l;
  const std::string local =
      r.choice("local", {"bobyqa", "cobyla", "nelder_mead", "none"}, "bobyqa");
  s.options.local = local == "cobyla"        ? planning::LocalMethod::cobyla
                    : local == "nelder_mead" ? planning::LocalMethod::nelder_mead
                    : local == "none"        ? planning::LocalMethod::none
                                             : planning::LocalMethod::bobyqa;
  s.options.global_evaluations = r.integer_or("budget", 1, 1000000, 600);
  s.options.local_evaluations = r.integer_or("local_budget", 0, 1000000, 200);
  QuantityField tolerance;
  tolerance.dimension = dimensions::none;
  tolerance.min = kPositive;
  tolerance.max = Bound{0.1, true};
  s.options.relative_x_tolerance = r.quantity_or("tolerance", tolerance, 1e-5);
  s.options.seed = static_cast<unsigned>(r.integer_or("seed", 0, 2147483647, 1));
  const std::string measure =
      r.choice("measure", {"peak", "vibration", "rms", "mean", "startup"}, "peak");
  s.measure = measure == "vibration" ? planning::OffsetMeasure::vibration
              : measure == "rms"     ? planning::OffsetMeasure::rms
              : measure == "mean"    ? planning::OffsetMeasure::mean
              : measure == "startup" ? planning::OffsetMeasure::startup
                                     : planning::OffsetMeasure::peak;
  s.harmonics = r.integer_or("harmonics", 1, 2000, 60);
  s.samples = r.integer_or("samples", 8, 100000, 256);
  if (s.samples < 2 * s.harmonics + 1)
    r.fail("samples", fmt::format("must be at least 2 harmonics + 1 = {} (Nyquist), got {}",
                                  2 * s.harmonics + 1, s.samples));
  s.check_time_domain = r.boolean_or("check_time_domain", false);
  if (auto poses = r.sections("poses")) {
    for (SectionReader& pose : *poses)
      s.poses.push_back(read_pose(pose, "optimize.poses[]"));
  }
  if (auto landscape = r.section("landscape")) {
    landscape->allow_schema("optimize.landscape");
    s.landscape_counts[0] = landscape->integer("x", 1, 1000);
    s.landscape_counts[1] = landscape->integer("y", 1, 1000);
    if (auto theta = landscape->quantities("theta", angle_deg()))
      s.landscape_theta_rad = *theta;
    else
      s.landscape_theta_rad = {s.bounds.lower.theta_rad};
    if (static_cast<long>(s.landscape_counts[0]) * s.landscape_counts[1] *
            static_cast<long>(s.landscape_theta_rad.size()) >
        1000000)
      landscape->fail_here("more than 1 000 000 landscape cells");
    landscape->finish();
  }
  r.finish();
  return s;
}

/// `advise:` (issue 9 item 4): the limits and resolution of the
/// cutting-parameter advice and, optionally, the redundancy-angle study.
AdviseSettings read_advise(SectionReader& r, const Job& job) {
  r.allow_schema("advise");
  AdviseSettings s;
  QuantityField rpm;
  rpm.dimension = dimensions::angular_speed;
  rpm.unit_si = 2.0 * std::numbers::pi / 60.0;
  rpm.unit = "rpm";
  rpm.min = kPositive;
  auto speeds = r.section("speeds");
  if (!speeds)
    r.fail("speeds", "required: the spindle range {from, to, count} (rpm) to search");
  speeds->allow_schema("advise.speeds");
  s.limits.speed_min_rad_s = speeds->quantity("from", rpm);
  s.limits.speed_count = speeds->integer("count", 1, 100000);
  s.limits.speed_max_rad_s = speeds->quantity_or("to", rpm, s.limits.speed_min_rad_s);
  if (s.limits.speed_count > 1 && !(s.limits.speed_max_rad_s > s.limits.speed_min_rad_s))
    speeds->fail("to", fmt::format("must exceed from ({} rpm) when count > 1, got {} rpm",
                                   s.limits.speed_min_rad_s / rpm.unit_si,
                                   s.limits.speed_max_rad_s / rpm.unit_si));
  speeds->finish();
  s.limits.refine_count = r.integer_or("refine", 0, 10000, 20);

  // The depth range: advise.depth_max, else stability.depth_max; ≤ overhang.
  if (auto depth_max = r.optional_quantity("depth_max", length_mm(kPositive)))
    s.limit.depth_max_m = *depth_max;
  else if (job.stability)
    s.limit.depth_max_m = job.stability->depth_max_m;
  else
    r.fail("depth_max", "required (or stability.depth_max): the largest depth considered (mm)");
  if (job.tool && s.limit.depth_max_m > job.tool->overhang_m * (1.0 + 1e-9))
    r.fail("depth_max", fmt::format("{} mm exceeds the tool overhang {} mm",
                                    s.limit.depth_max_m * 1e3, job.tool->overhang_m * 1e3));
  s.limits.depth_step_m =
      r.quantity_or("depth_step", length_mm(kPositive), s.limit.depth_max_m / 100.0);
  if (s.limits.depth_step_m > s.limit.depth_max_m * (1.0 + 1e-12) ||
      s.limit.depth_max_m / s.limits.depth_step_m > 100000.0)
    r.fail("depth_step",
           fmt::format("must lie in [depth_max / 100000, depth_max] = [{:g}, {:g}] mm, got {:g} mm",
                       s.limit.depth_max_m / 100000.0 * 1e3, s.limit.depth_max_m * 1e3,
                       s.limits.depth_step_m * 1e3));
  QuantityField margin;
  margin.dimension = dimensions::none;
  margin.min = kPositive;
  margin.max = Bound{1.0, true};
  s.limits.stability_margin = r.quantity_or("margin", margin, 1.0);
  s.limits.max_offset_m = r.optional_quantity("max_offset", length_mm(kPositive));
  const std::string measure = r.choice("measure", {"peak", "vibration", "rms", "mean"}, "peak");
  s.limits.measure = measure == "vibration" ? planning::OffsetMeasure::vibration
                     : measure == "rms"     ? planning::OffsetMeasure::rms
                     : measure == "mean"    ? planning::OffsetMeasure::mean
                                            : planning::OffsetMeasure::peak;
  s.limits.harmonics = r.integer_or("harmonics", 1, 2000, 60);
  s.limits.samples = r.integer_or("samples", 8, 100000, 256);
  if (s.limits.samples < 2 * s.limits.harmonics + 1)
    r.fail("samples", fmt::format("must be at least 2 harmonics + 1 = {} (Nyquist), got {}",
                                  2 * s.limits.harmonics + 1, s.limits.samples));
  const std::string method = r.choice("method", {"zoa", "sdm", "fdm", "fdm2"}, "zoa");
  s.limit.method = method == "sdm"    ? planning::LimitMethod::sdm
                   : method == "fdm"  ? planning::LimitMethod::fdm
                   : method == "fdm2" ? planning::LimitMethod::fdm2
                                      : planning::LimitMethod::zoa;
  s.limit.discretization = r.integer_or("discretization", 4, 10000, 40);
  if (s.limit.method != planning::LimitMethod::zoa && job.tool &&
      job.dynamics_source == Job::DynamicsSource::table && !job.modes.empty()) {
    // Two steps per period of the highest mode at the longest tooth period.
    double highest_hz = 0.0;
    for (const ModeSpec& mode : job.modes)
      highest_hz = std::max(highest_hz, mode.natural_frequency_hz);
    const double tau = 2.0 * std::numbers::pi / (job.tool->teeth * s.limits.speed_min_rad_s);
    const double needed = std::ceil(2.0 * highest_hz * tau * (1.0 - 1e-12));
    if (s.limit.discretization < needed)
      r.fail("discretization",
             fmt::format("{} steps per tooth period are too coarse for the {:g} Hz mode at "
                         "{:g} rpm: at least {:.0f} needed (or method: zoa)",
                         s.limit.discretization, highest_hz, s.limits.speed_min_rad_s / rpm.unit_si,
                         needed));
  }
  QuantityField tolerance;
  tolerance.dimension = dimensions::none;
  tolerance.min = kPositive;
  tolerance.max = Bound{0.1, true};
  s.limit.depth_tolerance = r.quantity_or("depth_tolerance", tolerance, 1e-3);
  s.peaks = r.integer_or("peaks", 0, 1000, 5);
  s.max_chatter_probability =
      r.quantity_or("max_chatter_probability", dimensionless(kPositive, Bound{1.0, false}), 0.05);
  s.along_path = r.choice("along", {"posture", "path"}, "posture") == "path";
  s.redundancy_angle_rad = r.quantity_or("redundancy_angle", angle_deg(), 0.0);
  if (auto redundancy = r.section("redundancy")) {
    redundancy->allow_schema("advise.redundancy");
    AdviseSettings::Redundancy study;
    auto angles = redundancy->section("angles");
    if (!angles)
      redundancy->fail("angles", "required: {from, to, count} (deg) about the tool axis");
    angles->allow_schema("advise.redundancy.angles");
    const double from = angles->quantity("from", angle_deg());
    const double to = angles->quantity("to", angle_deg());
    const int count = angles->integer("count", 1, 3600);
    if (count > 1 && !(to > from))
      angles->fail("to", fmt::format("must exceed from ({:g} deg) when count > 1, got {:g} deg",
                                     from / kDeg, to / kDeg));
    angles->finish();
    study.angles_rad = stability::linear_range(from, count > 1 ? to : from, count);
    study.at_spindle = redundancy->choice("at", {"range", "spindle"}, "range") == "spindle";
    if (!job.robot)
      redundancy->fail_here("needs a robot: section (the redundancy angle turns its posture)");
    const std::size_t joints = job.robot->description.joints.size();
    if (joints < 6)
      redundancy->fail_here(fmt::format(
          "the robot has {} joints: no rotation about the tool axis is free (a redundancy "
          "angle needs a 6-joint robot)",
          joints));
    if (job.robot->description.dh && job.robot->description.dh->links.empty())
      redundancy->fail_here("needs the robot's link masses (robot.links) for its modes");
    if (!job.path.empty() && !job.workpiece)
      redundancy->fail_here("a path needs a workpiece: section to be placed in the cell");
    if ((job.path.empty() || !job.workpiece || !job.workpiece->pose) &&
        job.robot->posture_rad.empty())
      redundancy->fail_here(
          "needs robot.posture (the tool pose to turn about its axis), or a path with "
          "workpiece.pose");
    redundancy->finish();
    s.redundancy = study;
  }
  r.finish();
  return s;
}

}  // namespace

void read_planning(SectionReader& root, Job& job) {
  if (auto workpiece = root.section("workpiece"))
    job.workpiece = read_workpiece(*workpiece);
  if (auto path = root.section("path"))
    job.path = read_path(*path);
  if (auto optimize = root.section("optimize")) {
    job.optimize = read_optimize(*optimize);
    // The pose search needs the whole 004 chain: robot, part, path and cut.
    if (!job.workpiece)
      optimize->fail_here("needs a workpiece: section (the table origin and the part's frame)");
    if (job.path.empty())
      optimize->fail_here("needs a path: section (the tool path in the workpiece frame)");
    if (!job.robot)
      optimize->fail_here("needs a robot: section with link masses (004 Eq 1)");
    if (job.robot->description.dh && job.robot->description.dh->links.empty())
      optimize->fail_here("needs the robot's link masses (robot.links) for M(q) of 004 Eq 1");
    if (!job.tool || !job.cutting || !job.process)
      optimize->fail_here("needs tool:, cutting: and process: sections (the milling force)");
  }
  if (auto advise = root.section("advise")) {
    if (!job.tool || !job.cutting || !job.process)
      advise->fail_here("needs tool:, cutting: and process: sections (ae, feed, the force law)");
    job.advise = read_advise(*advise, job);
    if (job.advise->along_path) {
      if (!job.workpiece || !job.workpiece->pose || job.path.empty())
        advise->fail("along", "path: needs a path: section and workpiece.pose (where the part is)");
      if (!job.robot || job.robot->description.joints.size() < 6)
        advise->fail("along",
                     "path: needs a 6-joint robot: section (the posture at every path point)");
      if (job.robot->description.dh && job.robot->description.dh->links.empty())
        advise->fail("along", "path: needs the robot's link masses (robot.links) for its modes");
    }
  }
}

}  // namespace robomill::job::detail
