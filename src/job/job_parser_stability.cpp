// The `stability:` section of a job: method, speed grid, depths, process
// damping and the structure options of `robomill stability`.

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "job_parser_stability.hpp"
#include "quantity_fields.hpp"
#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"

namespace robomill::job::detail {

StabilitySettings::Method read_stability_method(SectionReader& r, const std::string& fallback) {
  using Method = StabilitySettings::Method;
  const std::string method = r.choice("method", {"zoa", "sdm", "fdm", "fdm2"}, fallback);
  return method == "zoa"   ? Method::zoa
         : method == "sdm" ? Method::sdm
         : method == "fdm" ? Method::fdm
                           : Method::fdm2;
}

std::optional<StabilitySettings> read_stability(SectionReader& root,
                                                const std::optional<tool::ToolSpec>& tool,
                                                const std::vector<ModeSpec>& modes,
                                                Job::DynamicsSource source) {
  auto section = root.section("stability");
  if (!section)
    return std::nullopt;
  SectionReader& r = *section;
  r.allow_schema("stability");
  using Settings = StabilitySettings;
  Settings settings;

  settings.method = read_stability_method(r, "fdm");
  settings.mode = r.choice("mode", {"boundary", "map"}, "boundary") == "map"
                      ? Settings::Mode::map
                      : Settings::Mode::boundary;
  const std::string which = r.choice("modes", {"coupled", "envelope", "both"}, "coupled");
  settings.modes = which == "coupled"    ? Settings::Modes::coupled
                   : which == "envelope" ? Settings::Modes::envelope
                                         : Settings::Modes::both;

  const QuantityField rpm = field(dimensions::angular_speed, kRpm, "rpm", kPositive);
  auto speeds = r.section("speeds");
  if (!speeds) {
    r.fail("speeds", "required field missing (the spindle-speed range {from, to, count}, in rpm)");
  }
  speeds->allow_schema("stability.speeds");
  settings.speed_from_rad_s = speeds->quantity("from", rpm);
  const std::optional<double> to = speeds->optional_quantity("to", rpm);
  settings.speed_count = speeds->integer("count", 1, 100000);
  speeds->finish();
  if (settings.speed_count == 1) {
    // One speed: `to` may be left out; if given it must name the same speed.
    settings.speed_to_rad_s = to.value_or(settings.speed_from_rad_s);
    if (std::abs(settings.speed_to_rad_s - settings.speed_from_rad_s) >
        1e-9 * settings.speed_from_rad_s) {
      speeds->fail("to",
                   "with count 1 there is a single speed; leave out `to` or give it equal "
                   "to from (" +
                       detail::format_in_unit(settings.speed_from_rad_s, rpm) + "), got " +
                       detail::format_in_unit(settings.speed_to_rad_s, rpm));
    }
  } else {
    if (!to) {
      speeds->fail("to",
                   "required field missing (angular speed, in rpm by default; only a "
                   "single speed, count 1, may leave it out)");
    }
    settings.speed_to_rad_s = *to;
    if (!(settings.speed_to_rad_s > settings.speed_from_rad_s)) {
      speeds->fail("to", "must be greater than from (" +
                             detail::format_in_unit(settings.speed_from_rad_s, rpm) + "), got " +
                             detail::format_in_unit(settings.speed_to_rad_s, rpm));
    }
  }

  settings.depth_max_m = r.quantity("depth_max", length_mm());
  if (tool && settings.depth_max_m > tool->overhang_m * (1.0 + 1e-9)) {
    r.fail("depth_max", "depth search limit " +
                            detail::format_in_unit(settings.depth_max_m, length_mm()) +
                            " exceeds the tool overhang " +
                            detail::format_in_unit(tool->overhang_m, length_mm()));
  }
  settings.depth_count = r.integer_or("depths", 2, 100000, settings.depth_count);
  settings.depth_tolerance = r.quantity_or(
      "depth_tolerance", dimensionless(kPositive, Bound{0.1, true}), settings.depth_tolerance);
  settings.discretization = r.integer_or("discretization", 4, 10000, settings.discretization);
  settings.continuation = r.boolean_or("continuation", settings.continuation);
  // 000 §4-5: the diagrams with the deformation-corrected engagement too.
  settings.deformation = r.boolean_or("deformation", false);
  if (settings.deformation && settings.method == Settings::Method::zoa) {
    r.fail("deformation",
           "needs a time-domain method (sdm, fdm or fdm2): 000 solves its multipoint model by "
           "full discretization");
  }

  if (auto damping = r.section("process_damping")) {
    damping->allow_schema("stability.process_damping");
    settings.process_damping =
        damping->choice("model", {"linear_equivalent", "energy_balance"}) == "energy_balance"
            ? Settings::Damping::energy_balance
            : Settings::Damping::linear_equivalent;
    // 000 Eq 18-19: indentation coefficient, flank wear land, friction.
    settings.indentation_n_per_m3 =
        damping->quantity("Ksp", field(dimensions::force_per_volume, 1.0, "N/m^3", kPositive));
    settings.wear_land_m =
        damping->quantity("wear_land", field(dimensions::length, 1e-6, "um", kPositive));
    settings.friction = damping->quantity_or("mu", dimensionless(kNonNegative), 0.3);
    damping->finish();
  }
  r.finish();

  if (source == Job::DynamicsSource::frf && settings.method != Settings::Method::zoa) {
    r.fail("method",
           "dynamics.use is 'frf' (measured FRFs directly), which only the zero-order method "
           "(zoa) can use; set method: zoa, or dynamics.use: fit for the time-domain methods");
  }
  if (source == Job::DynamicsSource::frf && settings.modes != Settings::Modes::coupled) {
    r.fail("modes",
           "the envelope of one-mode diagrams needs modes; with dynamics.use: frf the measured "
           "FRFs are used whole (modes: coupled), or set dynamics.use: fit");
  }
  if (source == Job::DynamicsSource::frf && settings.process_damping != Settings::Damping::none) {
    r.fail("process_damping",
           "process damping is added per mode (003 §3.2) and needs modes; with measured FRFs "
           "use dynamics.use: fit");
  }
  if (modes.empty() && source == Job::DynamicsSource::table) {
    r.fail_here(
        "the stability command needs dynamics.modes (the structure's modal table) or measured "
        "FRFs (dynamics.frf); add a dynamics: section");
  }
  // Time-domain discretizations step through the tooth period τ = 60/(N n) in
  // m steps of h = τ/m; h is largest at the lowest speed. At least two steps
  // per period of the highest mode (h · f_max <= 0.5), otherwise that mode is
  // aliased: m >= 2 f_max τ_max. ZOA has no time step.
  if (tool && settings.method != Settings::Method::zoa) {
    double f_max = 0.0;
    for (const ModeSpec& mode : modes)
      f_max = std::max(f_max, mode.natural_frequency_hz);
    const double tau_max = 2.0 * kPi / (tool->teeth * settings.speed_from_rad_s);
    const double needed = 2.0 * f_max * tau_max;
    if (settings.discretization < needed * (1.0 - 1e-12)) {
      const double minimum = std::ceil(needed * (1.0 - 1e-12));
      const std::string fix = minimum <= 10000
                                  ? "; raise it or use method zoa"
                                  : ", beyond the limit of 10000: raise speeds.from or use "
                                    "method zoa";
      r.fail("discretization",
             fmt::format("{} steps per tooth period{} are too coarse for the {:g} Hz mode at "
                         "{:g} rpm with {} teeth: two steps per period of that mode need a "
                         "discretization of at least {:.0f}{}",
                         settings.discretization, r.has("discretization") ? "" : " (the default)",
                         f_max, settings.speed_from_rad_s / kRpm, tool->teeth, minimum, fix));
    }
  }
  return settings;
}

}  // namespace robomill::job::detail
