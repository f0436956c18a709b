// The planning sections of a job (docs/job-reference.md, "workpiece",
// "path", "optimize"): 004 §4.1's table, part and groove, and the pose search
// of 004 Eq 9. Units are converted here, once: lengths in mm and angles in deg
// unless written.

#include "job_parser_planning.hpp"

#include <fmt/format.h>

#include <numbers>

namespace robomill::io::detail {
namespace {

constexpr double kMm = 1e-3;
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr Bound kPositive{0.0, false};

QuantityField length_mm(std::optional<Bound> min = {}) {
  QuantityField f;
  f.dimension = dimensions::length;
  f.unit_si = kMm;
  f.unit = "mm";
  f.min = min;
  return f;
}

QuantityField angle_deg() {
  QuantityField f;
  f.dimension = dimensions::angle;
  f.unit_si = kDeg;
  f.unit = "deg";
  return f;
}

Eigen::Vector3d vector3(SectionReader& r, std::string_view key, const Eigen::Vector3d& fallback) {
  const auto v = r.quantities(key, length_mm(), 3);
  return v ? Eigen::Vector3d((*v)[0], (*v)[1], (*v)[2]) : fallback;
}

/// `{x, y, theta}`: a workpiece pose (mm, mm, deg).
planning::WorkpiecePose read_pose(SectionReader& r) {
  r.allow({"x", "y", "theta"});
  planning::WorkpiecePose pose;
  pose.x_m = r.quantity_or("x", length_mm(), 0.0);
  pose.y_m = r.quantity_or("y", length_mm(), 0.0);
  pose.theta_rad = r.quantity_or("theta", angle_deg(), 0.0);
  r.finish();
  return pose;
}

WorkpieceSettings read_workpiece(SectionReader& r) {
  r.allow({"table", "height", "tilt_axis", "pose"});
  WorkpieceSettings settings;
  const auto table = r.quantities("table", length_mm(), 3);
  if (!table)
    r.fail("table", "required: the table origin p_c [x, y, z] in the cell frame (mm)");
  settings.cell.table_origin_m = Eigen::Vector3d((*table)[0], (*table)[1], (*table)[2]);
  settings.cell.workpiece_height_m = r.quantity_or("height", length_mm(), 0.0);
  settings.cell.tilt_axis =
      r.choice("tilt_axis", {"x", "y"}, "y") == "x" ? planning::TiltAxis::x : planning::TiltAxis::y;
  if (auto pose = r.section("pose"))
    settings.pose = read_pose(*pose);
  r.finish();
  return settings;
}

std::vector<planning::PathPoint> read_path(SectionReader& r) {
  r.allow({"shape", "start", "length", "width", "points", "direction"});
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
  r.allow({"bounds", "variables", "algorithm", "local", "budget", "local_budget", "tolerance",
           "seed", "measure", "harmonics", "samples", "poses", "landscape", "check_time_domain"});
  OptimizeSettings s;
  auto bounds = r.section("bounds");
  if (!bounds)
    r.fail("bounds", "required: {x: [lower, upper], y: [...], theta: [...]} (004 Eq 9)");
  bounds->allow({"x", "y", "theta"});
  read_range(*bounds, "x", length_mm(), s.bounds.lower.x_m, s.bounds.upper.x_m);
  read_range(*bounds, "y", length_mm(), s.bounds.lower.y_m, s.bounds.upper.y_m);
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
      s.poses.push_back(read_pose(pose));
  }
  if (auto landscape = r.section("landscape")) {
    landscape->allow({"x", "y", "theta"});
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
}

}  // namespace robomill::io::detail
