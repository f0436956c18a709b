// The `tool:`, `cutting:`, `process:` and `forces:` sections of a job (the cut of
// `robomill forces` and every per-cut analysis): geometry, force law and cut in SI.

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "job_parser_cutting.hpp"
#include "quantity_fields.hpp"
#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"

namespace robomill::job::detail {

namespace {

// Documented units of the fields (DESIGN.md §3): bare numbers are read in them.
constexpr double kGPa = 1e9;
constexpr double kNPerMm2 = 1e6;
constexpr double kNPerMm = 1e3;
constexpr double kMmPerMin = 1e-3 / 60.0;

}  // namespace

std::optional<tool::ToolSpec> read_tool(SectionReader& root) {
  auto section = root.section("tool");
  if (!section)
    return std::nullopt;
  return detail::read_tool_fields(*section);
}

// The fields of a tool section, wherever it sits (`tool`, `toolpath.tools.T3`).
tool::ToolSpec read_tool_fields(SectionReader& r) {
  r.allow_schema("tool");

  tool::ToolSpec spec;
  const std::string type = r.choice("type", {"flat", "ball", "bull"}, "flat");
  spec.type = type == "ball"   ? tool::ToolType::ball
              : type == "bull" ? tool::ToolType::bull
                               : tool::ToolType::flat;
  spec.diameter_m = r.quantity("diameter", length_mm());
  spec.teeth = r.integer("teeth", 1, 20);
  spec.helix_rad = r.quantity_or(
      "helix", field(dimensions::angle, kDeg, "deg", kNonNegative, Bound{80 * kDeg, true}), 0.0);
  const double radius = 0.5 * spec.diameter_m;
  if (spec.type == tool::ToolType::bull) {
    spec.corner_radius_m = r.quantity("corner_radius", length_mm(kPositive));
    if (spec.corner_radius_m > radius * (1.0 + 1e-12))
      r.fail("corner_radius", "must be at most the tool radius (" +
                                  detail::format_in_unit(radius, length_mm()) + "), got " +
                                  detail::format_in_unit(spec.corner_radius_m, length_mm()));
  } else if (r.has("corner_radius")) {
    r.fail("corner_radius",
           "is read for tool.type: bull only (a flat end mill has none, a "
           "ball's is its radius)");
  }
  spec.overhang_m = r.quantity_or("overhang", length_mm(), 4.0 * spec.diameter_m);
  if (spec.type == tool::ToolType::ball && spec.overhang_m < radius) {
    r.fail("overhang", "must be at least the ball radius (" +
                           detail::format_in_unit(radius, length_mm()) +
                           ") for a ball-end mill, got " +
                           detail::format_in_unit(spec.overhang_m, length_mm()));
  }
  spec.youngs_modulus_pa =
      r.quantity_or("E", field(dimensions::pressure, kGPa, "GPa", kPositive), 600e9);
  if (auto runout = r.section("runout")) {
    runout->allow_schema("tool.runout");
    spec.runout.offset_m = runout->quantity_or("offset", length_mm(kNonNegative), 0.0);
    if (spec.runout.offset_m >= radius) {
      runout->fail("offset", "must be less than the tool radius (" +
                                 detail::format_in_unit(radius, length_mm()) + "), got " +
                                 detail::format_in_unit(spec.runout.offset_m, length_mm()));
    }
    spec.runout.angle_rad =
        runout->quantity_or("angle", field(dimensions::angle, kDeg, "deg"), 0.0);
    runout->finish();
  }
  r.finish();

  // Tool's constructor is the authority on what a physical cutter is; the
  // checks above only make the common mistakes point at the exact field.
  try {
    tool::Tool checked(spec);
  } catch (const std::invalid_argument& error) {
    r.fail_here(error.what());
  }
  return spec;
}

std::optional<cutting::CuttingLaw> read_cutting(SectionReader& root) {
  auto section = root.section("cutting");
  if (!section)
    return std::nullopt;
  SectionReader& r = *section;
  // The law decides which keys are valid, so it is read before allow_schema().
  const std::string law =
      r.choice("law", {"linear", "exponential", "fractional", "size_dependent"}, "linear");
  const std::string context = "for law '" + law + "'";
  const QuantityField pressure = field(dimensions::pressure, kNPerMm2, "N/mm^2");
  const QuantityField per_length = field(dimensions::force_per_length, kNPerMm, "N/mm");
  auto bounded = [](QuantityField field, std::optional<Bound> min) {
    field.min = min;
    return field;
  };

  cutting::CuttingLaw result;
  if (law == "linear") {
    r.allow_schema("cutting[law=linear]", {}, {}, context);
    cutting::LinearLaw l;
    l.Ktc_pa = r.quantity("Ktc", bounded(pressure, kPositive));
    l.Krc_pa = r.quantity_or("Krc", bounded(pressure, kNonNegative), 0.0);
    l.Kac_pa = r.quantity_or("Kac", pressure, 0.0);  // sign follows the helix hand
    l.Kte_n_per_m = r.quantity_or("Kte", bounded(per_length, kNonNegative), 0.0);
    l.Kre_n_per_m = r.quantity_or("Kre", bounded(per_length, kNonNegative), 0.0);
    l.Kae_n_per_m = r.quantity_or("Kae", per_length, 0.0);
    result = l;
  } else if (law == "exponential") {
    r.allow_schema("cutting[law=exponential]", {}, {}, context);
    cutting::ExponentialLaw l;
    l.kF_n_per_m = r.quantity("kF", bounded(per_length, kPositive));
    l.exponent = r.quantity("exponent", dimensionless(kPositive, Bound{1.5, true}));
    l.reference_chip_m = r.quantity_or("chip_unit", length_mm(), 1e-3);
    l.radial_ratio = r.quantity_or("kr", dimensionless(kNonNegative), 0.0);
    l.axial_ratio = r.quantity_or("ka", dimensionless(), 0.0);
    result = l;
  } else if (law == "fractional") {
    r.allow_schema("cutting[law=fractional]", {}, {}, context);
    cutting::FractionalLaw l;
    l.k0_n_per_m = r.quantity("k0", field(dimensions::force_per_length, 1.0, "N/m", kPositive));
    l.hs_m = r.quantity("hs", length_mm());
    l.r = r.quantity("r", dimensionless(kNonNegative));
    l.radial_ratio = r.quantity_or("kr", dimensionless(kNonNegative), 0.0);
    l.axial_ratio = r.quantity_or("ka", dimensionless(), 0.0);
    result = l;
  } else {
    r.allow_schema("cutting[law=size_dependent]", {}, {}, context);
    cutting::SizeDependentLaw l;
    l.kc1_pa = r.quantity("kc1", bounded(pressure, kPositive));
    l.b1 = r.quantity("b1", dimensionless());
    l.kc2 = r.quantity("kc2", dimensionless(kNonNegative));
    l.b2 = r.quantity("b2", dimensionless());
    l.reference_chip_m = r.quantity_or("chip_unit", length_mm(), 1e-3);
    result = l;
  }
  r.finish();
  try {
    cutting::validate(result);
  } catch (const std::invalid_argument& error) {
    r.fail_here(error.what());
  }
  return result;
}

std::optional<cutting::MillingProcess> read_process(SectionReader& root,
                                                    const std::optional<tool::ToolSpec>& tool) {
  auto section = root.section("process");
  if (!section)
    return std::nullopt;
  SectionReader& r = *section;
  r.allow_schema("process");

  cutting::MillingProcess process;
  process.spindle_rad_s =
      r.quantity("spindle", field(dimensions::angular_speed, kRpm, "rpm", kPositive));
  const bool per_tooth = r.has("feed_per_tooth");
  const bool rate = r.has("feed_rate");
  if (per_tooth && rate) {
    // Point at whichever comes second: that is the line the user added.
    const bool rate_second = r.line_of("feed_rate") >= r.line_of("feed_per_tooth");
    r.fail(rate_second ? "feed_rate" : "feed_per_tooth",
           "give either feed_per_tooth or feed_rate, not both");
  }
  if (!per_tooth && !rate) {
    r.fail("feed_per_tooth",
           "required field missing (give feed_per_tooth in mm, or feed_rate "
           "in mm/min)");
  }
  if (per_tooth) {
    process.feed_per_tooth_m = r.quantity("feed_per_tooth", length_mm());
  } else {
    const double feed_rate =
        r.quantity("feed_rate", field(dimensions::speed, kMmPerMin, "mm/min", kPositive));
    if (!tool) {
      r.fail("feed_rate",
             "converting a feed rate into a feed per tooth needs the number of teeth; add a "
             "tool: section or give feed_per_tooth instead");
    }
    const double revolutions_per_s = process.spindle_rad_s / (2.0 * kPi);
    process.feed_per_tooth_m = feed_rate / (tool->teeth * revolutions_per_s);
  }
  process.axial_depth_m = r.quantity("ap", length_mm());
  process.radial_depth_m = read_radial_depth(r, tool);
  process.direction = read_direction(r);
  r.finish();

  if (tool) {
    if (process.axial_depth_m > tool->overhang_m * (1.0 + 1e-9)) {
      r.fail("ap", "axial depth of cut " +
                       detail::format_in_unit(process.axial_depth_m, length_mm()) +
                       " exceeds the tool overhang " +
                       detail::format_in_unit(tool->overhang_m, length_mm()));
    }
  }
  return process;
}

double read_radial_depth(SectionReader& r, const std::optional<tool::ToolSpec>& tool) {
  const double ae = r.quantity("ae", length_mm());
  // A relative tolerance keeps "ae: 10 mm" on a 10 mm cutter (slotting)
  // valid despite rounding in unit conversion.
  if (tool && ae > tool->diameter_m * (1.0 + 1e-9))
    r.fail("ae", "radial depth of cut " + detail::format_in_unit(ae, length_mm()) +
                     " exceeds the tool diameter " +
                     detail::format_in_unit(tool->diameter_m, length_mm()));
  return ae;
}

cutting::MillingDirection read_direction(SectionReader& r) {
  return r.choice("direction", {"down", "up"}, "down") == "up" ? cutting::MillingDirection::up
                                                               : cutting::MillingDirection::down;
}

ForcesSettings read_forces(SectionReader& root, const std::optional<tool::ToolSpec>& tool) {
  ForcesSettings forces;
  auto section = root.section("forces");
  if (!section)
    return forces;
  SectionReader& r = *section;
  r.allow_schema("forces");
  forces.revolutions = r.integer_or("revolutions", 1, 1000, forces.revolutions);
  forces.steps_per_tooth = r.integer_or("steps_per_tooth", 4, 100000, forces.steps_per_tooth);
  // 0 (automatic) is the default and cannot be written: an explicit value is a count.
  forces.axial_elements = r.integer_or("axial_elements", 1, 10000, 0);
  // Each sample holds ~50 bytes; cap the history at 20 million samples (1 GB)
  // so a typo cannot exhaust memory.
  constexpr double kMaxSamples = 20e6;
  const double samples =
      static_cast<double>(forces.revolutions) * forces.steps_per_tooth * (tool ? tool->teeth : 1);
  if (samples > kMaxSamples) {
    r.fail(r.has("steps_per_tooth") ? "steps_per_tooth" : "revolutions",
           "revolutions x teeth x steps_per_tooth = " +
               std::to_string(static_cast<long long>(samples)) +
               " samples exceeds the limit of 20000000");
  }
  r.finish();
  return forces;
}

}  // namespace robomill::job::detail
