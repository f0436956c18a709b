// The `surface:` section of a job (docs/surface.md): the patch and its grid,
// the raster path (step-over, passes, pattern), the tool orientation of 001
// Eq 5 and the vibration switch. Lengths in mm, angles in deg, time in s
// unless written. The rules that need the tool and the grid together (001
// Eq 29-31, coverage, shank) are checked by the command.

#include <fmt/format.h>

#include <cmath>

#include "job_parser_surface.hpp"
#include "quantity_fields.hpp"

namespace robomill::job::detail {

void read_surface(SectionReader& root, Job& job) {
  auto section = root.section("surface");
  if (!section)
    return;
  SectionReader& r = *section;
  r.allow_schema("surface");
  if (!job.tool || !job.process)
    r.fail_here("a surface needs the tool: and process: sections");
  SurfaceSettings s;
  s.line = r.line();
  s.area_line = r.line_of("area");
  const auto area = r.quantities("area", length_mm(), 2);
  if (!area)
    r.fail("area", "required: [length_x, length_y] of the patch (mm), e.g. [2, 2]");
  s.area_x_m = (*area)[0];
  s.area_y_m = (*area)[1];
  s.grid_line = r.line_of("grid");
  const auto grid = r.integers("grid", 2, 1, 20000);
  if (!grid)
    r.fail("grid", "required: [nx, ny] cells over the area, e.g. [400, 400]");
  s.cells_x = (*grid)[0];
  s.cells_y = (*grid)[1];
  if (static_cast<double>(s.cells_x + 1) * (s.cells_y + 1) > 1e8)
    r.fail("grid",
           fmt::format("{} x {} cells exceed the limit of 1e8 nodes", s.cells_x, s.cells_y));
  if (const auto origin = r.quantities("origin", length_mm(std::nullopt), 2)) {
    s.origin_x_m = (*origin)[0];
    s.origin_y_m = (*origin)[1];
  }
  s.stepover_m = r.quantity_or("stepover", length_mm(), job.process->radial_depth_m);
  if (s.stepover_m > job.tool->diameter_m)
    r.fail("stepover", fmt::format("{:.4g} mm is wider than the tool ({:.4g} mm)",
                                   s.stepover_m * 1e3, job.tool->diameter_m * 1e3));
  s.passes_line = r.line_of("passes");
  s.passes = r.integer_or("passes", 1, 1'000'000, 0);
  s.first_pass_line = r.line_of("first_pass");
  s.first_pass_y_m = r.optional_quantity("first_pass", length_mm(std::nullopt));
  s.zigzag = r.choice("pattern", {"one_way", "zigzag"}, "one_way") == "zigzag";
  const QuantityField posture_angle =
      angle_deg(Bound{-89.0 * kDeg, true}, Bound{89.0 * kDeg, true});
  s.lead_line = r.line_of("lead");
  s.tilt_line = r.line_of("tilt");
  s.lead_rad = r.quantity_or("lead", posture_angle, 0.0);
  s.tilt_rad = r.quantity_or("tilt", posture_angle, 0.0);
  s.redundancy_rad = r.quantity_or("redundancy", angle_deg(), 0.0);
  s.vibration_line = r.line_of("vibration");
  s.vibration = r.boolean_or("vibration", false);
  s.warmup_s = r.optional_quantity(
      "warmup", field(dimensions::time, 1.0, "s", kNonNegative, Bound{600.0, true}));
  s.entry_m = r.optional_quantity("entry", length_mm(kNonNegative));
  const bool start_given = r.has("start");
  s.start_at_rest = r.choice("start", {"steady", "rest"}, "steady") == "rest";
  s.simulation_steps_per_tooth = r.integer_or("steps_per_tooth", 1, 100000, 0);
  if (s.warmup_s && s.entry_m)
    r.fail("warmup",
           "give either warmup (a steady cut) or entry (each pass enters the part), "
           "not both");
  if (s.start_at_rest && (s.warmup_s || s.entry_m))
    r.fail("start",
           fmt::format("start: rest (each pass from rest, fully engaged) excludes {}; give one",
                       s.warmup_s ? "warmup (a steady cut)" : "entry (each pass enters the part)"));
  if (!s.vibration && (s.warmup_s || s.entry_m || start_given || s.simulation_steps_per_tooth > 0))
    r.fail(s.warmup_s    ? "warmup"
           : s.entry_m   ? "entry"
           : start_given ? "start"
                         : "steps_per_tooth",
           "only with vibration: true (they set up the time-domain simulation)");
  s.steps_line = r.line_of("steps_per_revolution");
  s.steps_per_revolution = r.integer_or("steps_per_revolution", 1, 100'000'000, 0);
  s.spacing_line = r.line_of("edge_spacing");
  s.edge_spacing_m = r.quantity_or("edge_spacing", length_mm(), 0.0);
  s.grid_rule = r.boolean_or("grid_rule", true);
  r.finish();
  job.surface = std::move(s);
}

}  // namespace robomill::job::detail
