// The `deflection:` section of a job (docs/job-reference.md): how 000's
// force-induced deformation is computed — axial elements, the tool's bending
// section, whether the robot deflects, the static-chip correction of Eq 28 —
// and the depth sweep of `robomill deflection` (000 Figure 11). Lengths in mm
// unless written.

#include "job_parser_deflection.hpp"
#include "quantity_fields.hpp"

#include <fmt/format.h>

#include <cmath>

#include "robomill/deflection/contact_boundary.hpp"

namespace robomill::job::detail {

void read_deflection(SectionReader& root, Job& job) {
  const bool deformed_stability = job.stability && job.stability->deformation;
  auto section = root.section("deflection");
  if (!section) {
    if (deformed_stability)
      job.deflection = DeflectionSettings{};  // the defaults below
    else
      return;
  }
  DeflectionSettings settings;
  const QuantityField length = length_mm();
  if (section) {
    SectionReader& r = *section;
    r.allow_schema("deflection");
    settings.elements = r.integer_or("elements", 1, 200, settings.elements);
    if (auto d = r.optional_quantity("equivalent_diameter", length)) {
      if (job.tool && *d > job.tool->diameter_m * (1.0 + 1e-12)) {
        r.fail("equivalent_diameter",
               fmt::format("{} exceeds the tool diameter {}", format_in_unit(*d, length),
                           format_in_unit(job.tool->diameter_m, length)));
      }
      settings.equivalent_diameter_m = *d;
    }
    settings.chip_correction = r.boolean_or("chip_correction", settings.chip_correction);
    settings.robot = r.boolean_or("robot", settings.robot);
    if (settings.robot && r.has("robot") && !job.robot) {
      r.fail("robot",
             "is true but the job has no robot: section (give one, or robot: false for "
             "the tool's bending alone)");
    }
    if (auto depths = r.section("depths")) {
      depths->allow_schema("deflection.depths");
      settings.depth_from_m = depths->quantity("from", length);
      settings.depth_to_m = depths->quantity("to", length);
      settings.depth_count = depths->integer_or("count", 1, 1000, settings.depth_count);
      if (settings.depth_count > 1 && !(settings.depth_to_m > settings.depth_from_m)) {
        depths->fail("to", fmt::format("must exceed from ({})",
                                       format_in_unit(settings.depth_from_m, length)));
      }
      if (job.tool && settings.depth_to_m > job.tool->overhang_m * (1.0 + 1e-12)) {
        depths->fail("to", fmt::format("{} exceeds the tool overhang {}",
                                       format_in_unit(settings.depth_to_m, length),
                                       format_in_unit(job.tool->overhang_m, length)));
      }
      depths->finish();
    }
    settings.table_depths = r.integer_or("table_depths", 2, 1000, settings.table_depths);
    r.finish();
  }
  // A robot deflects only where it stands: without a posture its part is
  // left out (said in the outputs), unless the user asked for it.
  if (settings.robot && job.robot && job.robot->posture_rad.empty()) {
    if (section && section->has("robot"))
      throw InputError("robot.posture", 0,
                       "required with deflection.robot: true (the posture whose joint springs "
                       "deflect)");
    settings.robot = false;
  }
  if (!job.robot)
    settings.robot = false;
  if (job.process && job.process->direction != cutting::MillingDirection::down) {
    throw InputError("process.direction", 0,
                     "000's contact-boundary algorithm (deflection:, stability.deformation) is "
                     "written for down milling, where the wall is cut at the exit; got up");
  }
  if (job.cutting && !std::holds_alternative<cutting::LinearLaw>(*job.cutting)) {
    throw InputError("cutting.law", 0,
                     "000's deformation model uses the linear law (Eq 13: Ktc, Krc, Kte, Kre)");
  }
  job.deflection = settings;
}

}  // namespace robomill::job::detail
