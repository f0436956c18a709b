// The `atlas:` section of a job (docs/job-reference.md, docs/atlas.md): the
// grid of tool-tip positions (mm, cell frame), the tool axis and feed, the
// redundancy angles (deg), the analyses per item, the spindle range and depth
// window of the stability analysis (rpm, mm) and the SQLite store.

#include "job_parser_atlas.hpp"
#include "quantity_fields.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace robomill::job::detail {
void read_atlas(SectionReader& root, Job& job) {
  auto section = root.section("atlas");
  if (!section)
    return;
  SectionReader& r = *section;
  r.allow_schema("atlas");
  atlas::AtlasSpec spec;
  const QuantityField mm = field(dimensions::length, 1e-3, "mm");
  const QuantityField deg = field(dimensions::angle, kDeg, "deg");

  auto grid = r.section("grid");
  if (!grid)
    r.fail("grid", "required: {from: [x, y, z], to: [x, y, z], counts: [nx, ny, nz]} (mm)");
  grid->allow_schema("atlas.grid");
  const auto from = grid->quantities("from", mm, 3);
  if (!from)
    grid->fail("from", "required: the grid's first corner [x, y, z] in the cell frame");
  const auto to = grid->quantities("to", mm, 3);
  if (!to)
    grid->fail("to", "required: the grid's opposite corner [x, y, z]");
  spec.from_m = {(*from)[0], (*from)[1], (*from)[2]};
  spec.to_m = {(*to)[0], (*to)[1], (*to)[2]};
  const auto counts = grid->integers("counts", 3, 1, 100000);
  if (!counts)
    grid->fail("counts", "required: point counts [nx, ny, nz]");
  std::copy(counts->begin(), counts->end(), spec.counts.begin());
  grid->finish();

  spec.tool_axis = r.unit_vector_or("tool_axis", spec.tool_axis);
  spec.feed = r.unit_vector_or("feed", spec.feed);
  spec.feed -= spec.feed.dot(spec.tool_axis) * spec.tool_axis;
  if (!(spec.feed.norm() > 1e-9))
    r.fail("feed", "must not be parallel to tool_axis");
  spec.feed.normalize();

  if (r.is_map("redundancy")) {
    auto red = r.section("redundancy");
    red->allow_schema("atlas.redundancy");
    const double a = red->quantity("from", deg);
    const int count = red->integer("count", 1, 3600);
    const double b = count == 1 ? red->quantity_or("to", deg, a) : red->quantity("to", deg);
    if (count > 1 && !(b > a))
      red->fail("to", fmt::format("must exceed from ({:g} deg)", a / kDeg));
    red->finish();
    spec.redundancy_rad.clear();
    for (int i = 0; i < count; ++i)
      spec.redundancy_rad.push_back(count == 1 ? a : a + (b - a) * i / (count - 1));
  } else {
    spec.redundancy_rad = {r.quantity_or("redundancy", deg, 0.0)};
  }
  const long long items = static_cast<long long>(spec.counts[0]) * spec.counts[1] * spec.counts[2] *
                          static_cast<long long>(spec.redundancy_rad.size());
  if (items > 100000000LL)
    r.fail("grid", fmt::format("{} items (grid points × redundancy angles): at most 1e8", items));

  if (auto analyses = r.texts("analyses")) {
    spec.compliance = spec.frequency = spec.stability = false;
    if (analyses->empty())
      r.fail("analyses", "give at least one of compliance, frequency, stability");
    for (const auto& a : *analyses) {
      if (a.text == "compliance")
        spec.compliance = true;
      else if (a.text == "frequency")
        spec.frequency = true;
      else if (a.text == "stability")
        spec.stability = true;
      else
        throw InputError(a.path, a.line,
                         "'" + a.text +
                             "' is not an analysis; expected compliance, frequency "
                             "or stability");
    }
  }

  if (spec.stability) {
    auto speeds = r.section("speeds");
    if (!speeds)
      r.fail("speeds", "required with the stability analysis: {from, to, count} (rpm)");
    speeds->allow_schema("atlas.speeds");
    const QuantityField rpm = field(dimensions::angular_speed, kRpm, "rpm", kPositive);
    spec.speed_from_rad_s = speeds->quantity("from", rpm);
    spec.speed_count = speeds->integer("count", 1, 100000);
    spec.speed_to_rad_s = spec.speed_count == 1
                              ? speeds->quantity_or("to", rpm, spec.speed_from_rad_s)
                              : speeds->quantity("to", rpm);
    if (spec.speed_count > 1 && !(spec.speed_to_rad_s > spec.speed_from_rad_s))
      speeds->fail("to", "must be greater than from");
    speeds->finish();
    spec.depth_max_m = r.quantity("depth_max", field(dimensions::length, 1e-3, "mm", kPositive));
    if (!job.tool || !job.cutting || !job.process)
      r.fail("analyses", "stability needs the cut: give the tool:, cutting: and process: sections");
    if (spec.depth_max_m > job.tool->overhang_m * (1.0 + 1e-9))
      r.fail("depth_max", "exceeds the tool overhang");
  } else {
    if (r.has("speeds"))
      r.fail("speeds", "only used by the stability analysis (add it to analyses)");
    if (r.has("depth_max"))
      r.fail("depth_max", "only used by the stability analysis (add it to analyses)");
  }
  spec.batch = r.integer_or("batch", 1, 1000000, 0);
  const std::string store = r.optional_text("store").value_or("atlas.sqlite");
  if (store.empty())
    r.fail("store", "must name a file");
  spec.store = job.resolve(store);
  r.finish();

  if (!job.robot)
    r.fail_here("needs a robot: section (the robot whose workspace is mapped)");
  if (job.robot->posture_rad.empty())
    throw InputError("robot.posture", 0,
                     "required with atlas: the seed posture of every item's inverse kinematics");
  const bool has_mass = !(job.robot->description.dh && job.robot->description.dh->links.empty());
  if ((spec.frequency || spec.stability) && !has_mass)
    r.fail("analyses",
           "frequency and stability need the robot's link masses (robot.links); this robot has "
           "statics only: use analyses: [compliance]");
  job.atlas = spec;
}

}  // namespace robomill::job::detail
